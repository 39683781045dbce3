#include "gframe.h"

#include "../base/tolerance.h"

const ag_gframe ag_gframe_identity = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {0, 0, 0}};

void ag_gframe_apply(const ag_gframe *f, const double x[3], double y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = f->M[i][0] * x[0] + f->M[i][1] * x[1] + f->M[i][2] * x[2] + f->t[i];
}

ag_gframe ag_gframe_place(const ag_gframe *F, const double S[3], int k, const ag_box *B)
{
    double Sr[3] = {S[0], S[1], S[2]};
    if (k & 1) {
        Sr[0] = S[1];
        Sr[1] = S[0];
    }
    double s[3];
    for (int a = 0; a < 3; a++) {
        s[a] = Sr[a] > AG_PROC_TINY ? ag_box_extent(B, a) / Sr[a] : 1.0;
    }
    /* k quarter turns about z */
    double c = (k & 3) == 0 ? 1 : (k & 3) == 2 ? -1 : 0;
    double sn = (k & 3) == 1 ? 1 : (k & 3) == 3 ? -1 : 0;
    double R[3][3] = {{c, -sn, 0}, {sn, c, 0}, {0, 0, 1}};
    ag_gframe L;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            L.M[i][j] = s[i] * R[i][j];
    /* the local box's centre goes to B's centre */
    double h[3] = {S[0] / 2, S[1] / 2, S[2] / 2};
    for (int i = 0; i < 3; i++)
        L.t[i] = ag_box_centre_axis(B, i) -
                 (L.M[i][0] * h[0] + L.M[i][1] * h[1] + L.M[i][2] * h[2]);
    ag_gframe o;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            o.M[i][j] = F->M[i][0] * L.M[0][j] + F->M[i][1] * L.M[1][j] + F->M[i][2] * L.M[2][j];
        o.t[i] = F->M[i][0] * L.t[0] + F->M[i][1] * L.t[1] + F->M[i][2] * L.t[2] + F->t[i];
    }
    return o;
}

void ag_gframe_cells_of(const ag_gstmt *s, const ag_box *B, ag_gframe_cells *c)
{
    /* subdivide steps along the axes; repeat has any lattice vectors */
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++)
            c->v[k][a] = s->subdivide == 2 ? s->vec[k][a] : (k == a ? s->step[a] : 0);
    /* the lattice's extent, which negative vectors reach below B's min corner */
    double omin[3] = {0, 0, 0}, omax[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++)
        for (int a = 0; a < 3; a++) {
            double e = (double)(s->counts[k] - 1) * c->v[k][a];
            omin[a] += e < 0 ? e : 0;
            omax[a] += e > 0 ? e : 0;
        }
    for (int a = 0; a < 3; a++) {
        c->origin[a] = B->min[a] - omin[a];
        c->size[a] = ag_box_extent(B, a) - (omax[a] - omin[a]);
    }
}

ag_box ag_gframe_cell(const ag_gframe_cells *c, uint32_t i, uint32_t j, uint32_t k)
{
    ag_box b;
    for (int a = 0; a < 3; a++) {
        b.min[a] = c->origin[a] + i * c->v[0][a] + j * c->v[1][a] + k * c->v[2][a];
        b.max[a] = b.min[a] + c->size[a];
    }
    return b;
}
