/* The sweep's state: active edges and corners, the shell they build, and the virtual
 * height in which horizontal profile segments get an interval of their own. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "skel.h"
#include "../base/tolerance.h"

int ag__skel_vpush(sk_u32vec *v, uint32_t x)
{
    if (ag_array_reserve((void **)&v->arr, &v->cap, v->n + 1, sizeof(uint32_t)) != AG_OK)
        return 0;
    v->arr[v->n++] = x;
    return 1;
}

void ag__skel_fail(sk *S, ag_status st)
{
    if (S->st == AG_OK)
        S->st = st;
}

/* Real height of virtual height v. */
double ag__skel_real_z(const sk *S, double v)
{
    for (size_t k = 0; k < S->nflat; k++) {
        double vs = S->flat_h[k] + (double)k;
        if (v < vs)
            return v - (double)k;
        if (v <= vs + 1)
            return S->flat_h[k];
    }
    return v - (double)S->nflat;
}

/* Virtual height of real height z: `after` places z behind a flat interval at z. */
double ag__skel_virtual_z(const sk *S, double z, int after)
{
    size_t k = 0;
    while (k < S->nflat && (S->flat_h[k] < z || (after && S->flat_h[k] == z)))
        k++;
    return z + (double)k;
}

uint32_t ag__skel_vertex(sk *S, double x, double y, double z)
{
    z = ag__skel_real_z(S, z);
    uint32_t id = 0;
    if (ag_shell_add_vertex(S->shell, x + S->ox, y + S->oy, z, &id) != AG_OK)
        ag__skel_fail(S, AG_ERR_NOMEM);
    return id;
}

void ag__skel_seg(sk *S, uint32_t face, uint32_t a, uint32_t b)
{
    if (ag_shell_add_segment(S->shell, face, a, b) != AG_OK)
        ag__skel_fail(S, AG_ERR_NOMEM);
}

uint32_t ag__skel_new_face(sk *S, const sk_edge *e)
{
    ag_shell_face f = {AG_SHELL_FACE_SIDE, e->loop, e->edge, e->profile, e->seg, 0, 0};
    if (e->growing)
        f.segment = -1; /* the flat growth of a plan edit */
    uint32_t id = 0;
    if (ag_shell_add_face(S->shell, &f, &id) != AG_OK)
        ag__skel_fail(S, AG_ERR_NOMEM);
    return id;
}

uint32_t ag__skel_add_edge(sk *S)
{
    if (ag_array_reserve((void **)&S->e, &S->cap_e, S->ne + 1, sizeof(sk_edge)) != AG_OK ||
        ag_array_reserve((void **)&S->live_e, &S->cap_live_e, S->nlive_e + 1, sizeof(uint32_t)) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return NONE;
    }
    memset(&S->e[S->ne], 0, sizeof(sk_edge));
    S->e[S->ne].alive = 1;
    S->e[S->ne].start = S->e[S->ne].end = NONE;
    S->live_e[S->nlive_e++] = (uint32_t)S->ne;
    return (uint32_t)S->ne++;
}

/* A corner joining edge `in` to edge `out` at (x, y, z); velocity is set by settle(). */
uint32_t ag__skel_add_corner(sk *S, uint32_t in, uint32_t out, double x, double y, double z,
                           uint32_t vert)
{
    if (ag_array_reserve((void **)&S->c, &S->cap_c, S->nc + 1, sizeof(sk_corner)) != AG_OK ||
        ag_array_reserve((void **)&S->touched, &S->cap_touched, S->ntouched + 1, sizeof(uint32_t)) != AG_OK ||
        ag_array_reserve((void **)&S->live_c, &S->cap_live_c, S->nlive_c + 1, sizeof(uint32_t)) != AG_OK) {
        ag__skel_fail(S, AG_ERR_NOMEM);
        return NONE;
    }
    uint32_t k = (uint32_t)S->nc++;
    sk_corner *c = &S->c[k];
    memset(c, 0, sizeof *c);
    c->next_split = INFINITY;
    c->x = x;
    c->y = y;
    c->z = z;
    c->in = in;
    c->out = out;
    c->vert = vert;
    c->alive = 1;
    S->e[in].end = k;
    S->e[in].ver++;
    S->e[out].start = k;
    S->e[out].ver++;
    S->touched[S->ntouched++] = k;
    S->live_c[S->nlive_c++] = k;
    if (S->track_made && !S->no_winding_repair) {
        if (!S->made.n)
            S->made_z = S->zcur;
        if (!ag__skel_vpush(&S->made, k))
            ag__skel_fail(S, AG_ERR_NOMEM);
    }
    return k;
}

/* The corner stops at vertex v: its arc closes the faces on both sides. */
void ag__skel_retire(sk *S, uint32_t k, uint32_t v)
{
    sk_corner *c = &S->c[k];
    if (!c->alive)
        return;
    ag__skel_seg(S, S->e[c->in].face, c->vert, v);
    ag__skel_seg(S, S->e[c->out].face, v, c->vert);
    c->alive = 0;
}

void ag__skel_kill_edge(sk *S, uint32_t e)
{
    S->e[e].alive = 0;
    S->e[e].ver++;
}

/* Bytes held by the sweep's state and its shell so far (for the memory budget). */
static size_t state_bytes(const sk *S)
{
    const ag_shell *sh = S->shell;
    return S->cap_e * sizeof(sk_edge) + S->cap_c * sizeof(sk_corner) +
           (S->cap_live_c + S->cap_live_e + S->cap_touched) * sizeof(uint32_t) +
           S->q.cap * sizeof(ag_event) + sh->cap_verts * 3 * sizeof(double) +
           sh->cap_faces * sizeof(ag_shell_face) + sh->cap_segs * 3 * sizeof(uint32_t);
}

static void spend(sk *S)
{
    if (S->st == AG_OK && ag_budget_spend(S->budget, 1, state_bytes(S)) != AG_OK) {
        ag_error_set(S->err, S->budget->st, 0, "the extrusion was %s, at height %.4g m",
                     S->budget->why, ag__skel_real_z(S, S->zcur));
        ag__skel_fail(S, S->budget->st);
    }
}

void ag__skel_work(sk *S, size_t n)
{
    if (S->st == AG_OK && ag_budget_work(S->budget, n, state_bytes(S)) != AG_OK) {
        ag_error_set(S->err, S->budget->st, 0, "the extrusion was %s, at height %.4g m",
                     S->budget->why, ag__skel_real_z(S, S->zcur));
        ag__skel_fail(S, S->budget->st);
    }
}

void ag__skel_push(sk *S, const ag_event *ev)
{
    spend(S);
    if (S->st == AG_OK && ag_eventq_push(&S->q, ev) != AG_OK)
        ag__skel_fail(S, AG_ERR_NOMEM);
}

int ag__skel_pop(sk *S, ag_event *ev)
{
    spend(S);
    return S->st == AG_OK && ag_eventq_pop(&S->q, ev);
}

void ag__skel_compact_live(sk *S)
{
    size_t w = 0;
    for (size_t i = 0; i < S->nlive_c; i++)
        if (S->c[S->live_c[i]].alive)
            S->live_c[w++] = S->live_c[i];
    S->nlive_c = w;
    w = 0;
    for (size_t i = 0; i < S->nlive_e; i++)
        if (S->e[S->live_e[i]].alive)
            S->live_e[w++] = S->live_e[i];
    S->nlive_e = w;
}

double ag__skel_seg_slope(const ag_profile *p, int32_t seg)
{
    const ag_profile_point *a = &p->points[seg], *b = &p->points[seg + 1];
    if (b->z == a->z)
        return b->w - a->w;
    return (b->w - a->w) / (b->z - a->z);
}

int ag__skel_seg_flat(const ag_profile *p, int32_t seg)
{
    return p->points[seg + 1].z == p->points[seg].z;
}

/* Plane order by coefficients: the same three planes always come in the same order. */
static int plane_before(const sk_edge *a, const sk_edge *b)
{
    if (a->nx != b->nx)
        return a->nx < b->nx;
    if (a->ny != b->ny)
        return a->ny < b->ny;
    if (a->s != b->s)
        return a->s < b->s;
    return a->c < b->c;
}

int ag__skel_meet3(const sk *S, uint32_t e1, uint32_t e2, uint32_t e3, double *x, double *y,
                   double *z)
{
    const sk_edge *p[3] = {&S->e[e1], &S->e[e2], &S->e[e3]};
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0 && plane_before(p[j], p[j - 1]); j--) {
            const sk_edge *t = p[j];
            p[j] = p[j - 1];
            p[j - 1] = t;
        }
    /* nx x + ny y - s z = c, by Gaussian elimination with partial pivoting in extended
     * precision */
    long double A[3][4];
    for (int i = 0; i < 3; i++) {
        A[i][0] = p[i]->nx;
        A[i][1] = p[i]->ny;
        A[i][2] = -p[i]->s;
        A[i][3] = p[i]->c;
    }
    for (int col = 0; col < 3; col++) {
        int piv = col;
        for (int r = col + 1; r < 3; r++)
            if (fabsl(A[r][col]) > fabsl(A[piv][col]))
                piv = r;
        if (!(fabsl(A[piv][col]) > AG_EXTRUDE_MEET_PIVOT))
            return 0;
        if (piv != col)
            for (int k = 0; k < 4; k++) {
                long double t = A[col][k];
                A[col][k] = A[piv][k];
                A[piv][k] = t;
            }
        for (int r = col + 1; r < 3; r++) {
            long double f = A[r][col] / A[col][col];
            for (int k = col; k < 4; k++)
                A[r][k] -= f * A[col][k];
        }
    }
    long double r[3];
    for (int i = 2; i >= 0; i--) {
        long double v = A[i][3];
        for (int k = i + 1; k < 3; k++)
            v -= A[i][k] * r[k];
        r[i] = v / A[i][i];
    }
    if (!isfinite((double)r[0]) || !isfinite((double)r[1]) || !isfinite((double)r[2]))
        return 0;
    *x = (double)r[0];
    *y = (double)r[1];
    *z = (double)r[2];
    return 1;
}
