#include "style.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void add_profile(ag_style *s, const char *name, const ag_profile_point *pts, size_t n)
{
    ag_style_profile *p = &s->profiles[s->nprofiles++];
    snprintf(p->name, sizeof p->name, "%s", name);
    p->npoints = n;
    memcpy(p->points, pts, n * sizeof *pts);
}

static void add_rule(ag_style *s, uint32_t labels, uint32_t profile)
{
    ag_style_rule *r = &s->rules[s->nrules++];
    r->labels = labels;
    r->nchoices = 1;
    r->profile[0] = profile;
    r->weight[0] = 1;
}

ag_status ag_style_builtin(const char *name, ag_style *s, ag_error *err)
{
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name);
    s->height = 6;
    s->short_below = 4;
    s->long_above = 12;
    s->seed = 1;
    uint32_t any = AG_LABEL_ANY_LENGTH | AG_LABEL_ANY_ORIENTATION | AG_LABEL_ANY_AXIS;
    if (strcmp(name, "flat") == 0) {
        const ag_profile_point wall[] = {{0, 1}};
        add_profile(s, "wall", wall, 1);
        s->cap = 1;
        add_rule(s, any, 0);
    } else if (strcmp(name, "hip") == 0) {
        const ag_profile_point roof[] = {{1, 1}};
        add_profile(s, "hip45", roof, 1);
        add_rule(s, any, 0);
    } else if (strcmp(name, "gable") == 0) {
        const ag_profile_point roof[] = {{1, 1}}, wall[] = {{0, 1}};
        add_profile(s, "roof45", roof, 1);
        add_profile(s, "gable_wall", wall, 1);
        add_rule(s, AG_LABEL_ANY_LENGTH | AG_LABEL_ANY_ORIENTATION | AG_LABEL_ALONG, 0);
        add_rule(s, AG_LABEL_ANY_LENGTH | AG_LABEL_ANY_ORIENTATION | AG_LABEL_ACROSS, 1);
    } else if (strcmp(name, "mansard") == 0) {
        /* steep lower slope (about 70°) for 2.5 m, then a shallow one (about 20°) */
        const ag_profile_point roof[] = {{0.9, 2.5}, {0.9 + 2.75, 3.5}};
        add_profile(s, "mansard", roof, 2);
        add_rule(s, any, 0);
    } else if (strcmp(name, "overhang") == 0) {
        /* a flat soffit 0.5 m outwards at the eave, then a 45° roof */
        const ag_profile_point roof[] = {{-0.5, 0}, {0.5, 1}};
        add_profile(s, "overhang45", roof, 2);
        add_rule(s, any, 0);
    } else {
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0,
                            "unknown style '%s' (built-in: flat, hip, gable, mansard, overhang)",
                            name);
    }
    return AG_OK;
}

uint32_t ag_style_edge_labels(const ag_style *s, const double *xy, size_t n, size_t i,
                              const double axis[2])
{
    size_t j = (i + 1) % n;
    double dx = xy[2 * j] - xy[2 * i], dy = xy[2 * j + 1] - xy[2 * i + 1];
    double len = hypot(dx, dy);
    uint32_t l = len < s->short_below ? AG_LABEL_SHORT
                 : len > s->long_above ? AG_LABEL_LONG
                                       : AG_LABEL_MEDIUM;
    if (len > 0) {
        dx /= len;
        dy /= len;
    }
    double ox = dy, oy = -dx; /* outward normal of a CCW loop */
    if (s->has_street) {
        double c = ox * s->street_dir[0] + oy * s->street_dir[1];
        l |= c > 0.7071 ? AG_LABEL_STREET : c < -0.7071 ? AG_LABEL_BACK : AG_LABEL_SIDE;
    }
    if (fabs(ox) > fabs(oy))
        l |= ox > 0 ? AG_LABEL_EAST : AG_LABEL_WEST;
    else
        l |= oy > 0 ? AG_LABEL_NORTH : AG_LABEL_SOUTH;
    l |= fabs(dx * axis[0] + dy * axis[1]) >= 0.7071 ? AG_LABEL_ALONG : AG_LABEL_ACROSS;
    return l;
}

static uint64_t mix(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

static int matches(uint32_t rule, uint32_t labels)
{
    const uint32_t groups[3] = {AG_LABEL_ANY_LENGTH, AG_LABEL_ANY_ORIENTATION, AG_LABEL_ANY_AXIS};
    for (int g = 0; g < 3; g++) {
        uint32_t want = rule & groups[g];
        if (want && !(want & labels))
            return 0;
    }
    return 1;
}

ag_status ag_style_apply(const ag_style *s, const double *const *loops, const size_t *sizes,
                         size_t nloops, double height, size_t footprint, ag_plan **out,
                         ag_error *err)
{
    *out = NULL;
    if (!(height > 0))
        height = s->height;
    ag_plan *p = ag_plan_create();
    if (!p)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = AG_OK;
    for (size_t i = 0; i < s->nprofiles && st == AG_OK; i++) {
        const ag_style_profile *sp = &s->profiles[i];
        ag_profile_point pts[AG_STYLE_MAX_POINTS + 2];
        size_t n = 0;
        pts[n++] = (ag_profile_point){0, 0};
        pts[n++] = (ag_profile_point){0, height};
        for (size_t k = 0; k < sp->npoints; k++)
            pts[n++] = (ag_profile_point){sp->points[k].w, height + sp->points[k].z};
        st = ag_plan_add_profile(p, sp->name, pts, n, NULL, NULL, err);
    }
    if (s->cap)
        p->cap_height = height;
    /* main axis: direction of the longest edge of the first loop */
    double axis[2] = {1, 0}, best = -1;
    if (nloops) {
        const double *xy = loops[0];
        for (size_t i = 0; i < sizes[0]; i++) {
            size_t j = (i + 1) % sizes[0];
            double dx = xy[2 * j] - xy[2 * i], dy = xy[2 * j + 1] - xy[2 * i + 1];
            double len = hypot(dx, dy);
            if (len > best) {
                best = len;
                axis[0] = dx / len;
                axis[1] = dy / len;
            }
        }
    }
    for (size_t L = 0; L < nloops && st == AG_OK; L++) {
        size_t n = sizes[L];
        int32_t *prof = malloc((n ? n : 1) * sizeof *prof);
        if (!prof) {
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            break;
        }
        for (size_t i = 0; i < n; i++) {
            uint32_t lab = ag_style_edge_labels(s, loops[L], n, i, axis);
            prof[i] = 0;
            for (size_t r = 0; r < s->nrules; r++) {
                const ag_style_rule *ru = &s->rules[r];
                if (!matches(ru->labels, lab) || !ru->nchoices)
                    continue;
                double total = 0;
                for (size_t c = 0; c < ru->nchoices; c++)
                    total += ru->weight[c];
                uint64_t h = mix(s->seed ^ mix(footprint * 0x9e3779b97f4a7c15ULL + L * 7919 + i));
                double u = (double)(h >> 11) / 9007199254740992.0 * total;
                size_t pick = 0;
                for (size_t c = 0; c < ru->nchoices; c++) {
                    if (u < ru->weight[c]) {
                        pick = c;
                        break;
                    }
                    u -= ru->weight[c];
                    pick = c;
                }
                prof[i] = (int32_t)ru->profile[pick];
                break;
            }
        }
        st = ag_plan_add_loop(p, loops[L], n, prof, err);
        free(prof);
    }
    if (st != AG_OK) {
        ag_plan_free(p);
        return st;
    }
    *out = p;
    return AG_OK;
}
