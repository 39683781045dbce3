#include "part_library.h"

#include <jansson.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../io/part_bundle.h"
#include "../store/parts.h"
#include "part_media.h"

/* A part as the tables keep it, made before the transaction begins. */
typedef struct {
    json_t *terminals;             /* sha256 -> OBJ text */
    char *entry;
    ag_part_terminal_text *terms;
    size_t nterms;
    uint8_t *png;
    size_t png_len;
    char *stats;
    const char **tags;
} stored;

static void stored_clear(stored *s)
{
    json_decref(s->terminals);
    free(s->entry);
    free(s->terms);
    free(s->png);
    free(s->stats);
    free(s->tags);
    memset(s, 0, sizeof *s);
}

static char *stats_of(const ag_part *p, const ag_mesh *m)
{
    size_t visible = 0;
    for (size_t i = 0; i < p->nnodes; i++)
        visible += p->nodes[i].kind == AG_NODE_COMPONENT;
    json_t *j = json_pack("{s:I,s:I,s:I,s:I,s:I,s:[f,f,f],s:i}", "nodes", (json_int_t)p->nnodes,
                          "visible", (json_int_t)visible, "rules", (json_int_t)p->grammar->nrules,
                          "terminals", (json_int_t)p->grammar->nterminals, "triangles",
                          (json_int_t)m->ntris, "size", p->box.max[0] - p->box.min[0],
                          p->box.max[1] - p->box.min[1], p->box.max[2] - p->box.min[2],
                          "facing", p->facing);
    char *s = j ? json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))
                : NULL;
    json_decref(j);
    return s;
}

/* The thumbnail and the stats: the part derived and pictured (a thread of its own while the
 * entry is encoded; both only read the part). */
typedef struct {
    const ag_part *p;
    uint8_t *png;
    size_t png_len;
    char *stats;
    ag_status s;
    ag_error err;
} pictured;

static void *picture(void *arg)
{
    pictured *x = arg;
    ag_mesh *m = NULL;
    ag_error_clear(&x->err);
    x->s = ag_part_media_mesh(x->p, &m, &x->err);
    if (x->s == AG_OK)
        x->s = ag_part_media_picture(m, x->p->facing, AG_PART_THUMBNAIL_SIDE, &x->png,
                                     &x->png_len, &x->err);
    if (x->s == AG_OK && !(x->stats = stats_of(x->p, m)))
        x->s = ag_error_set(&x->err, AG_ERR_NOMEM, 0, "out of memory");
    ag_mesh_free(m);
    return NULL;
}

static ag_status prepare(const ag_part *p, stored *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    ag_status s = ag_part_validate(p, err);
    if (s != AG_OK)
        return s;
    pictured pic = {.p = p};
    pthread_t th;
    int threaded = pthread_create(&th, NULL, picture, &pic) == 0;
    if (s == AG_OK && !(out->terminals = json_object()))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t entry_len = 0;
    if (s == AG_OK)
        s = ag_part_bundle_entry_text(p, out->terminals, &out->entry, &entry_len, err);
    size_t nt = s == AG_OK ? json_object_size(out->terminals) : 0;
    if (s == AG_OK && nt && !(out->terms = calloc(nt, sizeof *out->terms)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK) {
        const char *key;
        json_t *v;
        json_object_foreach(out->terminals, key, v) {
            out->terms[out->nterms++] = (ag_part_terminal_text){key, json_string_value(v),
                                                                json_string_length(v)};
        }
    }
    if (s == AG_OK && p->ntags && !(out->tags = calloc(p->ntags, sizeof *out->tags)))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; s == AG_OK && i < p->ntags; i++)
        out->tags[i] = p->tags[i];
    if (threaded)
        pthread_join(th, NULL);
    else
        picture(&pic);
    out->png = pic.png;
    out->png_len = pic.png_len;
    out->stats = pic.stats;
    if (s == AG_OK && pic.s != AG_OK) {
        s = pic.s;
        if (err)
            *err = pic.err;
    }
    if (s != AG_OK)
        stored_clear(out);
    return s;
}

static ag_part_new row_of(const ag_part *p, const stored *st, const ag_part_library_source *from)
{
    return (ag_part_new){.version = p->version,
                         .name = p->name,
                         .description = p->description,
                         .tags = st->tags,
                         .ntags = p->ntags,
                         .entry_json = st->entry,
                         .terminals = st->terms,
                         .nterminals = st->nterms,
                         .source_model = from ? from->model : 0,
                         .source_name = p->source,
                         .source_version = p->source_version,
                         .source_node = p->source_node,
                         .thumbnail = st->png,
                         .thumbnail_len = st->png_len,
                         .stats_json = st->stats};
}

ag_status ag_part_library_save(ag_db *db, ag_part *p, const ag_part_library_source *from,
                               int64_t update, int64_t base, int64_t *id, int64_t *version,
                               ag_error *err)
{
    *id = 0;
    *version = 0;
    if (from) {
        char *name = from->name ? strdup(from->name) : NULL;
        if (from->name && !name)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        free(p->source);
        p->source = name;
        p->source_version = (long)from->version;
    }
    if (update) {
        if (base < 1)
            return ag_error_set(err, AG_ERR_INVALID, 0, "a new version names the version it "
                                                        "replaces");
        p->version = (unsigned)(base + 1);
    }
    stored st;
    ag_status s = prepare(p, &st, err);
    if (s != AG_OK)
        return s;
    ag_part_new row = row_of(p, &st, from);
    if ((s = ag_db_begin(db, err)) == AG_OK) {
        if (update) {
            s = ag_parts_add_version(db, update, base, &row, err);
            *id = update;
        } else {
            s = ag_parts_insert(db, &row, id, err);
        }
        s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    }
    if (s == AG_OK)
        *version = p->version;
    else
        *id = 0;
    stored_clear(&st);
    return s;
}

/* --- reading ------------------------------------------------------------------------------ */

static ag_status add_terminal(void *user, const char *sha256, const char *obj, size_t len)
{
    json_t *v = json_stringn(obj, len);
    if (!v || json_object_set_new(user, sha256, v))
        return AG_ERR_NOMEM;
    return AG_OK;
}

/* One version's entry (row, read with it) appended to parts, its terminals added to
 * terminals. */
static ag_status gather_row(ag_db *db, int64_t id, const ag_part_version_row *row, json_t *parts,
                            json_t *terminals, ag_error *err)
{
    ag_status s = AG_OK;
    json_error_t je;
    json_t *entry = json_loads(row->entry_json, 0, &je);
    if (!entry)
        s = ag_error_set(err, AG_ERR_INTERNAL, 0, "part %lld version %lld is not stored whole",
                         (long long)id, (long long)row->version);
    else if (json_array_append_new(parts, entry))
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK &&
        (s = ag_parts_each_terminal(db, id, row->version, add_terminal, terminals, err)) ==
            AG_ERR_NOMEM)
        ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return s;
}

static ag_status gather(ag_db *db, int64_t id, int64_t version, json_t *parts, json_t *terminals,
                        ag_error *err)
{
    ag_part_version_row row;
    ag_status s = ag_parts_get_version(db, id, version, 1, &row, err);
    if (s != AG_OK)
        return s;
    s = gather_row(db, id, &row, parts, terminals, err);
    ag_parts_version_row_clear(&row);
    return s;
}

/* Parts read back, by their stored entry. A part is a pure function of its entry and the
 * terminals the entry names by content, so an equal entry is the same part (whatever the
 * database); reading a large part back (the entry parsed, printed as a bundle and read again)
 * costs more than composing it, and a preview and the op after it read the same part. A few
 * parts, the least recently used going first, none whose entry is over a limit. */
#define PART_CACHE_SLOTS 8
#define PART_CACHE_MAX_ENTRY ((size_t)8 << 20)

typedef struct {
    char *entry;
    size_t len;
    ag_part *part;
    uint64_t used;
} cached_part;

static cached_part part_cache[PART_CACHE_SLOTS];
static uint64_t part_cache_clock;
static pthread_mutex_t part_cache_lock = PTHREAD_MUTEX_INITIALIZER;

/* A copy of the cached part read from entry; AG_ERR_NOT_FOUND when none is. */
static ag_status cache_get(const char *entry, ag_part **out, ag_error *err)
{
    size_t len = strlen(entry);
    ag_status s = AG_ERR_NOT_FOUND;
    pthread_mutex_lock(&part_cache_lock);
    for (size_t i = 0; i < PART_CACHE_SLOTS; i++) {
        cached_part *c = &part_cache[i];
        if (c->part && c->len == len && memcmp(c->entry, entry, len) == 0) {
            c->used = ++part_cache_clock;
            s = ag_part_copy(c->part, out, err);
            break;
        }
    }
    pthread_mutex_unlock(&part_cache_lock);
    return s;
}

/* Keeps a copy of p, read from entry (nothing when it is too large or memory is short). */
static void cache_put(const char *entry, const ag_part *p)
{
    size_t len = strlen(entry);
    if (len > PART_CACHE_MAX_ENTRY)
        return;
    char *e = malloc(len + 1);
    ag_part *c = NULL;
    if (!e || ag_part_copy(p, &c, NULL) != AG_OK) {
        free(e);
        return;
    }
    memcpy(e, entry, len + 1);
    pthread_mutex_lock(&part_cache_lock);
    size_t victim = 0;
    for (size_t i = 0; i < PART_CACHE_SLOTS; i++)
        if (!part_cache[i].part || part_cache[i].used < part_cache[victim].used) {
            victim = i;
            if (!part_cache[i].part)
                break;
        }
    cached_part old = part_cache[victim];
    part_cache[victim] = (cached_part){e, len, c, ++part_cache_clock};
    pthread_mutex_unlock(&part_cache_lock);
    free(old.entry);
    ag_part_free(old.part);
}

ag_status ag_part_library_load(ag_db *db, int64_t id, int64_t version, ag_part **out,
                               ag_error *err)
{
    *out = NULL;
    ag_part_version_row row;
    ag_status s = ag_parts_get_version(db, id, version, 1, &row, err);
    if (s != AG_OK)
        return s;
    if ((s = cache_get(row.entry_json, out, err)) != AG_ERR_NOT_FOUND) {
        ag_parts_version_row_clear(&row);
        return s;
    }
    json_t *parts = json_array(), *terminals = json_object();
    char *text = NULL;
    size_t len = 0;
    s = parts && terminals ? gather_row(db, id, &row, parts, terminals, err)
                           : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (s == AG_OK)
        s = ag_part_bundle_print(parts, terminals, &text, &len, err);
    json_decref(parts);
    json_decref(terminals);
    ag_part **list = NULL;
    size_t n = 0;
    if (s == AG_OK) {
        ag_error e;
        ag_error_clear(&e);
        if ((s = ag_part_bundle_read(text, len, &list, &n, &e)) != AG_OK)
            s = ag_error_set(err, s == AG_ERR_NOMEM ? s : AG_ERR_INTERNAL, 0,
                             "part %lld does not read back: %s", (long long)id, e.text);
    }
    free(text);
    if (s == AG_OK) {
        *out = list[0];
        list[0] = NULL;
        cache_put(row.entry_json, *out);
    }
    ag_part_bundle_free(list, n);
    ag_parts_version_row_clear(&row);
    return s;
}

ag_status ag_part_library_export(ag_db *db, const int64_t *ids, size_t n, int64_t version,
                                 char **text, size_t *len, ag_error *err)
{
    *text = NULL;
    *len = 0;
    int64_t *all = NULL;
    ag_status s = AG_OK;
    if (n == 0) { /* the whole library, by id */
        size_t count = ag_parts_count(db);
        if (count == 0)
            return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "the library holds no part");
        if (count > AG_PART_BUNDLE_MAX_PARTS)
            return ag_error_set(err, AG_ERR_TOO_LARGE, 0,
                                "the library holds %zu parts; a bundle holds at most %d", count,
                                AG_PART_BUNDLE_MAX_PARTS);
        ag_part_row *rows = NULL;
        ag_parts_query q = {.limit = count};
        int more = 0;
        if ((s = ag_parts_search(db, &q, &rows, &n, &more, err)) != AG_OK)
            return s;
        all = malloc((n ? n : 1) * sizeof *all);
        for (size_t i = 0; i < n; i++) {
            if (all)
                all[i] = rows[i].id;
            ag_parts_row_clear(&rows[i]);
        }
        free(rows);
        if (!all)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        ids = all;
        version = 0;
    } else if (n > AG_PART_BUNDLE_MAX_PARTS) {
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "a bundle holds at most %d parts",
                            AG_PART_BUNDLE_MAX_PARTS);
    }
    json_t *parts = json_array(), *terminals = json_object();
    if (!parts || !terminals)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; s == AG_OK && i < n; i++)
        s = gather(db, ids[i], n == 1 ? version : 0, parts, terminals, err);
    if (s == AG_OK)
        s = ag_part_bundle_print(parts, terminals, text, len, err);
    json_decref(parts);
    json_decref(terminals);
    free(all);
    return s;
}

ag_status ag_part_library_import(ag_db *db, const char *data, size_t len, int64_t **ids,
                                 size_t *n, ag_error *err)
{
    *ids = NULL;
    *n = 0;
    ag_part **parts = NULL;
    size_t np = 0;
    ag_status s = ag_part_bundle_read(data, len, &parts, &np, err);
    if (s != AG_OK)
        return s;
    stored *st = calloc(np, sizeof *st);
    int64_t *out = calloc(np, sizeof *out);
    if (!st || !out)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t made = 0;
    for (; s == AG_OK && made < np; made++) {
        if ((s = prepare(parts[made], &st[made], err)) != AG_OK) {
            char msg[AG_ERROR_TEXT];
            snprintf(msg, sizeof msg, "%s", err ? err->text : "");
            ag_error_set(err, s, 0, "parts[%zu]: %s", made, msg);
            break;
        }
    }
    if (s == AG_OK && (s = ag_db_begin(db, err)) == AG_OK) {
        for (size_t i = 0; s == AG_OK && i < np; i++) {
            ag_part_new row = row_of(parts[i], &st[i], NULL);
            s = ag_parts_insert(db, &row, &out[i], err);
        }
        s = s == AG_OK ? ag_db_commit(db, err) : (ag_db_rollback(db), s);
    }
    for (size_t i = 0; st && i < made; i++)
        stored_clear(&st[i]);
    free(st);
    ag_part_bundle_free(parts, np);
    if (s != AG_OK) {
        free(out);
        return s;
    }
    *ids = out;
    *n = np;
    return AG_OK;
}
