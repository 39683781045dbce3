/* The parts library's tables (store/parts.h, migration 0006): Debian's SQLite has FTS5; parts
 * keep their versions; terminals are stored once per content for the whole library and go
 * when no version uses them; search by words (prefixes, every word, any case), by tag, both,
 * with paging, and texts that look like FTS5 syntax are only words; deleting needs the newest
 * version; deleting the model a part came from leaves the part whole; a failed write leaves
 * nothing behind. Counts are read with plain SQL, independently of the module. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "store/parts.h"
#include "store_fixture.h"

typedef struct {
    char *path;
    ag_db *db;
} fx;

static int setup(void **state)
{
    fx *f = calloc(1, sizeof *f);
    f->path = temp_db();
    ag_error err;
    assert_int_equal(ag_db_open(f->path, NULL, &f->db, &err), AG_OK);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fx *f = *state;
    ag_db_close(f->db);
    remove_db(f->path);
    free(f);
    return 0;
}

static const char H1[] = "1111111111111111111111111111111111111111111111111111111111111111";
static const char H2[] = "2222222222222222222222222222222222222222222222222222222222222222";
static const char H3[] = "3333333333333333333333333333333333333333333333333333333333333333";

static int64_t put(ag_db *db, const char *name, const char *desc, const char *const *tags,
                   size_t ntags, const char *const *hashes, size_t nh)
{
    ag_part_terminal_text t[4];
    for (size_t i = 0; i < nh; i++)
        t[i] = (ag_part_terminal_text){hashes[i], "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 30};
    ag_part_new p = {.version = 1, .name = name, .description = desc, .tags = tags,
                     .ntags = ntags, .entry_json = "{\"name\":\"x\"}", .terminals = t,
                     .nterminals = nh, .source_model = 7, .source_name = "house",
                     .source_version = 3, .source_node = 12, .thumbnail = "\x89PNG",
                     .thumbnail_len = 4};
    ag_error err;
    int64_t id = 0;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_parts_insert(db, &p, &id, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
    return id;
}

static void sqlite_has_fts5(void **state)
{
    fx *f = *state;
    assert_true(sqlite3_compileoption_used("ENABLE_FTS5"));
    assert_int_equal(count(f->db, "SELECT count(*) FROM sqlite_master WHERE name = "
                                  "'parts_search' AND sql LIKE '%fts5%'"),
                     1);
}

static void versions_and_shared_terminals(void **state)
{
    fx *f = *state;
    ag_error err;
    const char *tags[] = {"window", "timber"};
    const char *h12[] = {H1, H2}, *h23[] = {H2, H3};
    int64_t a = put(f->db, "sash window", "one mullion", tags, 2, h12, 2);
    int64_t b = put(f->db, "dormer", NULL, NULL, 0, h23, 2);
    /* H2 is held once for both */
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_terminals"), 3);
    assert_int_equal(ag_parts_count_terminals(f->db), 3);
    /* a second version of a, made on version 1 */
    ag_part_terminal_text t = {H3, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", 30};
    const char *tags2[] = {"window"};
    ag_part_new p = {.version = 2, .name = "sash window", .description = "two mullions",
                     .tags = tags2, .ntags = 1, .entry_json = "{\"v\":2}", .terminals = &t,
                     .nterminals = 1, .thumbnail = "png2", .thumbnail_len = 4};
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_add_version(f->db, a, 1, &p, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    /* again on version 1: stale, naming version 2 */
    p.version = 2;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_add_version(f->db, a, 1, &p, &err), AG_ERR_STALE);
    assert_int_equal(err.element, 2);
    assert_int_equal(ag_parts_add_version(f->db, 99, 1, &p, &err), AG_ERR_NOT_FOUND);
    ag_db_rollback(f->db);

    ag_part_row row;
    assert_int_equal(ag_parts_get(f->db, a, &row, &err), AG_OK);
    assert_int_equal(row.version, 2);
    assert_string_equal(row.description, "two mullions");
    assert_int_equal(row.ntags, 1);
    assert_string_equal(row.tags[0], "window");
    ag_parts_row_clear(&row);
    ag_part_version_row *vs;
    size_t nv;
    assert_int_equal(ag_parts_versions(f->db, a, &vs, &nv, &err), AG_OK);
    assert_int_equal(nv, 2);
    assert_int_equal(vs[0].version, 2);
    assert_int_equal(vs[1].version, 1);
    assert_int_equal(vs[1].source_model, 7);
    assert_string_equal(vs[1].source_name, "house");
    assert_int_equal(vs[1].source_node, 12);
    assert_int_equal(vs[0].source_model, 0);
    assert_null(vs[0].source_name);
    for (size_t i = 0; i < nv; i++)
        ag_parts_version_row_clear(&vs[i]);
    free(vs);
    ag_part_version_row v1;
    assert_int_equal(ag_parts_get_version(f->db, a, 1, 1, &v1, &err), AG_OK);
    assert_string_equal(v1.entry_json, "{\"name\":\"x\"}");
    ag_parts_version_row_clear(&v1);
    assert_int_equal(ag_parts_get_version(f->db, a, 5, 0, &v1, &err), AG_ERR_NOT_FOUND);
    assert_non_null(strstr(err.text, "no version 5"));
    void *png;
    size_t len;
    assert_int_equal(ag_parts_thumbnail(f->db, a, 0, &png, &len, &err), AG_OK);
    assert_int_equal(len, 4);
    assert_memory_equal(png, "png2", 4);
    free(png);

    /* deleting needs the newest version; b still holds H2 and H3, a's version 1 H1 */
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_delete(f->db, a, 1, &err), AG_ERR_STALE);
    assert_int_equal(ag_parts_delete(f->db, a, 2, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_get(f->db, a, &row, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_versions"), 1);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_terminals"), 2);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_terminals WHERE sha256 LIKE '1%'"), 0);
    assert_int_equal(count(f->db, "SELECT count(*) FROM parts_search"), 1);
    assert_int_equal(count(f->db, "SELECT count(*) FROM part_tags"), 0);
    assert_int_equal(ag_parts_count(f->db), 1);
    (void)b;
}

static size_t search(ag_db *db, const char *q, const char *tag, size_t offset, size_t limit,
                     int *more, int64_t *ids)
{
    ag_part_row *rows;
    size_t n;
    ag_error err;
    ag_parts_query pq = {q, tag, offset, limit};
    ag_status s = ag_parts_search(db, &pq, &rows, &n, more, &err);
    if (s != AG_OK)
        fail_msg("search '%s': %s", q ? q : "", err.text);
    for (size_t i = 0; i < n; i++) {
        if (ids)
            ids[i] = rows[i].id;
        ag_parts_row_clear(&rows[i]);
    }
    free(rows);
    return n;
}

static void search_by_words_tags_and_pages(void **state)
{
    fx *f = *state;
    const char *win[] = {"window"}, *door[] = {"door", "timber"};
    int64_t w1 = put(f->db, "Sash Window", "a window with one mullion", win, 1, NULL, 0);
    int64_t d1 = put(f->db, "front door", "panelled, timber", door, 2, NULL, 0);
    int64_t w2 = put(f->db, "bay window", "three lights", win, 1, NULL, 0);
    int64_t p1 = put(f->db, "portico", "Ionic columns, a pediment", NULL, 0, NULL, 0);
    int64_t ids[16];
    int more;
    /* every part, by id */
    assert_int_equal(search(f->db, NULL, NULL, 0, 10, &more, ids), 4);
    assert_false(more);
    assert_int_equal(ids[0], w1);
    assert_int_equal(ids[3], p1);
    /* words are prefixes, case does not matter, every word must match somewhere */
    assert_int_equal(search(f->db, "WIND", NULL, 0, 10, &more, ids), 2);
    assert_int_equal(search(f->db, "window mull", NULL, 0, 10, &more, ids), 1);
    assert_int_equal(ids[0], w1);
    assert_int_equal(search(f->db, "timber", NULL, 0, 10, &more, ids), 1); /* a tag */
    assert_int_equal(ids[0], d1);
    assert_int_equal(search(f->db, "pediment", NULL, 0, 10, &more, ids), 1); /* a description */
    assert_int_equal(ids[0], p1);
    assert_int_equal(search(f->db, "chimney", NULL, 0, 10, &more, ids), 0);
    /* tag alone, and with words */
    assert_int_equal(search(f->db, NULL, "window", 0, 10, &more, ids), 2);
    assert_int_equal(ids[0], w1);
    assert_int_equal(ids[1], w2);
    assert_int_equal(search(f->db, "bay", "window", 0, 10, &more, ids), 1);
    assert_int_equal(ids[0], w2);
    assert_int_equal(search(f->db, "bay", "door", 0, 10, &more, ids), 0);
    assert_int_equal(search(f->db, NULL, "Window", 0, 10, &more, ids), 0); /* tags exactly */
    /* pages */
    assert_int_equal(search(f->db, NULL, NULL, 0, 3, &more, ids), 3);
    assert_true(more);
    assert_int_equal(search(f->db, NULL, NULL, 3, 3, &more, ids), 1);
    assert_false(more);
    assert_int_equal(ids[0], p1);
    assert_int_equal(search(f->db, "window", NULL, 1, 1, &more, ids), 1);
    assert_false(more);
    /* what FTS5 would read as syntax is only separators and words here */
    const char *odd[] = {"\"window", "window\"", "window*", "NEAR(window door)", "window OR door",
                         "-window", "window:", "(window", "^window", "'window'", "window AND"};
    for (size_t i = 0; i < sizeof odd / sizeof odd[0]; i++)
        search(f->db, odd[i], NULL, 0, 10, &more, ids);
    assert_int_equal(search(f->db, "  ,;  ", NULL, 0, 10, &more, ids), 4); /* no words: all */
    /* limits */
    char longq[AG_PARTS_QUERY_MAX + 2];
    memset(longq, 'a', sizeof longq - 1);
    longq[sizeof longq - 1] = '\0';
    ag_part_row *rows;
    size_t n;
    ag_error err;
    ag_parts_query pq = {longq, NULL, 0, 10};
    assert_int_equal(ag_parts_search(f->db, &pq, &rows, &n, &more, &err), AG_ERR_INVALID);
    pq.q = "a b c d e f g h i j k l m n o p q";
    assert_int_equal(ag_parts_search(f->db, &pq, &rows, &n, &more, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "words"));
}

static void a_part_outlives_its_source_model(void **state)
{
    fx *f = *state;
    ag_error err;
    int64_t m = insert_model(f->db, &(ag_model_new){.name = "house", .mesh = "m", .mesh_len = 1});
    ag_part_new p = {.version = 1, .name = "window", .entry_json = "{}", .source_model = m,
                     .source_name = "house", .thumbnail = "p", .thumbnail_len = 1};
    int64_t id;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_insert(f->db, &p, &id, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_delete(f->db, m, 1, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    ag_part_version_row v;
    assert_int_equal(ag_parts_get_version(f->db, id, 0, 1, &v, &err), AG_OK);
    assert_int_equal(v.source_model, m);
    assert_string_equal(v.source_name, "house");
    ag_parts_version_row_clear(&v);
}

static void a_failed_write_leaves_nothing(void **state)
{
    fx *f = *state;
    ag_error err;
    const char *tags[] = {"window"};
    ag_part_terminal_text t = {H1, "v 0 0 0\n", 8};
    char name[260];
    memset(name, 'n', sizeof name - 1);
    name[sizeof name - 1] = '\0'; /* past the table's 200 characters */
    ag_part_new ok = {.version = 1, .name = "fine", .tags = tags, .ntags = 1, .entry_json = "{}",
                      .terminals = &t, .nterminals = 1, .thumbnail = "p", .thumbnail_len = 1};
    ag_part_new bad = ok;
    bad.name = name;
    int64_t id;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_parts_insert(f->db, &ok, &id, &err), AG_OK);
    assert_int_not_equal(ag_parts_insert(f->db, &bad, &id, &err), AG_OK);
    ag_db_rollback(f->db);
    static const char *const tables[] = {"parts", "part_versions", "part_tags", "part_terminals",
                                         "part_version_terminals", "parts_search"};
    for (size_t i = 0; i < sizeof tables / sizeof tables[0]; i++) {
        char sql[96];
        snprintf(sql, sizeof sql, "SELECT count(*) FROM %s", tables[i]);
        assert_int_equal(count(f->db, sql), 0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(sqlite_has_fts5, setup, teardown),
        cmocka_unit_test_setup_teardown(versions_and_shared_terminals, setup, teardown),
        cmocka_unit_test_setup_teardown(search_by_words_tags_and_pages, setup, teardown),
        cmocka_unit_test_setup_teardown(a_part_outlives_its_source_model, setup, teardown),
        cmocka_unit_test_setup_teardown(a_failed_write_leaves_nothing, setup, teardown),
    };
    return cmocka_run_group_tests_name("parts_store", tests, NULL, NULL);
}
