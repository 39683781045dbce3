#include "mesh.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Grows *arr (elements of size elem) so that it holds at least need elements. */
static int grow(void **arr, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t n = *cap ? *cap : 16;
    while (n < need) {
        if (n > SIZE_MAX / 2)
            return -1;
        n *= 2;
    }
    if (n > SIZE_MAX / elem)
        return -1;
    void *p = realloc(*arr, n * elem);
    if (!p)
        return -1;
    *arr = p;
    *cap = n;
    return 0;
}

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
    if (nverts > m->cap_verts) {
        if (nverts > SIZE_MAX / (3 * sizeof(double)))
            return AG_ERR_NOMEM;
        double *p = realloc(m->pos, nverts * 3 * sizeof(double));
        if (!p)
            return AG_ERR_NOMEM;
        m->pos = p;
        m->cap_verts = nverts;
    }
    if (ntris > m->cap_tris) {
        if (ntris > SIZE_MAX / (3 * sizeof(uint32_t)))
            return AG_ERR_NOMEM;
        uint32_t *t = realloc(m->tri, ntris * 3 * sizeof(uint32_t));
        if (!t)
            return AG_ERR_NOMEM;
        m->tri = t;
        uint32_t *c = realloc(m->tri_component, ntris * sizeof(uint32_t));
        if (!c)
            return AG_ERR_NOMEM;
        m->tri_component = c;
        m->cap_tris = ntris;
    }
    return AG_OK;
}

ag_status ag_mesh_add_vertex(ag_mesh *m, double x, double y, double z)
{
    if (m->nverts >= UINT32_MAX)
        return AG_ERR_TOO_LARGE; /* triangle indices are 32-bit */
    if (m->nverts == m->cap_verts) {
        size_t n = m->cap_verts ? m->cap_verts * 2 : 64;
        if (ag_mesh_reserve(m, n, m->cap_tris) != AG_OK)
            return AG_ERR_NOMEM;
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
        size_t n = m->cap_tris ? m->cap_tris * 2 : 64;
        if (ag_mesh_reserve(m, m->cap_verts, n) != AG_OK)
            return AG_ERR_NOMEM;
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
    if (grow((void **)&m->group_names, &m->cap_groups, m->ngroups + 1, sizeof(char *)))
        return AG_ERR_NOMEM;
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
    if (grow((void **)&m->component_group, &m->cap_components, m->ncomponents + 1,
             sizeof(int32_t)))
        return AG_ERR_NOMEM;
    m->component_group[m->ncomponents] = group;
    if (index)
        *index = m->ncomponents;
    m->ncomponents++;
    return AG_OK;
}

ag_box ag_mesh_bounds(const ag_mesh *m)
{
    ag_box b;
    for (int k = 0; k < 3; k++) {
        b.min[k] = INFINITY;
        b.max[k] = -INFINITY;
    }
    size_t n = 3 * m->ntris;
    for (size_t i = 0; i < n; i++) {
        const double *p = m->pos + 3 * (size_t)m->tri[i];
        for (int k = 0; k < 3; k++) {
            if (p[k] < b.min[k])
                b.min[k] = p[k];
            if (p[k] > b.max[k])
                b.max[k] = p[k];
        }
    }
    return b;
}

double ag_box_diagonal(const ag_box *b)
{
    if (!(b->min[0] <= b->max[0]) || !(b->min[1] <= b->max[1]) || !(b->min[2] <= b->max[2]))
        return 0.0;
    double dx = b->max[0] - b->min[0], dy = b->max[1] - b->min[1], dz = b->max[2] - b->min[2];
    return sqrt(dx * dx + dy * dy + dz * dz);
}

void ag_mesh_component_triangle_counts(const ag_mesh *m, size_t *counts)
{
    memset(counts, 0, m->ncomponents * sizeof *counts);
    for (size_t t = 0; t < m->ntris; t++)
        counts[m->tri_component[t]]++;
}

static uint32_t uf_find(uint32_t *parent, uint32_t v)
{
    uint32_t r = v;
    while (parent[r] != r)
        r = parent[r];
    while (parent[v] != r) { /* path compression */
        uint32_t next = parent[v];
        parent[v] = r;
        v = next;
    }
    return r;
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
    uint32_t *parent = malloc((nv ? nv : 1) * sizeof *parent);
    uint32_t *root_piece = malloc((nv ? nv : 1) * sizeof *root_piece);
    uint32_t *touched = malloc((nv ? nv : 1) * sizeof *touched);
    uint32_t *tri_piece = malloc(nt * sizeof *tri_piece);
    /* Pieces: their first triangle (unique, so it orders pieces) and their group. */
    uint32_t *piece_first = malloc(nt * sizeof *piece_first);
    int32_t *piece_group = malloc(nt * sizeof *piece_group);
    ag_status st = AG_ERR_NOMEM;
    if (!start || !order || !parent || !root_piece || !touched || !tri_piece || !piece_first ||
        !piece_group)
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
        parent[v] = root_piece[v] = NONE;

    size_t npieces = 0;
    for (size_t c = 0; c < nc; c++) {
        size_t ntouched = 0;
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            const uint32_t *tv = m->tri + 3 * (size_t)order[i];
            for (int k = 0; k < 3; k++)
                if (parent[tv[k]] == NONE) {
                    parent[tv[k]] = tv[k];
                    touched[ntouched++] = tv[k];
                }
            uint32_t r0 = uf_find(parent, tv[0]);
            for (int k = 1; k < 3; k++) {
                uint32_t r = uf_find(parent, tv[k]);
                if (r != r0)
                    parent[r] = r0;
            }
        }
        for (size_t i = start[c]; i < start[c + 1]; i++) {
            uint32_t t = order[i];
            uint32_t r = uf_find(parent, m->tri[3 * (size_t)t]);
            if (root_piece[r] == NONE) {
                root_piece[r] = (uint32_t)npieces;
                piece_first[npieces] = t;
                piece_group[npieces] = m->component_group[c];
                npieces++;
            }
            tri_piece[t] = root_piece[r];
        }
        for (size_t i = 0; i < ntouched; i++)
            parent[touched[i]] = root_piece[touched[i]] = NONE;
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
    free(parent);
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
