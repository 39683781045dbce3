#include "parts.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_WORDS 16

void ag_parts_row_clear(ag_part_row *row)
{
    if (!row)
        return;
    free(row->name);
    free(row->description);
    for (size_t i = 0; i < row->ntags; i++)
        free(row->tags[i]);
    free(row->tags);
    memset(row, 0, sizeof *row);
}

void ag_parts_version_row_clear(ag_part_version_row *row)
{
    if (!row)
        return;
    free(row->entry_json);
    free(row->source_name);
    free(row->stats_json);
    memset(row, 0, sizeof *row);
}

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

/* --- writing ------------------------------------------------------------------------------ */

/* The searched text of a version: its tags joined by spaces. */
static char *joined_tags(const ag_part_new *p)
{
    size_t n = 1;
    for (size_t i = 0; i < p->ntags; i++)
        n += strlen(p->tags[i]) + 1;
    char *s = malloc(n), *w = s;
    if (!s)
        return NULL;
    *w = '\0';
    for (size_t i = 0; i < p->ntags; i++)
        w += sprintf(w, "%s%s", i ? " " : "", p->tags[i]);
    return s;
}

/* The part's searched metadata and tags become p's. */
static ag_status put_metadata(ag_db *db, int64_t id, const ag_part_new *p, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "DELETE FROM part_tags WHERE part_id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    if ((s = ag_db_step_done(db, st, "replacing a part's tags", err)) != AG_OK)
        return s;
    for (size_t i = 0; i < p->ntags; i++) {
        /* a tag given twice is kept once, where it came first */
        if ((s = ag_db_prepared(db, &st,
                                "INSERT OR IGNORE INTO part_tags (part_id, tag, position) "
                                "VALUES (?, ?, ?)",
                                err)) != AG_OK)
            return s;
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_text(st, 2, p->tags[i], -1, SQLITE_STATIC);
        sqlite3_bind_int64(st, 3, (sqlite3_int64)i);
        if ((s = ag_db_step_done(db, st, "storing a part's tags", err)) != AG_OK)
            return s;
    }
    if ((s = ag_db_prepared(db, &st, "DELETE FROM parts_search WHERE rowid = ?", err)) != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    if ((s = ag_db_step_done(db, st, "indexing a part", err)) != AG_OK)
        return s;
    char *tags = joined_tags(p);
    if (!tags)
        return nomem(err);
    s = ag_db_prepared(db, &st,
                       "INSERT INTO parts_search (rowid, name, tags, description) "
                       "VALUES (?, ?, ?, ?)",
                       err);
    if (s == AG_OK) {
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_text(st, 2, p->name, -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 3, tags, -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 4, p->description ? p->description : "", -1, SQLITE_STATIC);
        s = ag_db_step_done(db, st, "indexing a part", err);
    }
    free(tags);
    return s;
}

static ag_status put_version(ag_db *db, int64_t id, const ag_part_new *p, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st,
        "INSERT INTO part_versions (part_id, version, entry, source_model, source_name, "
        "source_version, source_node, thumbnail, stats) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)",
        err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    sqlite3_bind_int64(st, 2, p->version);
    sqlite3_bind_text(st, 3, p->entry_json, -1, SQLITE_STATIC);
    if (p->source_model > 0)
        sqlite3_bind_int64(st, 4, p->source_model);
    else
        sqlite3_bind_null(st, 4);
    if (p->source_name)
        sqlite3_bind_text(st, 5, p->source_name, -1, SQLITE_STATIC);
    else
        sqlite3_bind_null(st, 5);
    sqlite3_bind_int64(st, 6, p->source_version);
    sqlite3_bind_int64(st, 7, p->source_node);
    sqlite3_bind_blob64(st, 8, p->thumbnail_len ? p->thumbnail : "", p->thumbnail_len,
                        SQLITE_STATIC);
    sqlite3_bind_text(st, 9, p->stats_json ? p->stats_json : "{}", -1, SQLITE_STATIC);
    if ((s = ag_db_step_done(db, st, "storing a part version", err)) != AG_OK)
        return s;
    for (size_t i = 0; i < p->nterminals; i++) {
        const ag_part_terminal_text *t = &p->terminals[i];
        /* content-addressed: a text the library holds already is shared */
        if ((s = ag_db_prepared(db, &st,
                                "INSERT OR IGNORE INTO part_terminals (sha256, obj) VALUES (?, ?)",
                                err)) != AG_OK)
            return s;
        sqlite3_bind_text(st, 1, t->sha256, -1, SQLITE_STATIC);
        sqlite3_bind_text(st, 2, t->obj, (int)t->len, SQLITE_STATIC);
        if ((s = ag_db_step_done(db, st, "storing a terminal", err)) != AG_OK)
            return s;
        if ((s = ag_db_prepared(db, &st,
                                "INSERT OR IGNORE INTO part_version_terminals (part_id, version, "
                                "sha256) VALUES (?, ?, ?)",
                                err)) != AG_OK)
            return s;
        sqlite3_bind_int64(st, 1, id);
        sqlite3_bind_int64(st, 2, p->version);
        sqlite3_bind_text(st, 3, t->sha256, -1, SQLITE_STATIC);
        if ((s = ag_db_step_done(db, st, "storing a terminal", err)) != AG_OK)
            return s;
    }
    return AG_OK;
}

static ag_status check_new(const ag_part_new *p, ag_error *err)
{
    if (!p->name || !p->entry_json || p->version < 1)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "a part version needs a name, an entry "
                                                     "and a version");
    for (size_t i = 0; i < p->nterminals; i++)
        if (!p->terminals[i].sha256 || strlen(p->terminals[i].sha256) != 64)
            return ag_error_set(err, AG_ERR_INTERNAL, 0, "a terminal needs its SHA-256");
    return AG_OK;
}

ag_status ag_parts_insert(ag_db *db, const ag_part_new *p, int64_t *id, ag_error *err)
{
    *id = 0;
    ag_status s = check_new(p, err);
    sqlite3_stmt *st;
    if (s == AG_OK)
        s = ag_db_prepared(db, &st,
                           "INSERT INTO parts (name, description, version) VALUES (?, ?, ?)", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_text(st, 1, p->name, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, p->description ? p->description : "", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, p->version);
    if ((s = ag_db_step_done(db, st, "storing a part", err)) != AG_OK)
        return s;
    int64_t new_id = sqlite3_last_insert_rowid(ag_db_handle(db));
    if ((s = put_version(db, new_id, p, err)) == AG_OK &&
        (s = put_metadata(db, new_id, p, err)) == AG_OK)
        *id = new_id;
    return s;
}

/* The newest version of a part: AG_ERR_NOT_FOUND without it. */
static ag_status newest(ag_db *db, int64_t id, int64_t *version, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "SELECT version FROM parts WHERE id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        *version = sqlite3_column_int64(st, 0);
    else if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no part %lld", (long long)id);
    else
        s = ag_db_fail(db, err, "reading a part");
    sqlite3_reset(st);
    return s;
}

ag_status ag_parts_add_version(ag_db *db, int64_t id, int64_t base, const ag_part_new *p,
                               ag_error *err)
{
    int64_t have = 0;
    ag_status s = check_new(p, err);
    if (s == AG_OK)
        s = newest(db, id, &have, err);
    if (s != AG_OK)
        return s;
    if (have != base)
        return ag_error_set(err, AG_ERR_STALE, (long)have,
                            "part %lld is at version %lld, not %lld", (long long)id,
                            (long long)have, (long long)base);
    if ((int64_t)p->version != base + 1)
        return ag_error_set(err, AG_ERR_INTERNAL, 0, "the new version of part %lld is %lld",
                            (long long)id, (long long)base + 1);
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st,
                            "UPDATE parts SET name = ?, description = ?, version = ?, "
                            "updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE id = ?",
                            err)) != AG_OK)
        return s;
    sqlite3_bind_text(st, 1, p->name, -1, SQLITE_STATIC);
    sqlite3_bind_text(st, 2, p->description ? p->description : "", -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, p->version);
    sqlite3_bind_int64(st, 4, id);
    if ((s = ag_db_step_done(db, st, "updating a part", err)) != AG_OK)
        return s;
    if ((s = put_version(db, id, p, err)) != AG_OK)
        return s;
    return put_metadata(db, id, p, err);
}

ag_status ag_parts_delete(ag_db *db, int64_t id, int64_t version, ag_error *err)
{
    int64_t have = 0;
    ag_status s = newest(db, id, &have, err);
    if (s != AG_OK)
        return s;
    if (have != version)
        return ag_error_set(err, AG_ERR_STALE, (long)have,
                            "part %lld is at version %lld, not %lld", (long long)id,
                            (long long)have, (long long)version);
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st, "DELETE FROM parts WHERE id = ?", err)) != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    return ag_db_step_done(db, st, "deleting a part", err);
}

/* --- reading ------------------------------------------------------------------------------ */

#define PART_COLUMNS "p.id, p.name, p.description, p.version, p.created_at, p.updated_at"

static ag_status read_tags(ag_db *db, ag_part_row *row, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "SELECT tag FROM part_tags WHERE part_id = ? ORDER BY position", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, row->id);
    size_t cap = 0;
    int rc, bad = 0;
    while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (row->ntags == cap) {
            cap = cap ? 2 * cap : 8;
            char **t = realloc(row->tags, cap * sizeof *t);
            if (!t) {
                s = nomem(err);
                break;
            }
            row->tags = t;
        }
        char *tag = ag_db_column_dup(st, 0, NULL, &bad);
        if (!tag)
            s = nomem(err);
        else
            row->tags[row->ntags++] = tag;
    }
    if (s == AG_OK && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading a part's tags");
    sqlite3_reset(st);
    return s;
}

/* The columns of PART_COLUMNS (tags are read after the statement is done with). */
static ag_status read_part(sqlite3_stmt *st, ag_part_row *row, ag_error *err)
{
    memset(row, 0, sizeof *row);
    int bad = 0;
    row->id = sqlite3_column_int64(st, 0);
    row->name = ag_db_column_dup(st, 1, NULL, &bad);
    row->description = ag_db_column_dup(st, 2, NULL, &bad);
    row->version = sqlite3_column_int64(st, 3);
    ag_db_column_copy(st, 4, row->created_at, sizeof row->created_at);
    ag_db_column_copy(st, 5, row->updated_at, sizeof row->updated_at);
    if (!row->name || !row->description) {
        ag_parts_row_clear(row);
        return nomem(err);
    }
    return AG_OK;
}

ag_status ag_parts_get(ag_db *db, int64_t id, ag_part_row *row, ag_error *err)
{
    memset(row, 0, sizeof *row);
    sqlite3_stmt *st;
    ag_status s =
        ag_db_prepared(db, &st, "SELECT " PART_COLUMNS " FROM parts p WHERE p.id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        s = read_part(st, row, err);
    else if (rc == SQLITE_DONE)
        s = ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no part %lld", (long long)id);
    else
        s = ag_db_fail(db, err, "reading a part");
    sqlite3_reset(st);
    if (s == AG_OK && (s = read_tags(db, row, err)) != AG_OK)
        ag_parts_row_clear(row);
    return s;
}

#define VERSION_COLUMNS                                                                        \
    "part_id, version, source_model, source_name, source_version, source_node, stats, "        \
    "length(thumbnail), created_at"

static ag_status read_version(sqlite3_stmt *st, int entry_col, ag_part_version_row *row,
                              ag_error *err)
{
    memset(row, 0, sizeof *row);
    int bad = 0;
    row->part = sqlite3_column_int64(st, 0);
    row->version = sqlite3_column_int64(st, 1);
    row->source_model = sqlite3_column_int64(st, 2);
    row->source_name = ag_db_column_dup(st, 3, NULL, &bad);
    row->source_version = sqlite3_column_int64(st, 4);
    row->source_node = sqlite3_column_int64(st, 5);
    row->stats_json = ag_db_column_dup(st, 6, NULL, &bad);
    row->thumbnail_bytes = (size_t)sqlite3_column_int64(st, 7);
    ag_db_column_copy(st, 8, row->created_at, sizeof row->created_at);
    if (entry_col >= 0)
        row->entry_json = ag_db_column_dup(st, entry_col, NULL, &bad);
    if (bad || !row->stats_json || (entry_col >= 0 && !row->entry_json)) {
        ag_parts_version_row_clear(row);
        return nomem(err);
    }
    return AG_OK;
}

ag_status ag_parts_versions(ag_db *db, int64_t id, ag_part_version_row **rows, size_t *n,
                            ag_error *err)
{
    *rows = NULL;
    *n = 0;
    int64_t have;
    ag_status s = newest(db, id, &have, err);
    sqlite3_stmt *st;
    if (s == AG_OK)
        s = ag_db_prepared(db, &st,
                           "SELECT " VERSION_COLUMNS " FROM part_versions WHERE part_id = ? "
                           "ORDER BY version DESC",
                           err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    ag_part_version_row *out = NULL;
    size_t cnt = 0, cap = 0;
    int rc;
    while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        if (cnt == cap) {
            cap = cap ? 2 * cap : 8;
            ag_part_version_row *q = realloc(out, cap * sizeof *q);
            if (!q) {
                s = nomem(err);
                break;
            }
            out = q;
        }
        if ((s = read_version(st, -1, &out[cnt], err)) == AG_OK)
            cnt++;
    }
    if (s == AG_OK && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading a part's versions");
    sqlite3_reset(st);
    if (s != AG_OK) {
        for (size_t i = 0; i < cnt; i++)
            ag_parts_version_row_clear(&out[i]);
        free(out);
        return s;
    }
    *rows = out;
    *n = cnt;
    return AG_OK;
}

/* The version a caller means: 0 is the newest. */
static ag_status resolve_version(ag_db *db, int64_t id, int64_t *version, ag_error *err)
{
    int64_t have;
    ag_status s = newest(db, id, &have, err);
    if (s == AG_OK && *version == 0)
        *version = have;
    return s;
}

/* A statement about one version (0: the newest) with the part and the version bound as ?1 and
 * ?2; *version becomes the one meant. */
static ag_status version_statement(ag_db *db, int64_t id, int64_t *version, const char *sql,
                                   sqlite3_stmt **st, ag_error *err)
{
    ag_status s = resolve_version(db, id, version, err);
    if (s == AG_OK)
        s = ag_db_prepared(db, st, sql, err);
    if (s == AG_OK) {
        sqlite3_bind_int64(*st, 1, id);
        sqlite3_bind_int64(*st, 2, *version);
    }
    return s;
}

static ag_status no_version(int64_t id, int64_t version, ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "part %lld has no version %lld", (long long)id,
                        (long long)version);
}

ag_status ag_parts_get_version(ag_db *db, int64_t id, int64_t version, int with_entry,
                               ag_part_version_row *row, ag_error *err)
{
    memset(row, 0, sizeof *row);
    sqlite3_stmt *st;
    ag_status s = version_statement(
        db, id, &version,
        with_entry ? "SELECT " VERSION_COLUMNS ", entry FROM part_versions "
                     "WHERE part_id = ?1 AND version = ?2"
                   : "SELECT " VERSION_COLUMNS " FROM part_versions "
                     "WHERE part_id = ?1 AND version = ?2",
        &st, err);
    if (s != AG_OK)
        return s;
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW)
        s = read_version(st, with_entry ? 9 : -1, row, err);
    else if (rc == SQLITE_DONE)
        s = no_version(id, version, err);
    else
        s = ag_db_fail(db, err, "reading a part version");
    sqlite3_reset(st);
    return s;
}

ag_status ag_parts_each_terminal(ag_db *db, int64_t id, int64_t version,
                                 ag_status (*each)(void *user, const char *sha256,
                                                   const char *obj, size_t len),
                                 void *user, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s = version_statement(db, id, &version,
                                    "SELECT t.sha256, t.obj FROM part_version_terminals v "
                                    "JOIN part_terminals t ON t.sha256 = v.sha256 "
                                    "WHERE v.part_id = ?1 AND v.version = ?2 ORDER BY t.sha256",
                                    &st, err);
    if (s != AG_OK)
        return s;
    int rc;
    while (s == AG_OK && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        const char *sha = (const char *)sqlite3_column_text(st, 0);
        const char *obj = (const char *)sqlite3_column_text(st, 1);
        size_t len = (size_t)sqlite3_column_bytes(st, 1);
        s = each(user, sha ? sha : "", obj ? obj : "", len);
    }
    if (s == AG_OK && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "reading a part's terminals");
    sqlite3_reset(st);
    return s;
}

ag_status ag_parts_thumbnail(ag_db *db, int64_t id, int64_t version, void **png, size_t *len,
                             ag_error *err)
{
    *png = NULL;
    *len = 0;
    sqlite3_stmt *st;
    ag_status s = version_statement(
        db, id, &version,
        "SELECT thumbnail FROM part_versions WHERE part_id = ?1 AND version = ?2", &st, err);
    if (s != AG_OK)
        return s;
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        size_t n = (size_t)sqlite3_column_bytes(st, 0);
        void *b = malloc(n ? n : 1);
        if (!b)
            s = nomem(err);
        else {
            if (n)
                memcpy(b, sqlite3_column_blob(st, 0), n);
            *png = b;
            *len = n;
        }
    } else if (rc == SQLITE_DONE) {
        s = no_version(id, version, err);
    } else {
        s = ag_db_fail(db, err, "reading a thumbnail");
    }
    sqlite3_reset(st);
    return s;
}

/* The FTS5 expression of a search text: every word a quoted prefix, all required. Words are
 * what the index's tokenizer (unicode61) keeps: runs of letters, digits and non-ASCII
 * characters; everything else separates them, so no text can be read as FTS5 syntax. */
static ag_status match_expr(const char *q, char *out, size_t cap, int *words, ag_error *err)
{
    *words = 0;
    size_t len = strlen(q), w = 0;
    if (len > AG_PARTS_QUERY_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "q: at most %d bytes", AG_PARTS_QUERY_MAX);
    out[0] = '\0';
    for (size_t i = 0; i < len;) {
        unsigned char c = (unsigned char)q[i];
        int word = c >= 0x80 || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') ||
                   (c >= 'A' && c <= 'Z');
        if (!word) {
            i++;
            continue;
        }
        if (++*words > MAX_WORDS)
            return ag_error_set(err, AG_ERR_INVALID, 0, "q: at most %d words", MAX_WORDS);
        if (w + 4 >= cap)
            return ag_error_set(err, AG_ERR_INVALID, 0, "q: too long");
        if (w)
            out[w++] = ' ';
        out[w++] = '"';
        while (i < len) {
            c = (unsigned char)q[i];
            if (!(c >= 0x80 || (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') ||
                  (c >= 'A' && c <= 'Z')))
                break;
            if (w + 4 >= cap)
                return ag_error_set(err, AG_ERR_INVALID, 0, "q: too long");
            out[w++] = (char)c;
            i++;
        }
        out[w++] = '"';
        out[w++] = '*';
        out[w] = '\0';
    }
    return AG_OK;
}

ag_status ag_parts_search(ag_db *db, const ag_parts_query *q, ag_part_row **rows, size_t *n,
                          int *more, ag_error *err)
{
    *rows = NULL;
    *n = 0;
    *more = 0;
    char expr[4 * AG_PARTS_QUERY_MAX + 64];
    int words = 0;
    ag_status s = match_expr(q->q ? q->q : "", expr, sizeof expr, &words, err);
    if (s != AG_OK)
        return s;
    int text = words > 0, tag = q->tag != NULL;
    static const char *const sql[4] = {
        "SELECT " PART_COLUMNS " FROM parts p ORDER BY p.id LIMIT ? OFFSET ?",
        "SELECT " PART_COLUMNS " FROM parts p WHERE EXISTS (SELECT 1 FROM part_tags t "
        "WHERE t.part_id = p.id AND t.tag = ?2) ORDER BY p.id LIMIT ? OFFSET ?",
        "SELECT " PART_COLUMNS " FROM parts_search s JOIN parts p ON p.id = s.rowid "
        "WHERE parts_search MATCH ?3 ORDER BY s.rank, p.id LIMIT ? OFFSET ?",
        "SELECT " PART_COLUMNS " FROM parts_search s JOIN parts p ON p.id = s.rowid "
        "WHERE parts_search MATCH ?3 AND EXISTS (SELECT 1 FROM part_tags t WHERE "
        "t.part_id = p.id AND t.tag = ?2) ORDER BY s.rank, p.id LIMIT ? OFFSET ?",
    };
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st, sql[2 * text + tag], err)) != AG_OK)
        return s;
    /* the tag is ?2 and the text ?3 where they occur; LIMIT and OFFSET, unnumbered, are the
     * statement's last two parameters */
    int nparams = sqlite3_bind_parameter_count(st);
    size_t want = q->limit + 1; /* one more tells whether another page follows */
    sqlite3_bind_int64(st, nparams - 1, (sqlite3_int64)want);
    sqlite3_bind_int64(st, nparams, (sqlite3_int64)q->offset);
    if (tag)
        sqlite3_bind_text(st, 2, q->tag, -1, SQLITE_STATIC);
    if (text)
        sqlite3_bind_text(st, 3, expr, -1, SQLITE_STATIC);
    ag_part_row *out = calloc(want, sizeof *out);
    size_t cnt = 0;
    int rc = SQLITE_DONE;
    if (!out)
        s = nomem(err);
    while (s == AG_OK && cnt < want && (rc = sqlite3_step(st)) == SQLITE_ROW)
        if ((s = read_part(st, &out[cnt], err)) == AG_OK)
            cnt++;
    if (s == AG_OK && rc != SQLITE_DONE && rc != SQLITE_ROW)
        s = ag_db_fail(db, err, "searching the parts");
    sqlite3_reset(st);
    for (size_t i = 0; s == AG_OK && i < cnt; i++)
        s = read_tags(db, &out[i], err);
    if (s != AG_OK) {
        for (size_t i = 0; i < cnt; i++)
            ag_parts_row_clear(&out[i]);
        free(out);
        return s;
    }
    if (cnt > q->limit) {
        ag_parts_row_clear(&out[q->limit]);
        cnt = q->limit;
        *more = 1;
    }
    *rows = out;
    *n = cnt;
    return AG_OK;
}

static size_t count_of(ag_db *db, const char *sql)
{
    sqlite3_stmt *st = ag_db_prepare(db, sql, NULL);
    size_t n = 0;
    if (st && sqlite3_step(st) == SQLITE_ROW)
        n = (size_t)sqlite3_column_int64(st, 0);
    if (st)
        sqlite3_reset(st);
    return n;
}

size_t ag_parts_count(ag_db *db)
{
    return count_of(db, "SELECT count(*) FROM parts");
}

size_t ag_parts_count_terminals(ag_db *db)
{
    return count_of(db, "SELECT count(*) FROM part_terminals");
}
