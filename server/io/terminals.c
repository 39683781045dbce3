#include "terminals.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "obj.h"

ag_status ag_terminals_format(const ag_gterminal *t, char **out, size_t *len, ag_error *err)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t v = 0; v < t->nverts; v++) {
        const double *p = t->pos + 3 * v;
        double x = p[0] == 0 ? 0 : p[0], y = p[1] == 0 ? 0 : p[1], z = p[2] == 0 ? 0 : p[2];
        fprintf(f, "v %.10g %.10g %.10g\n", x, y, z);
    }
    for (size_t k = 0; k < t->ntris; k++)
        fprintf(f, "f %u %u %u\n", t->tri[3 * k] + 1, t->tri[3 * k + 1] + 1, t->tri[3 * k + 2] + 1);
    if (fclose(f) || !buf) {
        free(buf);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    *out = buf;
    *len = n;
    return AG_OK;
}

static uint64_t fnv1a(const char *s, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t i = 0; i < n; i++) {
        h ^= (unsigned char)s[i];
        h *= 0x100000001b3ULL;
    }
    return h;
}

void ag_terminals_set_clear(ag_terminal_set *s)
{
    for (size_t i = 0; i < s->n; i++) {
        free(s->path[i]);
        free(s->obj[i]);
    }
    free(s->path);
    free(s->obj);
    free(s->len);
    memset(s, 0, sizeof *s);
}

ag_status ag_terminals_set_init(ag_terminal_set *s, size_t nterminals, ag_error *err)
{
    size_t cap = nterminals + 1;
    s->path = calloc(cap, sizeof *s->path);
    s->obj = calloc(cap, sizeof *s->obj);
    s->len = calloc(cap, sizeof *s->len);
    if (!s->path || !s->obj || !s->len)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return AG_OK;
}

ag_status ag_terminals_set_add(ag_terminal_set *s, ag_gterminal *t, char *bytes, size_t len,
                               const char *ext, ag_error *err)
{
    char path[64];
    snprintf(path, sizeof path, "terminals/%016llx.%s", (unsigned long long)fnv1a(bytes, len),
             ext);
    free(t->path);
    if (!(t->path = strdup(path))) {
        free(bytes);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t k = 0; k < s->n; k++)
        if (!strcmp(s->path[k], path)) {
            free(bytes); /* an equal terminal's file */
            return AG_OK;
        }
    if (!(s->path[s->n] = strdup(path))) {
        free(bytes);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    s->obj[s->n] = bytes;
    s->len[s->n] = len;
    s->bytes += len;
    s->n++;
    return AG_OK;
}

ag_status ag_terminals_collect(ag_grammar *g, ag_terminal_set *s, ag_error *err)
{
    ag_status st = ag_terminals_set_init(s, g->nterminals, err);
    for (size_t i = 0; st == AG_OK && i < g->nterminals; i++) {
        char *text;
        size_t len;
        if ((st = ag_terminals_format(&g->terminals[i], &text, &len, err)) == AG_OK)
            st = ag_terminals_set_add(s, &g->terminals[i], text, len, "obj", err);
    }
    return st;
}

ag_status ag_terminals_set_lookup(void *user, const char *path, char **obj, size_t *len,
                                  ag_error *err)
{
    const ag_terminal_set *s = user;
    for (size_t i = 0; i < s->n; i++) {
        if (strcmp(s->path[i], path) != 0)
            continue;
        if (!(*obj = malloc(s->len[i] + 1)))
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        memcpy(*obj, s->obj[i], s->len[i]);
        (*obj)[s->len[i]] = '\0';
        *len = s->len[i];
        return AG_OK;
    }
    return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "no terminal %s", path);
}

ag_status ag_terminals_write(ag_grammar *g, const char *dir, size_t *bytes, ag_error *err)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/terminals", dir);
    if (mkdir(path, 0777) && errno != EEXIST)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
    ag_terminal_set set = {0};
    ag_status st = ag_terminals_collect(g, &set, err);
    for (size_t i = 0; st == AG_OK && i < set.n; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, set.path[i]);
        FILE *f = fopen(path, "wb");
        int ok = f && fwrite(set.obj[i], 1, set.len[i], f) == set.len[i];
        if (f && fclose(f))
            ok = 0;
        if (!ok)
            st = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(errno));
    }
    if (st == AG_OK && bytes)
        *bytes = set.bytes;
    ag_terminals_set_clear(&set);
    return st;
}

static int safe_path(const char *p)
{
    if (!*p || p[0] == '/' || strchr(p, '\\'))
        return 0;
    const char *s = p;
    while (*s) {
        const char *e = strchr(s, '/');
        size_t n = e ? (size_t)(e - s) : strlen(s);
        if ((n == 2 && !memcmp(s, "..", 2)) || n == 0)
            return 0;
        if (!e)
            break;
        s = e + 1;
    }
    return 1;
}

int ag_terminals_path_is_safe(const char *path)
{
    return path && safe_path(path);
}

ag_status ag_terminals_load_buffer(ag_gterminal *t, const char *data, size_t len, ag_error *err)
{
    ag_obj_read_options o = {.up = AG_UP_Z};
    ag_mesh *m = NULL;
    ag_error e = {0};
    ag_status st = ag_obj_read_buffer(data, len, &o, &m, &e);
    if (st)
        return ag_error_set(err, st, e.element, "terminal '%s': %s", t->name, e.text);
    st = ag_grammar_set_terminal_geometry(t, m->pos, m->nverts, m->tri, m->ntris);
    ag_mesh_free(m);
    if (st)
        return ag_error_set(err, st, 0, "out of memory");
    return AG_OK;
}

ag_status ag_terminals_load(ag_grammar *g, const char *dir, ag_error *err)
{
    for (size_t i = 0; i < g->nterminals; i++) {
        ag_gterminal *t = &g->terminals[i];
        if (!t->path || !safe_path(t->path))
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "terminal '%s' has an unsafe or empty path '%s'", t->name,
                                t->path ? t->path : "");
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, t->path);
        ag_obj_read_options o = {.up = AG_UP_Z};
        ag_mesh *m = NULL;
        ag_error e = {0};
        ag_status st = ag_obj_read_file(path, &o, &m, &e);
        if (st)
            return ag_error_set(err, st, e.element, "terminal '%s' (%s): %s", t->name, t->path,
                                e.text);
        st = ag_grammar_set_terminal_geometry(t, m->pos, m->nverts, m->tri, m->ntris);
        ag_mesh_free(m);
        if (st)
            return ag_error_set(err, st, 0, "out of memory");
    }
    return AG_OK;
}
