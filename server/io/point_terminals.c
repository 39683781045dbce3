#include "point_terminals.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "filemap.h"
#include "ply.h"

static int names_ply(const char *p)
{
    size_t n = p ? strlen(p) : 0;
    return n > 4 && !strcasecmp(p + n - 4, ".ply");
}

int ag_point_terminals_is_point_grammar(const ag_grammar *g, ag_error *err)
{
    if (!g->nterminals)
        return 0;
    int first = names_ply(g->terminals[0].path);
    for (size_t i = 1; i < g->nterminals; i++)
        if (names_ply(g->terminals[i].path) != first) {
            ag_error_set(err, AG_ERR_PARSE, 0,
                         "terminal '%s' names a %s file but '%s' a %s one: a grammar's terminals "
                         "are all meshes or all point sets",
                         g->terminals[i].name, first ? "mesh" : "point", g->terminals[0].name,
                         first ? "point (.ply)" : "mesh");
            return -1;
        }
    return first;
}

ag_status ag_point_terminals_format(const ag_cloud *t, char **out, size_t *len, ag_error *err)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_ply_write_options o = {0};
    ag_status st = ag_ply_write(t, &o, f, err);
    if (fclose(f) && st == AG_OK)
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st != AG_OK || !buf) {
        free(buf);
        return st != AG_OK ? st : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    *out = buf;
    *len = n;
    return AG_OK;
}

ag_status ag_point_terminals_collect(ag_grammar *g, ag_cloud *const *clouds, ag_terminal_set *s,
                                     ag_error *err)
{
    ag_status st = ag_terminals_set_init(s, g->nterminals, err);
    for (size_t i = 0; st == AG_OK && i < g->nterminals; i++) {
        char *bytes;
        size_t len;
        if ((st = ag_point_terminals_format(clouds[i], &bytes, &len, err)) == AG_OK)
            st = ag_terminals_set_add(s, &g->terminals[i], bytes, len, "ply", err);
    }
    return st;
}

ag_status ag_point_terminals_decode(const ag_gterminal *t, const uint8_t *data, size_t len,
                                    ag_cloud **out, ag_error *err)
{
    *out = NULL;
    ag_error e = {0};
    ag_cloud *c;
    ag_status st = ag_ply_read_buffer(data, len, &c, &e);
    if (st != AG_OK)
        return ag_error_set(err, st, e.element, "terminal '%s' (%s): %s", t->name,
                            t->path ? t->path : "", e.text);
    /* local coordinates: any offset the file has is put back */
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++)
            c->xyz[3 * i + a] += c->offset[a];
    memset(c->offset, 0, sizeof c->offset);
    for (size_t i = 0; i < c->n; i++)
        for (int a = 0; a < 3; a++) {
            double v = c->xyz[3 * i + a], slack = 1e-3 * t->size[a] + 1e-4;
            if (!(v >= -slack && v <= t->size[a] + slack)) {
                ag_cloud_free(c);
                return ag_error_set(err, AG_ERR_PARSE, 0,
                                    "terminal '%s' (%s): point %zu has %c = %g, outside its box "
                                    "[0, %g]",
                                    t->name, t->path ? t->path : "", i + 1, "xyz"[a], v,
                                    t->size[a]);
            }
        }
    *out = c;
    return AG_OK;
}

ag_status ag_point_terminals_load(const ag_grammar *g, const char *dir, ag_cloud **clouds,
                                  ag_error *err)
{
    for (size_t i = 0; i < g->nterminals; i++) {
        const ag_gterminal *t = &g->terminals[i];
        clouds[i] = NULL;
        if (!ag_terminals_path_is_safe(t->path))
            return ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                "terminal '%s' has an unsafe or empty path '%s'", t->name,
                                t->path ? t->path : "");
        /* terminals share files: read each once */
        for (size_t k = 0; k < i && !clouds[i]; k++)
            if (clouds[k] && !strcmp(g->terminals[k].path, t->path) &&
                !memcmp(g->terminals[k].size, t->size, sizeof t->size)) {
                ag_status st = ag_cloud_clone(clouds[k], &clouds[i], err);
                if (st != AG_OK)
                    return st;
            }
        if (clouds[i])
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, t->path);
        ag_filemap fm;
        ag_error e = {0};
        if (ag_filemap_open(path, &fm, &e) != AG_OK)
            return ag_error_set(err, e.code ? e.code : AG_ERR_IO, 0, "terminal '%s' (%s): %s",
                                t->name, t->path, e.text);
        ag_status st = ag_point_terminals_decode(t, fm.data, fm.len, &clouds[i], err);
        ag_filemap_close(&fm);
        if (st != AG_OK)
            return st;
    }
    return AG_OK;
}
