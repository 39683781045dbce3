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

ag_status ag_terminals_write(ag_grammar *g, const char *dir, size_t *bytes, ag_error *err)
{
    size_t total = 0;
    char path[4096];
    snprintf(path, sizeof path, "%s/terminals", dir);
    if (mkdir(path, 0777) && errno != EEXIST)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
    uint64_t *hashes = malloc((g->nterminals + 1) * sizeof *hashes);
    if (!hashes)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < g->nterminals; i++) {
        ag_gterminal *t = &g->terminals[i];
        char *text;
        size_t len;
        ag_status st = ag_terminals_format(t, &text, &len, err);
        if (st) {
            free(hashes);
            return st;
        }
        uint64_t h = fnv1a(text, len);
        hashes[i] = h;
        int dup = 0;
        for (size_t k = 0; k < i; k++)
            dup |= hashes[k] == h;
        char rel[64];
        snprintf(rel, sizeof rel, "terminals/%016llx.obj", (unsigned long long)h);
        free(t->path);
        t->path = strdup(rel);
        if (!t->path) {
            free(text);
            free(hashes);
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        }
        if (!dup) {
            snprintf(path, sizeof path, "%s/%s", dir, rel);
            FILE *f = fopen(path, "wb");
            int ok = f && fwrite(text, 1, len, f) == len;
            if (f && fclose(f))
                ok = 0;
            if (!ok) {
                free(text);
                free(hashes);
                return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path,
                                    strerror(errno));
            }
            total += len;
        }
        free(text);
    }
    free(hashes);
    if (bytes)
        *bytes = total;
    return AG_OK;
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
