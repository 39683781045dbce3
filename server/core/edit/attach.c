#include "attach.h"

static double coord(const ag_box *b, int c) { return c < 3 ? b->min[c] : b->max[c - 3]; }

size_t ag_attach_detect(const ag_box *bi, const ag_box *bj, double eps, ag_attach out[12])
{
    size_t n = 0;
    int overlap[3], noverlap = 0;
    for (int a = 0; a < 3; a++) {
        double lo = bi->min[a] > bj->min[a] ? bi->min[a] : bj->min[a];
        double hi = bi->max[a] < bj->max[a] ? bi->max[a] : bj->max[a];
        overlap[a] = hi - lo > eps;
        noverlap += overlap[a];
    }
    for (int a = 0; a < 3; a++) {
        int equal = 0;
        for (int s = 0; s < 2; s++)
            for (int t = 0; t < 2; t++) {
                int ci = a + 3 * s, cj = a + 3 * t;
                double d = coord(bi, ci) - coord(bj, cj);
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
        if (bj->max[a] - bj->min[a] > bi->max[a] - bi->min[a]) {
            L = bj;
            S = bi;
            swap = 1;
        }
        double len = L->max[a] - L->min[a], slen = S->max[a] - S->min[a];
        if (len <= eps || slen <= eps)
            continue;
        ag_attach r = {.type = type, .ci = a, .cj = a, .swap = swap};
        if (S->min[a] >= L->min[a] - eps && S->max[a] <= L->max[a] + eps) {
            r.form = 0;
            r.k = (0.5 * (S->min[a] + S->max[a]) - L->min[a]) / len;
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
        return 1.0;
    case AG_ATTACH_VOLUME:
        return 0.3;
    case AG_ATTACH_SIZE:
        return 3.0; /* an element's own size matters more than where it sits */
    case AG_ATTACH_POSITION:
        return 1e-3; /* only keeps the system definite: far below every other term */
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
