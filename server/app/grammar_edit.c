#include "grammar_edit.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/grammar_text.h"
#include "../io/meshblob.h"
#include "../io/meshjson.h"
#include "../io/splittree_json.h"
#include "../io/terminals.h"
#include "../store/grammars.h"
#include "../store/models.h"
#include "../store/states.h"
#include "modelops.h"

void ag_grammar_derived_clear(ag_grammar_derived *d)
{
    if (!d)
        return;
    ag_grammar_free(d->grammar);
    ag_mesh_free(d->mesh);
    free(d->tree_json);
    memset(d, 0, sizeof *d);
}

/* Line and column of "terminal NAME" in the text (1, 1 when it cannot be found). */
static void find_declaration(const char *text, size_t len, const char *name, long *line,
                             long *col)
{
    *line = 1;
    *col = 1;
    size_t nl = strlen(name);
    long ln = 1;
    for (size_t i = 0; i < len;) {
        size_t s = i;
        while (s < len && (text[s] == ' ' || text[s] == '\t'))
            s++;
        if (len - s > 9 + nl && memcmp(text + s, "terminal", 8) == 0 &&
            (text[s + 8] == ' ' || text[s + 8] == '\t')) {
            size_t n = s + 8;
            while (n < len && (text[n] == ' ' || text[n] == '\t'))
                n++;
            if (len - n >= nl && memcmp(text + n, name, nl) == 0 &&
                (n + nl == len || text[n + nl] == ' ' || text[n + nl] == '\t' ||
                 text[n + nl] == '\r' || text[n + nl] == '\n')) {
                *line = ln;
                *col = (long)(s - i) + 1;
                return;
            }
        }
        while (i < len && text[i] != '\n')
            i++;
        i++;
        ln++;
    }
}

ag_status ag_grammar_edit_derive(const char *text, size_t len, ag_terminal_lookup lookup,
                                 void *user, ag_grammar_derived *out, ag_error *err, long *col)
{
    memset(out, 0, sizeof *out);
    if (col)
        *col = 0;
    long c = 0;
    ag_status s = ag_grammar_text_parse(text, len, &out->grammar, err, &c);
    if (s != AG_OK) {
        if (col)
            *col = c;
        /* name and resolve errors come with a position too: all are the text's fault */
        if (s != AG_ERR_NOMEM && err && err->element > 0)
            err->code = s = AG_ERR_PARSE;
        return s;
    }
    ag_grammar *g = out->grammar;
    for (size_t i = 0; i < g->nterminals && s == AG_OK; i++) {
        ag_gterminal *t = &g->terminals[i];
        char *obj = NULL;
        size_t olen = 0;
        ag_error e;
        ag_error_clear(&e);
        s = t->path ? lookup(user, t->path, &obj, &olen, &e) : AG_ERR_NOT_FOUND;
        if (s == AG_ERR_NOT_FOUND) {
            long line, cc;
            find_declaration(text, len, t->name, &line, &cc);
            if (col)
                *col = cc;
            s = ag_error_set(err, AG_ERR_PARSE, line,
                             "terminal '%s' names \"%s\", which is not one of this model's "
                             "terminals",
                             t->name, t->path ? t->path : "");
        } else if (s != AG_OK) {
            if (err)
                *err = e;
        } else {
            s = ag_terminals_load_buffer(t, obj, olen, err);
        }
        free(obj);
    }
    ag_grammar_derive_options dopt = {.max_triangles = AG_GRAMMAR_EDIT_MAX_TRIANGLES};
    if (s == AG_OK)
        s = ag_grammar_derive(g, &dopt, &out->mesh, err);
    if (s == AG_OK)
        s = ag_splittree_json_build(g, NULL, &out->tree_json, &out->ncomponents, err);
    if (s == AG_OK && out->ncomponents != out->mesh->ncomponents)
        s = ag_error_set(err, AG_ERR_INTERNAL, 0,
                         "the split tree places %zu terminals but the derivation %zu",
                         out->ncomponents, out->mesh->ncomponents);
    if (s != AG_OK)
        ag_grammar_derived_clear(out);
    return s;
}

ag_status ag_grammar_edit_store(ag_db *db, int64_t model, int64_t version,
                                const ag_grammar_derived *d, const char *text, size_t len,
                                const char *summary_json, ag_error *err)
{
    uint8_t *blob = NULL;
    size_t blob_len = 0;
    ag_status s = ag_meshblob_encode(d->mesh, &blob, &blob_len);
    if (s != AG_OK)
        return ag_error_set(err, s, 0, "cannot encode the derived mesh");
    json_t *summary = ag_meshjson_summary(d->mesh);
    char *stats = summary ? json_dumps(summary, JSON_COMPACT) : NULL;
    json_decref(summary);
    int64_t mesh_blob = 0;
    if (!stats)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory summarising the mesh");
    if (s == AG_OK)
        s = ag_models_set_mesh(db, model, blob, blob_len, stats, &mesh_blob, err);
    if (s == AG_OK) {
        ag_grammar_new g = {.model = model,
                            .version = version,
                            .mesh_blob = mesh_blob,
                            .text = text,
                            .text_len = len,
                            .tree_json = d->tree_json,
                            .summary_json = summary_json};
        s = ag_grammars_put(db, &g, err);
    }
    free(stats);
    free(blob);
    return s;
}

typedef struct {
    ag_db *db;
    int64_t model;
} stored_terminals;

static ag_status lookup_stored(void *user, const char *path, char **obj, size_t *len,
                               ag_error *err)
{
    const stored_terminals *st = user;
    return ag_grammars_get_terminal(st->db, st->model, path, obj, len, err);
}

ag_status ag_grammar_edit_apply(ag_app *app, int64_t model, int64_t base, const char *author,
                                const char *cid, const char *text, size_t len, int64_t *version,
                                ag_error *err, long *col)
{
    *version = 0;
    if (col)
        *col = 0;
    if (len > AG_GRAMMAR_TEXT_MAX)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "a grammar holds at most %zu bytes",
                            AG_GRAMMAR_TEXT_MAX);
    ag_db *db = ag_app_db(app, err);
    if (!db)
        return err ? err->code : AG_ERR_DB;
    ag_grammar_row cur;
    ag_status s = ag_grammars_current(db, model, 0, &cur, err);
    if (s != AG_OK)
        return s;
    ag_grammars_row_clear(&cur);

    stored_terminals ctx = {db, model};
    ag_grammar_derived d;
    if ((s = ag_grammar_edit_derive(text, len, lookup_stored, &ctx, &d, err, col)) != AG_OK)
        return s;
    json_t *summary = json_pack(
        "{s:s, s:I, s:I, s:I, s:I, s:I, s:I}", "source", "edit", "rules",
        (json_int_t)d.grammar->nrules, "terminals", (json_int_t)d.grammar->nterminals,
        "grammar_bytes", (json_int_t)len, "triangles", (json_int_t)d.mesh->ntris, "vertices",
        (json_int_t)d.mesh->nverts, "components", (json_int_t)d.mesh->ncomponents);
    char *summary_text = summary ? json_dumps(summary, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(summary);
    json_t *op = json_pack("{s:s, s:I}", "kind", "grammar", "bytes", (json_int_t)len);
    ag_modelops_txn t;
    if (!summary_text || !op)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK && (s = ag_modelops_server_begin(app, model, base, &t, err)) == AG_OK) {
        /* the states before and after are kept: the author's undo restores the old text */
        s = ag_states_keep(t.db, model, t.version - 1, err);
        if (s == AG_OK)
            s = ag_grammar_edit_store(t.db, model, t.version, &d, text, len, summary_text, err);
        if (s == AG_OK)
            s = ag_states_keep(t.db, model, t.version, err);
        if (s == AG_OK) {
            int64_t v = t.version;
            if ((s = ag_modelops_server_commit(&t, author, cid, op, err)) == AG_OK)
                *version = v;
        } else {
            ag_modelops_server_abort(&t);
        }
    }
    json_decref(op);
    free(summary_text);
    ag_grammar_derived_clear(&d);
    return s;
}
