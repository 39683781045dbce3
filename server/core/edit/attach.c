#include "attach.h"

#include "../base/tolerance.h"

size_t ag_attach_detect(const ag_box *bi, const ag_box *bj, double eps, ag_attach out[12])
{
    size_t n = 0;
    int overlap[3], noverlap = 0;
    for (int a = 0; a < 3; a++) {
        overlap[a] = ag_box_overlap_axis(bi, bj, a) > eps;
        noverlap += overlap[a];
    }
    for (int a = 0; a < 3; a++) {
        int equal = 0;
        for (int s = 0; s < 2; s++)
            for (int t = 0; t < 2; t++) {
                int ci = a + 3 * s, cj = a + 3 * t;
                double d = ag_box_coord(bi, ci) - ag_box_coord(bj, cj);
                if (d <= eps && d >= -eps) {
                    out[n++] = (ag_attach){.type = AG_ATTACH_CORNER, .ci = ci, .cj = cj, .k = d};
                    equal = 1;
                }
            }
        /* An overlap whose ends are already tied needs no ratio on that side; keep the
         * ratios only when no end is shared, so the soft terms never fight the hard ones. */
        if (!overlap[a] || equal)
            continue;
        int type = noverlap == 1 ? AG_ATTACH_EDGE : noverlap == 2 ? AG_ATTACH_PLANE
                                                                  : AG_ATTACH_VOLUME;
        const ag_box *L = bi, *S = bj;
        int swap = 0;
        if (ag_box_extent(bj, a) > ag_box_extent(bi, a)) {
            L = bj;
            S = bi;
            swap = 1;
        }
        double len = ag_box_extent(L, a), slen = ag_box_extent(S, a);
        if (len <= eps || slen <= eps)
            continue;
        ag_attach r = {.type = type, .ci = a, .cj = a, .swap = swap};
        if (S->min[a] >= L->min[a] - eps && S->max[a] <= L->max[a] + eps) {
            r.form = 0;
            r.k = (ag_box_centre_axis(S, a) - L->min[a]) / len;
        } else if (S->min[a] < L->min[a]) {
            r.form = 1;
            r.k = (S->max[a] - L->min[a]) / slen;
        } else {
            r.form = 2;
            r.k = (L->max[a] - S->min[a]) / slen;
        }
        out[n++] = r;
    }
    return n;
}

double ag_attach_weight(int type)
{
    switch (type) {
    case AG_ATTACH_EDGE:
    case AG_ATTACH_PLANE:
        return AG_EDIT_WEIGHT_RATIO;
    case AG_ATTACH_VOLUME:
        return AG_EDIT_WEIGHT_VOLUME;
    case AG_ATTACH_SIZE:
        return AG_EDIT_WEIGHT_SIZE;
    case AG_ATTACH_POSITION:
        return AG_EDIT_WEIGHT_POSITION;
    default:
        return 0;
    }
}

const char *ag_attach_type_name(int type)
{
    static const char *names[] = {"ground", "corner", "edge", "plane", "volume", "size",
                                  "position"};
    return type >= 0 && type < AG_ATTACH_COUNT ? names[type] : "?";
}
