#include "mesh.h"

#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/uf.h"

ag_mesh *ag_mesh_create(void)
{
    return calloc(1, sizeof(ag_mesh));
}

void ag_mesh_free(ag_mesh *m)
{
    if (!m)
        return;
    for (size_t i = 0; i < m->ngroups; i++)
        free(m->group_names[i]);
    free(m->group_names);
    free(m->pos);
    free(m->tri);
    free(m->tri_component);
    free(m->component_group);
    free(m);
}

ag_status ag_mesh_reserve(ag_mesh *m, size_t nverts, size_t ntris)
{
    ag_status st = ag_array_reserve_exact((void **)&m->pos, &m->cap_verts, nverts,
                                          3 * sizeof *m->pos);
    if (st || ntris <= m->cap_tris)
        return st;
    /* two arrays, one capacity: it moves only once both have grown */
    size_t cap = m->cap_tris;
    if ((st = ag_array_reserve_exact((void **)&m->tri, &cap, ntris, 3 * sizeof *m->tri)))
        return st;
    cap = m->cap_tris;
    if ((st = AG_ARRAY_RESERVE_EXACT(m->tri_component, cap, ntris)))
        return st;
    m->cap_tris = ntris;
    return AG_OK;
}

ag_status ag_mesh_add_vertex(ag_mesh *m, double x, double y, double z)
{
    if (m->nverts >= UINT32_MAX)
        return AG_ERR_TOO_LARGE; /* triangle indices are 32-bit */
    if (m->nverts == m->cap_verts) {
        size_t n;
        ag_status st = ag_array_capacity(m->cap_verts, m->nverts + 1, 3 * sizeof *m->pos, &n);
        if (st || (st = ag_mesh_reserve(m, n, m->cap_tris)))
            return st;
    }
    double *p = m->pos + 3 * m->nverts++;
    p[0] = x;
    p[1] = y;
    p[2] = z;
    return AG_OK;
}

ag_status ag_mesh_add_triangle(ag_mesh *m, uint32_t a, uint32_t b, uint32_t c, uint32_t component)
{
    if (m->ntris == m->cap_tris) {
        size_t n;
        ag_status st = ag_array_capacity(m->cap_tris, m->ntris + 1, 3 * sizeof *m->tri, &n);
        if (st || (st = ag_mesh_reserve(m, m->cap_verts, n)))
            return st;
    }
    uint32_t *t = m->tri + 3 * m->ntris;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    m->tri_component[m->ntris++] = component;
    return AG_OK;
}

ag_status ag_mesh_add_group(ag_mesh *m, const char *name, size_t *index)
{
    ag_status st = AG_ARRAY_RESERVE(m->group_names, m->cap_groups, m->ngroups + 1);
    if (st)
        return st;
    char *copy = strdup(name ? name : "");
    if (!copy)
        return AG_ERR_NOMEM;
    m->group_names[m->ngroups] = copy;
    if (index)
        *index = m->ngroups;
    m->ngroups++;
    return AG_OK;
}

ag_status ag_mesh_add_component(ag_mesh *m, int32_t group, size_t *index)
{
    if (m->ncomponents >= UINT32_MAX)
        return AG_ERR_TOO_LARGE;
    ag_status st = AG_ARRAY_RESERVE(m->component_group, m->cap_components, m->ncomponents + 1);
    if (st)
        return st;
    m->component_group[m->ncomponents] = group;
    if (index)
        *index = m->ncomponents;
    m->ncomponents++;
    return AG_OK;
}

ag_box ag_mesh_bounds(const ag_mesh *m)
{
    /* ag_box_extend_point's comparisons (a NaN never wins either), in six scalars and
     * without branches: every commit of an edit summarizes its mesh, twice as fast so */
    ag_box b = ag_box_empty();
    double x0 = b.min[0], y0 = b.min[1], z0 = b.min[2], x1 = b.max[0], y1 = b.max[1],
           z1 = b.max[2];
    size_t n = 3 * m->ntris;
    for (size_t i = 0; i < n; i++) {
        const double *p = m->pos + 3 * (size_t)m->tri[i];
        x0 = p[0] < x0 ? p[0] : x0;
        x1 = p[0] > x1 ? p[0] : x1;
        y0 = p[1] < y0 ? p[1] : y0;
        y1 = p[1] > y1 ? p[1] : y1;
        z0 = p[2] < z0 ? p[2] : z0;
        z1 = p[2] > z1 ? p[2] : z1;
    }
    return (ag_box){{x0, y0, z0}, {x1, y1, z1}};
}

void ag_mesh_component_triangle_counts(const ag_mesh *m, size_t *counts)
{
    memset(counts, 0, m->ncomponents * sizeof *counts);
    for (size_t t = 0; t < m->ntris; t++)
        counts[m->tri_component[t]]++;
}

#define NONE UINT32_MAX

ag_status ag_mesh_split_connected(ag_mesh *m)
{
    size_t nc = m->ncomponents, nt = m->ntris, nv = m->nverts;
    if (nt == 0) {
        m->ncomponents = 0;
        return AG_OK;
    }
    /* Triangles grouped by component (counting sort, file order kept within each). */
    size_t *start = calloc(nc + 1, sizeof *start);
    uint32_t *order = malloc(nt * sizeof *order);
    /* connected pieces per component: vertices joined by triangles, reset after each one */
    ag_uf uf = {0};
    uint8_t *seen = calloc(nv + 1, 1);
    uint32_t *root_piece = malloc((nv ? nv : 1) * sizeof *root_piece);
    uint32_t *touched = malloc((nv ? nv : 1) * sizeof *touched);
    uint32_t *tri_piece = malloc(nt * sizeof *tri_piece);
    /* Pieces: their first triangle (unique, so it orders pieces) and their group. */
    uint32_t *piece_first = malloc(nt * sizeof *piece_first);
    int32_t *piece_group = malloc(nt * sizeof *piece_group);
    ag_status st = AG_ERR_NOMEM;
    if (ag_uf_init(&uf, nv, 0) || !start || !order || !seen || !root_piece || !touched ||
        !tri_piece || !piece_first || !piece_group)
        goto out;

    for (size_t t = 0; t < nt; t++)
        start[m->tri_component[t] + 1]++;
    for (size_t c = 0; c < nc; c++)
        start[c + 1] += start[c];
    {
        size_t *fill = malloc((nc ? nc : 1) * sizeof *fill);
        if (!fill)
            goto out;
        memcpy(fill, start, nc * sizeof *fill);
        for (size_t t = 0; t < nt; t++)
            order[fill[m->tri_component[t]]++] = (uint32_t)t;
        free(fill);
    }
    for (size_t v = 0; v < nv; v++)
        root_piece[v] = NONE;

    size_t npieces = 0;
    for (size_t c = 0; c < nc; c++) {
        size_t ntouched = 0;
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            const uint32_t *tv = m->tri + 3 * (size_t)order[i];
            for (int k = 0; k < 3; k++)
                if (!seen[tv[k]]) {
                    seen[tv[k]] = 1;
                    touched[ntouched++] = tv[k];
                }
            ag_uf_union(&uf, tv[0], tv[1]);
            ag_uf_union(&uf, tv[0], tv[2]);
        }
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            uint32_t t = order[i];
            uint32_t r = ag_uf_find(&uf, m->tri[3 * (size_t)t]);
            if (root_piece[r] == NONE) {
                root_piece[r] = (uint32_t)npieces;
                piece_first[npieces] = t;
                piece_group[npieces] = m->component_group[c];
                npieces++;
            }
            tri_piece[t] = root_piece[r];
        }
        for (size_t i = 0; i < ntouched; i++) {
            ag_uf_reset(&uf, touched[i]);
            seen[touched[i]] = 0;
            root_piece[touched[i]] = NONE;
        }
    }

    /* Renumber pieces by their first triangle: rank[p] via a triangle-indexed table. */
    uint32_t *rank_of_first = order; /* reuse: no longer needed */
    for (size_t t = 0; t < nt; t++)
        rank_of_first[t] = NONE;
    for (size_t p = 0; p < npieces; p++)
        rank_of_first[piece_first[p]] = (uint32_t)p;
    uint32_t *piece_rank = malloc(npieces * sizeof *piece_rank);
    int32_t *new_group = malloc(npieces * sizeof *new_group);
    if (!piece_rank || !new_group) {
        free(piece_rank);
        free(new_group);
        goto out;
    }
    uint32_t next = 0;
    for (size_t t = 0; t < nt; t++)
        if (rank_of_first[t] != NONE) {
            piece_rank[rank_of_first[t]] = next;
            new_group[next] = piece_group[rank_of_first[t]];
            next++;
        }
    for (size_t t = 0; t < nt; t++)
        m->tri_component[t] = piece_rank[tri_piece[t]];
    free(piece_rank);
    free(m->component_group);
    m->component_group = new_group;
    m->ncomponents = m->cap_components = npieces;
    st = AG_OK;
out:
    free(start);
    free(order);
    ag_uf_free(&uf);
    free(seen);
    free(root_piece);
    free(touched);
    free(tri_piece);
    free(piece_first);
    free(piece_group);
    return st;
}

void ag_mesh_compact_components(ag_mesh *m)
{
    if (m->ncomponents == 0)
        return;
    size_t *counts = calloc(m->ncomponents, sizeof *counts);
    if (!counts)
        return; /* out of memory: the mesh stays valid, only uncompacted */
    ag_mesh_component_triangle_counts(m, counts);
    size_t k = 0;
    for (size_t c = 0; c < m->ncomponents; c++) {
        if (counts[c]) {
            m->component_group[k] = m->component_group[c];
            counts[c] = k++; /* counts now holds the new index */
        }
    }
    for (size_t t = 0; t < m->ntris; t++)
        m->tri_component[t] = (uint32_t)counts[m->tri_component[t]];
    m->ncomponents = k;
    free(counts);
}

ag_mesh *ag_mesh_clone(const ag_mesh *m)
{
    ag_mesh *c = ag_mesh_create();
    if (!c)
        return NULL;
    if (ag_mesh_reserve(c, m->nverts, m->ntris) != AG_OK)
        goto fail;
    if (m->nverts)
        memcpy(c->pos, m->pos, m->nverts * 3 * sizeof(double));
    if (m->ntris) {
        memcpy(c->tri, m->tri, m->ntris * 3 * sizeof(uint32_t));
        memcpy(c->tri_component, m->tri_component, m->ntris * sizeof(uint32_t));
    }
    c->nverts = m->nverts;
    c->ntris = m->ntris;
    for (size_t g = 0; g < m->ngroups; g++)
        if (ag_mesh_add_group(c, m->group_names[g], NULL) != AG_OK)
            goto fail;
    for (size_t k = 0; k < m->ncomponents; k++)
        if (ag_mesh_add_component(c, m->component_group[k], NULL) != AG_OK)
            goto fail;
    return c;
fail:
    ag_mesh_free(c);
    return NULL;
}

const char *ag_mesh_difference(const ag_mesh *a, const ag_mesh *b)
{
    if (a->nverts != b->nverts || a->ntris != b->ntris)
        return "the vertex or triangle counts";
    if (a->ncomponents != b->ncomponents || a->ngroups != b->ngroups)
        return "the component or group counts";
    if (a->nverts && memcmp(a->pos, b->pos, 3 * a->nverts * sizeof *a->pos))
        return "the vertices";
    if (a->ntris && (memcmp(a->tri, b->tri, 3 * a->ntris * sizeof *a->tri) ||
                     memcmp(a->tri_component, b->tri_component, a->ntris * sizeof *a->tri_component)))
        return "the triangles";
    if (a->ncomponents && memcmp(a->component_group, b->component_group,
               a->ncomponents * sizeof *a->component_group))
        return "the components' groups";
    for (size_t i = 0; i < a->ngroups; i++)
        if (strcmp(a->group_names[i], b->group_names[i]))
            return "the group names";
    return "";
}
