/* The op table (app/optable.h) against what documents and sends op kinds: the structural
 * kinds of schema/edit_ops.md, the op kinds table of schema/websocket.md (with the server-made
 * ones marked "made by the server only"), the web client's OP_KINDS (web/src/opkinds.js), and
 * the live protocol's message types against the messages schema/websocket.md lists. The rows
 * themselves: one per kind, what each lane needs, and the kinds that leave geometry alone are
 * the ones the store's state lookup skips (store/states.c). The docs are read as text here,
 * independently of the table. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/modelops.h"
#include "app/optable.h"
#include "net/live_protocol.h"
#include "file_fixture.h"

#define MAX_KINDS 64

typedef struct {
    char kind[MAX_KINDS][32];
    int server_only[MAX_KINDS];
    size_t n;
} kind_list;

static char *read_repo_file(const char *rel)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", AG_REPO_DIR, rel);
    return read_text_file(path);
}

static void add(kind_list *l, const char *k, size_t len, int server_only)
{
    assert_true(len < 32 && l->n < MAX_KINDS);
    memcpy(l->kind[l->n], k, len);
    l->kind[l->n][len] = '\0';
    l->server_only[l->n] = server_only;
    l->n++;
}

static int has(const kind_list *l, const char *k)
{
    for (size_t i = 0; i < l->n; i++)
        if (strcmp(l->kind[i], k) == 0)
            return 1;
    return 0;
}

/* The `backquoted` names in the first cell of each table row after `heading`, up to the
 * table's end; a row whose text says "made by the server only" marks them server-only. */
static void table_kinds(const char *text, const char *heading, kind_list *out)
{
    memset(out, 0, sizeof *out);
    const char *p = strstr(text, heading);
    if (!p)
        fail_msg("no \"%s\" in the document", heading);
    p = strstr(p, "\n|");
    assert_non_null(p);
    int rows = 0;
    for (p++; *p == '|'; rows++) {
        const char *eol = strchr(p, '\n');
        if (!eol)
            eol = p + strlen(p);
        const char *cell_end = strchr(p + 1, '|');
        int server = 0;
        for (const char *q = p; q + 27 < eol; q++)
            if (memcmp(q, "made by the server only", 23) == 0)
                server = 1;
        if (rows >= 2) /* header and separator */
            for (const char *q = p + 1; q < cell_end;) {
                const char *a = strchr(q, '`');
                if (!a || a >= cell_end)
                    break;
                const char *b = strchr(a + 1, '`');
                assert_true(b && b < cell_end);
                add(out, a + 1, (size_t)(b - a - 1), server);
                q = b + 1;
            }
        p = *eol ? eol + 1 : eol;
    }
    assert_true(out->n > 0);
}

/* The strings of `export const OP_KINDS = [ ... ];`. */
static void web_kinds(const char *text, kind_list *out)
{
    memset(out, 0, sizeof *out);
    const char *p = strstr(text, "export const OP_KINDS");
    assert_non_null(p);
    p = strchr(p, '[');
    const char *end = strchr(p, ']');
    assert_true(p && end);
    for (const char *q = p; q < end;) {
        /* a string literal in either quote style */
        const char *a = strpbrk(q, "'\"");
        if (!a || a > end)
            break;
        const char *b = strchr(a + 1, *a);
        assert_true(b && b < end);
        add(out, a + 1, (size_t)(b - a - 1), 0);
        q = b + 1;
    }
}

static void the_table_is_what_the_docs_and_the_client_say(void **state)
{
    (void)state;
    char *ws = read_repo_file("schema/websocket.md");
    char *eo = read_repo_file("schema/edit_ops.md");
    char *web = read_repo_file("web/src/opkinds.js");
    kind_list documented, structural, client;
    table_kinds(ws, "Op kinds:", &documented);
    table_kinds(eo, "## Kinds", &structural);
    web_kinds(web, &client);

    /* every documented kind has its row, with the sender the document says */
    for (size_t i = 0; i < documented.n; i++) {
        const ag_op_kind *row = ag_optable_find(documented.kind[i]);
        if (!row)
            fail_msg("schema/websocket.md documents \"%s\", the op table has no row", documented.kind[i]);
        if (!!(row->flags & AG_OP_CLIENT) == documented.server_only[i])
            fail_msg("\"%s\": the document and the table disagree on who sends it", row->kind);
    }
    /* and every row is documented */
    for (size_t i = 0; i < ag_optable_count; i++)
        if (!has(&documented, ag_optable[i].kind))
            fail_msg("the op table's \"%s\" is not in schema/websocket.md", ag_optable[i].kind);
    /* the structural edits of edit_ops.md are undoable client kinds of the structural lane */
    for (size_t i = 0; i < structural.n; i++) {
        const ag_op_kind *row = ag_optable_find(structural.kind[i]);
        if (!row)
            fail_msg("schema/edit_ops.md documents \"%s\", the op table has no row", structural.kind[i]);
        assert_int_equal(row->flags & (AG_OP_CLIENT | AG_OP_UNDOABLE | AG_OP_GEOMETRY),
                         AG_OP_CLIENT | AG_OP_UNDOABLE | AG_OP_GEOMETRY);
        assert_int_equal(row->lane, AG_OP_STRUCTURAL);
        assert_non_null(row->run);
    }
    /* what the web client sends is exactly what clients may send */
    for (size_t i = 0; i < client.n; i++) {
        const ag_op_kind *row = ag_optable_find(client.kind[i]);
        if (!row || !(row->flags & AG_OP_CLIENT))
            fail_msg("the web client sends \"%s\", which is not a client kind of the table",
                     client.kind[i]);
    }
    for (size_t i = 0; i < ag_optable_count; i++)
        if ((ag_optable[i].flags & AG_OP_CLIENT) && !has(&client, ag_optable[i].kind))
            fail_msg("clients may send \"%s\" but web/src/opkinds.js does not list it",
                     ag_optable[i].kind);
    free(ws);
    free(eo);
    free(web);
}

static void rows_have_what_their_lane_needs(void **state)
{
    (void)state;
    for (size_t i = 0; i < ag_optable_count; i++) {
        const ag_op_kind *row = &ag_optable[i];
        for (size_t j = 0; j < i; j++)
            assert_string_not_equal(ag_optable[j].kind, row->kind);
        assert_ptr_equal(ag_optable_find(row->kind), row);
        if (row->flags & AG_OP_CLIENT) {
            assert_non_null(row->validate);
            assert_null(row->made_by);
        } else {
            assert_non_null(row->made_by); /* the refusal names the REST call */
            assert_null(row->run);
        }
        if (row->lane == AG_OP_FAST)
            assert_null(row->run); /* applied at once, inside the sequenced transaction */
        assert_false(row->run && row->effect);
        /* the kinds that leave geometry alone are those store/states.c skips */
        int plain = strcmp(row->kind, "rename") == 0 || strcmp(row->kind, "note") == 0;
        assert_int_equal(!(row->flags & AG_OP_GEOMETRY), plain);
    }
    assert_null(ag_optable_find("fly"));
    assert_null(ag_optable_find(NULL));
}

static void validation_goes_through_the_table(void **state)
{
    (void)state;
    ag_error err;
    json_t *o = json_pack("{s:s}", "kind", "grammar");
    assert_int_equal(ag_modelops_validate(o, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "made by the server"));
    assert_non_null(strstr(err.text, ag_optable_find("grammar")->made_by));
    json_decref(o);
    o = json_pack("{s:s}", "kind", "undo");
    assert_int_equal(ag_modelops_validate(o, &err), AG_OK);
    json_decref(o);
    o = json_pack("{s:s, s:i}", "kind", "undo", "extra", 1);
    assert_int_equal(ag_modelops_validate(o, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "extra"));
    json_decref(o);
    o = json_pack("{s:s, s:i}", "kind", "restore", "version", 0);
    assert_int_equal(ag_modelops_validate(o, &err), AG_ERR_INVALID);
    json_decref(o);
    o = json_pack("{s:i}", "kind", 3);
    assert_int_equal(ag_modelops_validate(o, &err), AG_ERR_INVALID);
    json_decref(o);
}

static void the_live_protocol_handles_the_documented_messages(void **state)
{
    (void)state;
    char *ws = read_repo_file("schema/websocket.md");
    size_t n = 0;
    for (const char *type; (type = ag_live_protocol_type(n)); n++) {
        char quoted[64];
        snprintf(quoted, sizeof quoted, "{\"type\":\"%s\"", type);
        if (!strstr(ws, quoted))
            fail_msg("the live protocol handles \"%s\", schema/websocket.md does not show it", type);
    }
    assert_int_equal(n, 6); /* hello, op, presence, watch, preview, preview.end */
    free(ws);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_table_is_what_the_docs_and_the_client_say),
        cmocka_unit_test(rows_have_what_their_lane_needs),
        cmocka_unit_test(validation_goes_through_the_table),
        cmocka_unit_test(the_live_protocol_handles_the_documented_messages),
    };
    return cmocka_run_group_tests_name("optable", tests, NULL, NULL);
}
