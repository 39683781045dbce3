/* The least-squares system of one set of units (resize_internal.h), in named phases run in
 * this order by ag__resize_system_build:
 *
 *   add_targets        the edited units' coordinates and a targeted frame's become target
 *                      classes, a fixed frame's are fixed
 *   add_ties           hard attachments merge coordinates: the ground (without a frame), a
 *                      unit's faces on the frame's faces, shared coordinates of adjacent units,
 *                      a coordinate shared with an adjacent unit outside the system
 *   add_ratios         overlaps keep their ratios (attach.h): a single unit keeps the relative
 *                      place of its centre, a pattern along an axis it repeats on keeps both ends
 *                      relative to the unit it lies in (its count follows, resize_layout.c); a
 *                      ratio between two units both held on that axis is left out, so it cannot
 *                      pull a held unit out of its size
 *   add_frame_ratios   units that nothing holds on an axis (no target, fixed coordinate or
 *                      frame face in what they are attached to) keep their place relative to
 *                      the frame, so a parent's new box carries its children along
 *   add_size_terms     size where an axis is attached at one end only (the paper's size
 *                      equations), and where it floats unless other units lie along it (a
 *                      roof over the walls it covers follows them); never along the axes a unit
 *                      follows what it lies in along (there a pattern's count follows its
 *                      length); position everywhere, weakly, at the expected place
 *   factorize          free classes become columns; rows without a free term are dropped;
 *                      the matrix is factorized (its structure only: targets are not in it)
 *   add_target_terms   each row's right-hand side split into its fixed part and the terms on
 *                      target classes, so a solve for new targets does no lookups */
#include <assert.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "attach.h"
#include "resize_internal.h"

/* A ratio found between two units (or a unit and an outside box), decided on once every hard
 * attachment is known. */
typedef struct {
    int32_t su, lu;  /* slots of S and L, -1 for an outside box */
    ag_box sb, lb;   /* their boxes (an outside box's values go to the right-hand side) */
    ag_attach at;
} ratio;

typedef struct {
    const ag_splittree *t;
    const ag__resize_spec *spec;
    double eps;
    int32_t *slot;   /* per tree node: its slot in this system or -1 */
    uint8_t *below;  /* per tree node: below a unit of the system (re-derived, not attached) */
    ratio *ratios;
    size_t nratios, cap_ratios;
    uint32_t *members; /* per class root, once the hard attachments are in: coordinates in it */
    uint8_t *holds;    /* per slot: bit a set when another unit lies along it on axis a (it is
                          the longer box of a ratio there) */
} build;

static ag_status nomem(ag_error *err)
{
    return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
}

static uint32_t coord_id(size_t slot, int c)
{
    return 6 * (uint32_t)slot + (uint32_t)c;
}

static ag_status add_hard(ag__resize_system *s, uint32_t coord, uint32_t other, double d)
{
    ag_status st = AG_ARRAY_RESERVE(s->hard, s->cap_hard, s->nhard + 1);
    if (st)
        return st;
    s->hard[s->nhard++] = (ag__resize_hard){coord, other, d};
    return AG_OK;
}

static ag__resize_row *new_row(ag__resize_system *s)
{
    if (AG_ARRAY_RESERVE(s->rows, s->cap_rows, s->nrows + 1))
        return NULL;
    ag__resize_row *r = &s->rows[s->nrows++];
    memset(r, 0, sizeof *r);
    return r;
}

/* Ties coordinates i and j: value(i) - value(j) = d. A target class keeps its root, then a
 * fixed one (their values are stored at the root); two targets or two fixed classes both stay
 * (the equality is only checked afterwards). */
static void tie(ag__resize_system *s, uint32_t i, uint32_t j, double d)
{
    uint32_t ri = ag_uf_find(&s->classes, i), rj = ag_uf_find(&s->classes, j);
    if (ri == rj)
        return;
    double rel = ag_uf_offset(&s->classes, j) + d - ag_uf_offset(&s->classes, i); /* ri - rj */
    if (s->fix[ri] && s->fix[rj])
        return;
    if (s->fix[ri])
        ag_uf_link(&s->classes, rj, ri, -rel);
    else
        ag_uf_link(&s->classes, ri, rj, rel);
}

/* Fixes coordinate i's class to value(i) = v, unless it is fixed or targeted already. */
static void fix_const(ag__resize_system *s, uint32_t i, double v)
{
    uint32_t r = ag_uf_find(&s->classes, i);
    if (s->fix[r])
        return;
    s->fix[r] = AG__RESIZE_FIXED;
    s->val[r] = v - ag_uf_offset(&s->classes, i);
}

/* Is coordinate i's class fixed or a target? */
static int held_coord(ag__resize_system *s, uint32_t i)
{
    return s->fix[ag_uf_find(&s->classes, i)] != AG__RESIZE_FREE;
}

/* Is slot q held on axis a (one of its two coordinates there fixed or a target)? An outside
 * box (q < 0) is. */
static int held(ag__resize_system *s, int32_t q, int a)
{
    return q < 0 || held_coord(s, coord_id((size_t)q, a)) || held_coord(s, coord_id((size_t)q, a + 3));
}

/* ---- targets and the frame --------------------------------------------------------------- */

static ag_status add_targets(ag__resize_system *s, build *b, ag_error *err)
{
    const ag__resize_spec *sp = b->spec;
    size_t nc = 6 * s->nslots;
    s->fix = calloc(nc + 1, 1);
    s->val = calloc(nc + 1, sizeof *s->val);
    s->col = malloc((nc + 1) * sizeof *s->col);
    if (ag_uf_init(&s->classes, nc, 1) || !s->fix || !s->val || !s->col)
        return nomem(err);
    for (size_t e = 0; e < sp->nedit; e++)
        for (int c = 0; c < 6; c++) {
            s->fix[coord_id(e, c)] = AG__RESIZE_TARGETED;
            if (add_hard(s, coord_id(e, c), AG__RESIZE_TARGET, 0))
                return nomem(err);
        }
    if (s->frame) {
        size_t f = s->nunits;
        for (int c = 0; c < 6; c++) {
            uint32_t id = coord_id(f, c);
            s->fix[id] = s->frame == AG__FRAME_TARGETED ? AG__RESIZE_TARGETED : AG__RESIZE_FIXED;
            s->val[id] = ag_box_coord(&sp->frame_new, c);
        }
    }
    return AG_OK;
}

/* ---- hard attachments -------------------------------------------------------------------- */

/* A shared coordinate stays shared: with a unit of the system the two classes merge, with a
 * box outside it the class is fixed to that box's coordinate. */
static ag_status add_corner(ag__resize_system *s, size_t q, int vs, const ag_box *bv,
                            const ag_attach *at)
{
    uint32_t cu = coord_id(q, at->ci);
    if (vs >= 0) {
        uint32_t cv = coord_id((size_t)vs, at->cj);
        tie(s, cu, cv, at->k);
        return add_hard(s, cu, cv, at->k);
    }
    double value = ag_box_coord(bv, at->cj) + at->k;
    fix_const(s, cu, value);
    return add_hard(s, cu, AG__RESIZE_CONST, value);
}

static ag_status keep_ratio(build *b, int32_t q, int32_t vs, const ag_box *bu, const ag_box *bv,
                            const ag_attach *at)
{
    if (AG_ARRAY_RESERVE(b->ratios, b->cap_ratios, b->nratios + 1))
        return AG_ERR_NOMEM;
    ratio *r = &b->ratios[b->nratios++];
    int l_is_u = !at->swap;
    r->lu = l_is_u ? q : vs;
    r->su = l_is_u ? vs : q;
    r->lb = l_is_u ? *bu : *bv;
    r->sb = l_is_u ? *bv : *bu;
    r->at = *at;
    return AG_OK;
}

/* A unit's faces on the frame's faces, per axis. */
static ag_status frame_ties(ag__resize_system *s, build *b, size_t q, const ag_box *bu)
{
    const ag_box *F = &b->spec->frame_old;
    size_t f = s->nunits;
    for (int a = 0; a < 3; a++)
        for (int side = 0; side < 2; side++) {
            int c = a + 3 * side;
            double d = ag_box_coord(bu, c) - ag_box_coord(F, c);
            if (fabs(d) > b->eps)
                continue;
            tie(s, coord_id(q, c), coord_id(f, c), d);
            if (add_hard(s, coord_id(q, c), coord_id(f, c), d))
                return AG_ERR_NOMEM;
        }
    return AG_OK;
}

static ag_status add_ties(ag__resize_system *s, build *b, const ag__resize_units *u,
                          ag_error *err)
{
    const ag__resize_spec *sp = b->spec;
    const ag_splittree *t = b->t;
    if (!s->frame) {
        double ground = t->nodes[0].box.min[2];
        for (size_t q = 0; q < sp->nunits; q++)
            if (fabs(sp->old[q].min[2] - ground) <= b->eps) {
                fix_const(s, coord_id(q, 2), ground);
                if (add_hard(s, coord_id(q, 2), AG__RESIZE_CONST, ground))
                    return nomem(err);
            }
    }
    for (size_t q = 0; q < sp->nunits; q++) {
        const ag_box *bu = &sp->old[q];
        if (s->frame && frame_ties(s, b, q, bu))
            return nomem(err);
        int32_t un = sp->units[q];
        for (uint32_t k = u->adj_start[un]; k < u->adj_start[un + 1]; k++) {
            int32_t v = (int32_t)u->adj_list[k];
            int vs = b->slot[v];
            if (vs >= 0 && vs < (int)q)
                continue; /* the pair was done from v */
            if (vs < 0 && (!sp->outside || b->below[v] || v == sp->frame_node))
                continue; /* a descendant (re-derived), the frame, or outside a level below */
            const ag_box *bv = vs >= 0 ? &sp->old[vs] : &t->nodes[v].box;
            ag_attach at[12];
            size_t na = ag_attach_detect(bu, bv, b->eps, at);
            for (size_t m = 0; m < na; m++) {
                ag_status st = at[m].type == AG_ATTACH_CORNER
                                   ? add_corner(s, q, vs, bv, &at[m])
                                   : keep_ratio(b, (int32_t)q, vs, bu, bv, &at[m]);
                if (st)
                    return nomem(err);
            }
        }
    }
    return AG_OK;
}

/* ---- ratios ------------------------------------------------------------------------------ */

/* A term of a row: on slot q's coordinate c, or a constant from box bx when q < 0. */
static void term(ag__resize_row *row, int32_t q, int c, const ag_box *bx, double coef)
{
    if (coef == 0)
        return;
    if (q >= 0) {
        row->coord[row->nterms] = coord_id((size_t)q, c);
        row->coef[row->nterms++] = coef;
    } else {
        row->rhs -= coef * ag_box_coord(bx, c);
    }
}

/* S's centre at the ratio k along L on axis a. */
static ag_status centre_row(ag__resize_system *s, int32_t sq, const ag_box *sb, int32_t lq,
                            const ag_box *lb, int a, double k, double w, int type)
{
    ag__resize_row *row = new_row(s);
    if (!row)
        return AG_ERR_NOMEM;
    row->type = (uint8_t)type;
    term(row, lq, a, lb, w * (k - 1));
    term(row, lq, a + 3, lb, -w * k);
    term(row, sq, a, sb, 0.5 * w);
    term(row, sq, a + 3, sb, 0.5 * w);
    if (!row->nterms)
        s->nrows--;
    return AG_OK;
}

/* S's coordinate c (side 0: min, 1: max) at its ratio along L on axis a. */
static ag_status end_row(ag__resize_system *s, int32_t sq, const ag_box *sb, int32_t lq,
                         const ag_box *lb, int a, int side, double w, int type)
{
    double len = ag_box_extent(lb, a);
    if (len <= AG_EDIT_FLAT)
        return AG_OK;
    double k = (ag_box_coord(sb, a + 3 * side) - lb->min[a]) / len;
    ag__resize_row *row = new_row(s);
    if (!row)
        return AG_ERR_NOMEM;
    row->type = (uint8_t)type;
    term(row, sq, a + 3 * side, sb, w);
    term(row, lq, a, lb, -w * (1 - k));
    term(row, lq, a + 3, lb, -w * k);
    if (!row->nterms)
        s->nrows--;
    return AG_OK;
}

static int is_lattice(const ag__resize_system *s, int32_t q, int a)
{
    if (q < 0 || (size_t)q >= s->nunits)
        return 0;
    return (s->stretch[q] >> a) & 1;
}

/* Which axes each unit follows what it lies in along: a pattern along the axes it repeats on;
 * a visible unit sharing its rule with another unit of the system (a repetition no pattern
 * holds) along every axis that is not thin for it; a unique element along none. */
static ag_status stretch_axes(ag__resize_system *s, const ag__resize_units *u,
                              const ag__resize_spec *sp, ag_error *err)
{
    const ag_splittree *t = s->in->tree;
    s->stretch = calloc(sp->nunits + 1, 1);
    if (!s->stretch)
        return nomem(err);
    for (size_t q = 0; q < sp->nunits; q++) {
        int32_t n = sp->units[q];
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_PATTERN) {
            s->stretch[q] = u->lattice[n];
            continue;
        }
        int repeated = 0;
        for (size_t r = 0; r < sp->nunits && !repeated && x->rule >= 0; r++)
            repeated = r != q && t->nodes[sp->units[r]].kind == AG_NODE_COMPONENT &&
                       t->nodes[sp->units[r]].rule == x->rule;
        if (!repeated)
            continue;
        double e[3], emax = 0;
        ag_box_extents(&sp->old[q], e);
        for (int a = 0; a < 3; a++)
            emax = fmax(emax, e[a]);
        for (int a = 0; a < 3; a++)
            if (e[a] >= AG_EDIT_THIN_RATIO * emax)
                s->stretch[q] |= (uint8_t)(1u << a);
    }
    return AG_OK;
}

/* A partial overlap keeps S's share (attach.h forms 1 and 2). */
static ag_status partial_row(ag__resize_system *s, const ratio *r, double w)
{
    int a = r->at.ci;
    double k = r->at.k;
    ag__resize_row *row = new_row(s);
    if (!row)
        return AG_ERR_NOMEM;
    row->type = r->at.type;
    if (r->at.form == 1) { /* bS - aL - k (bS - aS) */
        term(row, r->lu, a, &r->lb, -w);
        term(row, r->su, a, &r->sb, w * k);
        term(row, r->su, a + 3, &r->sb, w * (1 - k));
    } else { /* bL - aS - k (bS - aS) */
        term(row, r->lu, a + 3, &r->lb, w);
        term(row, r->su, a, &r->sb, w * (k - 1));
        term(row, r->su, a + 3, &r->sb, -w * k);
    }
    if (!row->nterms)
        s->nrows--;
    return AG_OK;
}

/* Is coordinate c (0..5) of slot q settled without the soft rows: held (fixed or a target), or
 * the free, unattached end of a unit that keeps its size (add_size_terms) whose other end is
 * held? A box outside the system is. */
static int settled(ag__resize_system *s, const build *b, int32_t q, int c)
{
    if (q < 0)
        return 1;
    uint32_t id = coord_id((size_t)q, c);
    if (held_coord(s, id))
        return 1;
    int a = c % 3, other = c < 3 ? c + 3 : c - 3;
    return !is_lattice(s, q, a) && b->members[ag_uf_find(&s->classes, id)] == 1 &&
           held_coord(s, coord_id((size_t)q, other));
}

/* The ratio rows, now that every hard attachment is known. A row all of whose coordinates are
 * settled could only pull against the hard attachments and sizes (a side wall held on the
 * front wall's end keeps its thickness rather than its place along a stretched roof): it is
 * left out. */
static ag_status add_ratios(ag__resize_system *s, build *b, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    if (!(b->members = calloc(nc + 1, sizeof *b->members)))
        return nomem(err);
    for (size_t i = 0; i < nc; i++)
        b->members[ag_uf_find(&s->classes, (uint32_t)i)]++;
    if (!(b->holds = calloc(s->nslots + 1, 1)))
        return nomem(err);
    for (size_t i = 0; i < b->nratios; i++)
        if (b->ratios[i].lu >= 0)
            b->holds[b->ratios[i].lu] |= (uint8_t)(1u << b->ratios[i].at.ci);
    const ag__resize_spec *sp = b->spec;
    for (size_t i = 0; i < b->nratios; i++) {
        const ratio *r = &b->ratios[i];
        if (sp->held && r->su >= 0 && r->lu >= 0 && (size_t)r->su < sp->nunits &&
            (size_t)r->lu < sp->nunits &&
            ((sp->held[r->su] && (size_t)r->lu < sp->nedit) ||
             (sp->held[r->lu] && (size_t)r->su < sp->nedit)))
            continue; /* the edited element does not pull what the edit happens on */
        int a = r->at.ci;
        double w = ag_attach_weight(r->at.type);
        int sa = settled(s, b, r->su, a), sb = settled(s, b, r->su, a + 3);
        int la = settled(s, b, r->lu, a), lb = settled(s, b, r->lu, a + 3);


        ag_status st = AG_OK;
        if (r->at.form == 1) { /* over aL, aS, bS */
            if (!(la && sa && sb))
                st = partial_row(s, r, w);
        } else if (r->at.form == 2) { /* over bL, aS, bS */
            if (!(lb && sa && sb))
                st = partial_row(s, r, w);
        } else if (is_lattice(s, r->su, a)) {
            /* a pattern along an axis it repeats on: both ends relative to L */
            if (!(sa && la && lb))
                st = end_row(s, r->su, &r->sb, r->lu, &r->lb, a, 0, w, r->at.type);
            if (!st && !(sb && la && lb))
                st = end_row(s, r->su, &r->sb, r->lu, &r->lb, a, 1, w, r->at.type);
        } else if (!(sa && sb && la && lb)) {
            st = centre_row(s, r->su, &r->sb, r->lu, &r->lb, a, r->at.k, w, r->at.type);
        }
        if (st)
            return nomem(err);
    }
    return AG_OK;
}

/* ---- frame ratios ------------------------------------------------------------------------ */

static uint32_t find_root(uint32_t *p, uint32_t x)
{
    while (p[x] != x)
        x = p[x] = p[p[x]];
    return x;
}

static void join(uint32_t *p, uint32_t a, uint32_t b)
{
    a = find_root(p, a);
    b = find_root(p, b);
    if (a != b)
        p[a] = b;
}

/* Per axis, the units linked by shared coordinates or by a ratio between them form groups; a
 * group holding no target, fixed coordinate or frame face floats, and every unit of it keeps
 * its place relative to the frame (its centre, or both ends along an axis a pattern repeats
 * on). */
static ag_status add_frame_ratios(ag__resize_system *s, build *b, ag_error *err)
{
    if (!s->frame)
        return AG_OK;
    size_t n = s->nunits, f = s->nunits;
    uint32_t *grp = malloc((n + 1) * sizeof *grp);
    uint8_t *anchored = malloc(n + 1);
    uint32_t *rep = malloc((6 * s->nslots + 1) * sizeof *rep); /* class root -> a unit */
    if (!grp || !anchored || !rep) {
        free(grp);
        free(anchored);
        free(rep);
        return nomem(err);
    }
    double w = ag_attach_weight(AG_ATTACH_PLANE);
    ag_status st = AG_OK;
    for (int a = 0; a < 3 && !st; a++) {
        for (size_t q = 0; q < n; q++) {
            grp[q] = (uint32_t)q;
            anchored[q] = 0;
        }
        for (size_t i = 0; i < 6 * s->nslots; i++)
            rep[i] = UINT32_MAX;
        for (size_t q = 0; q < n; q++)
            for (int side = 0; side < 2; side++) {
                uint32_t r = ag_uf_find(&s->classes, coord_id(q, a + 3 * side));
                if (rep[r] == UINT32_MAX)
                    rep[r] = (uint32_t)q;
                else
                    join(grp, (uint32_t)q, rep[r]);
            }
        for (size_t i = 0; i < b->nratios; i++) {
            const ratio *r = &b->ratios[i];
            if (r->at.ci == a && r->su >= 0 && r->lu >= 0)
                join(grp, (uint32_t)r->su, (uint32_t)r->lu);
        }
        for (size_t q = 0; q < n; q++)
            if (held(s, (int32_t)q, a))
                anchored[find_root(grp, (uint32_t)q)] = 1;
        for (size_t i = 0; i < b->nratios; i++) /* attached to a box outside: held by it */
            if (b->ratios[i].at.ci == a && (b->ratios[i].su < 0 || b->ratios[i].lu < 0)) {
                int32_t q = b->ratios[i].su >= 0 ? b->ratios[i].su : b->ratios[i].lu;
                anchored[find_root(grp, (uint32_t)q)] = 1;
            }
        const ag_box *F = &b->spec->frame_old;
        double len = ag_box_extent(F, a);
        if (len <= AG_EDIT_FLAT)
            continue;
        for (size_t q = 0; q < n && !st; q++) {
            if (anchored[find_root(grp, (uint32_t)q)])
                continue;
            const ag_box *bu = &b->spec->old[q];
            if (is_lattice(s, (int32_t)q, a)) {
                for (int side = 0; side < 2 && !st; side++)
                    st = end_row(s, (int32_t)q, bu, (int32_t)f, F, a, side, w, AG_ATTACH_PLANE);
            } else {
                double k = (ag_box_centre_axis(bu, a) - F->min[a]) / len;
                st = centre_row(s, (int32_t)q, bu, (int32_t)f, F, a, k, w, AG_ATTACH_PLANE);
            }
        }
    }
    free(grp);
    free(anchored);
    free(rep);
    return st ? nomem(err) : AG_OK;
}

/* ---- size and position ------------------------------------------------------------------- */

static ag_status add_size_terms(ag__resize_system *s, build *b, ag_error *err)
{
    const ag__resize_spec *sp = b->spec;
    const uint32_t *members = b->members;
    double ws = ag_attach_weight(AG_ATTACH_SIZE), wp = ag_attach_weight(AG_ATTACH_POSITION);
    /* a fixed frame that changed carries what lies in it: the weak terms hold each unit where
     * the frame's map puts it (its centre, and its ends along the axes it follows) */
    ag__resize_map fm = ag__resize_map_between(&sp->frame_old, &sp->frame_new);
    for (size_t q = 0; q < sp->nunits; q++) {
        const ag_box *bx = &sp->old[q];
        ag_box mapped = *bx;
        if (s->frame == AG__FRAME_FIXED && !sp->expect) {
            for (int a = 0; a < 3; a++) {
                double lo = fm.s[a] * bx->min[a] + fm.t[a], hi = fm.s[a] * bx->max[a] + fm.t[a];
                if (!is_lattice(s, (int32_t)q, a)) {
                    double c = 0.5 * (lo + hi), h = 0.5 * ag_box_extent(bx, a);
                    lo = c - h;
                    hi = c + h;
                }
                mapped.min[a] = lo;
                mapped.max[a] = hi;
            }
        }
        const ag_box *ex = sp->expect ? &sp->expect[q] : &mapped;
        for (int a = 0; a < 3; a++) {
            if (is_lattice(s, (int32_t)q, a))
                continue;
            uint32_t ca = coord_id(q, a), cb = ca + 3;
            uint32_t ra = ag_uf_find(&s->classes, ca), rb = ag_uf_find(&s->classes, cb);
            int att_a = s->fix[ra] || members[ra] > 1, att_b = s->fix[rb] || members[rb] > 1;
            if (att_a && att_b)
                continue; /* held at both ends: its size is theirs */
            if (!att_a && !att_b && (b->holds[q] >> a & 1))
                continue; /* floating, and what lies along it carries it (a roof over walls) */
            ag__resize_row *row = new_row(s);
            if (!row)
                return nomem(err);
            *row = (ag__resize_row){.coord = {cb, ca},
                                    .coef = {ws, -ws},
                                    .nterms = 2,
                                    .type = AG_ATTACH_SIZE,
                                    .rhs = ws * ag_box_extent(bx, a)};
        }
        for (int c = 0; c < 6; c++) {
            ag__resize_row *row = new_row(s);
            if (!row)
                return nomem(err);
            *row = (ag__resize_row){.coord = {coord_id(q, c)},
                                    .coef = {wp},
                                    .nterms = 1,
                                    .type = AG_ATTACH_POSITION,
                                    .rhs = wp * ag_box_coord(ex, c)};
        }
    }
    return AG_OK;
}

/* ---- columns and factorization ----------------------------------------------------------- */

static int is_free(ag__resize_system *s, uint32_t coord)
{
    return !s->fix[ag_uf_find(&s->classes, coord)];
}

static ag_status factorize(ag__resize_system *s, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    for (size_t i = 0; i < nc; i++)
        s->col[i] = -1;
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = ag_uf_find(&s->classes, (uint32_t)i);
        if (!s->fix[r] && s->col[r] < 0)
            s->col[r] = (int32_t)s->ncols++;
    }
    size_t keep = 0, nnz = 0;
    for (size_t i = 0; i < s->nrows; i++) {
        int free_terms = 0;
        for (int z = 0; z < s->rows[i].nterms; z++)
            free_terms += is_free(s, s->rows[i].coord[z]);
        if (free_terms) {
            s->rows[keep++] = s->rows[i];
            nnz += (size_t)free_terms;
        }
    }
    s->nrows = keep;
    s->b = malloc((s->nrows + 1) * sizeof *s->b);
    s->x = malloc((s->ncols + 1) * sizeof *s->x);
    if (!s->b || !s->x)
        return nomem(err);
    if (!s->ncols)
        return AG_OK;
    uint32_t *ri = malloc((nnz + 1) * sizeof *ri), *ci = malloc((nnz + 1) * sizeof *ci);
    double *vv = malloc((nnz + 1) * sizeof *vv);
    if (!ri || !ci || !vv) {
        free(ri);
        free(ci);
        free(vv);
        return nomem(err);
    }
    size_t p = 0;
    for (size_t i = 0; i < s->nrows; i++)
        for (int z = 0; z < s->rows[i].nterms; z++) {
            uint32_t r = ag_uf_find(&s->classes, s->rows[i].coord[z]);
            if (s->fix[r])
                continue;
            ri[p] = (uint32_t)i;
            ci[p] = (uint32_t)s->col[r];
            vv[p++] = s->rows[i].coef[z];
        }
    assert(p == nnz);
    ag_status st = ag_lsq_create(s->nrows, s->ncols, p, ri, ci, vv, &s->lsq, err);
    free(ri);
    free(ci);
    free(vv);
    return st;
}

/* ---- target terms ------------------------------------------------------------------------ */

static ag_status add_target_terms(ag__resize_system *s, ag_error *err)
{
    size_t nc = 6 * s->nslots;
    s->croot = malloc((nc + 1) * sizeof *s->croot);
    s->coff = malloc((nc + 1) * sizeof *s->coff);
    s->b0 = malloc((s->nrows + 1) * sizeof *s->b0);
    size_t nt = 0;
    for (size_t i = 0; i < s->nrows; i++)
        for (int z = 0; z < s->rows[i].nterms; z++)
            nt += s->fix[ag_uf_find(&s->classes, s->rows[i].coord[z])] == AG__RESIZE_TARGETED;
    s->trow = malloc((nt + 1) * sizeof *s->trow);
    s->troot = malloc((nt + 1) * sizeof *s->troot);
    s->tcoef = malloc((nt + 1) * sizeof *s->tcoef);
    if (!s->croot || !s->coff || !s->b0 || !s->trow || !s->troot || !s->tcoef)
        return nomem(err);
    for (size_t i = 0; i < nc; i++) {
        s->croot[i] = ag_uf_find(&s->classes, (uint32_t)i);
        s->coff[i] = ag_uf_offset(&s->classes, (uint32_t)i);
    }
    for (size_t i = 0; i < s->nrows; i++) {
        const ag__resize_row *row = &s->rows[i];
        double b = row->rhs;
        for (int z = 0; z < row->nterms; z++) {
            uint32_t c = row->coord[z], r = s->croot[c];
            b -= row->coef[z] * (s->coff[c] + (s->fix[r] == AG__RESIZE_FIXED ? s->val[r] : 0));
            if (s->fix[r] == AG__RESIZE_TARGETED) {
                assert(s->nterms_t < nt);
                s->trow[s->nterms_t] = (uint32_t)i;
                s->troot[s->nterms_t] = r;
                s->tcoef[s->nterms_t++] = row->coef[z];
            }
        }
        s->b0[i] = b;
    }
    return AG_OK;
}

void ag__resize_system_free(ag__resize_system *s)
{
    if (!s)
        return;
    free(s->slot_node);
    free(s->old);
    free(s->stretch);
    ag_uf_free(&s->classes);
    free(s->fix);
    free(s->val);
    free(s->col);
    free(s->rows);
    free(s->hard);
    free(s->croot);
    free(s->coff);
    free(s->b0);
    free(s->trow);
    free(s->troot);
    free(s->tcoef);
    ag_lsq_free(s->lsq);
    free(s->b);
    free(s->x);
    memset(s, 0, sizeof *s);
}

ag_status ag__resize_system_build(ag__resize_system *s, const ag_proceduralize_result *in,
                                  const ag__resize_units *u, const ag__resize_spec *spec,
                                  ag_error *err)
{
    memset(s, 0, sizeof *s);
    const ag_splittree *t = in->tree;
    s->in = in;
    s->u = u;
    s->nunits = spec->nunits;
    s->frame = spec->frame;
    s->nslots = spec->nunits + (spec->frame ? 1 : 0);
    s->diag = ag_box_diagonal(&t->nodes[0].box);
    if (s->nslots > UINT32_MAX / 6 - 1)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "resize: too many nodes move");
    build b = {.t = t,
               .spec = spec,
               .eps = ag__resize_touch(t, s->diag)};
    s->slot_node = malloc((s->nslots + 1) * sizeof *s->slot_node);
    s->old = malloc((s->nslots + 1) * sizeof *s->old);
    b.slot = malloc((t->nnodes + 1) * sizeof *b.slot);
    b.below = calloc(t->nnodes + 1, 1);
    ag_status st = AG_OK;
    if (!s->slot_node || !s->old || !b.slot || !b.below) {
        st = nomem(err);
        goto done;
    }
    for (size_t n = 0; n < t->nnodes; n++)
        b.slot[n] = -1;
    for (size_t q = 0; q < spec->nunits; q++) {
        s->slot_node[q] = spec->units[q];
        s->old[q] = spec->old[q];
        b.slot[spec->units[q]] = (int32_t)q;
    }
    if (spec->frame) {
        s->slot_node[spec->nunits] = -1;
        s->old[spec->nunits] = spec->frame_old;
    }
    if (spec->outside) /* descendants of the units are re-derived, not attached */
        for (size_t n = 1; n < t->nnodes; n++)
            for (int32_t p = t->nodes[n].parent; p > 0; p = t->nodes[p].parent)
                if (b.slot[p] >= 0) {
                    b.below[n] = 1;
                    break;
                }
    if (!st)
        st = stretch_axes(s, u, spec, err);
    if (!st)
        st = add_targets(s, &b, err);
    if (!st)
        st = add_ties(s, &b, u, err);
    if (!st)
        st = add_ratios(s, &b, err);
    if (!st)
        st = add_frame_ratios(s, &b, err);
    if (!st)
        st = add_size_terms(s, &b, err);
    if (!st)
        st = factorize(s, err);
    if (!st)
        st = add_target_terms(s, err);
done:
    free(b.slot);
    free(b.below);
    free(b.ratios);
    free(b.members);
    free(b.holds);
    return st;
}

/* ---- solve ------------------------------------------------------------------------------- */

ag_status ag__resize_system_solve(ag__resize_system *s, size_t nedit, const ag_box *targets,
                                  const ag_box *frame_target, ag_box *boxes, double *residual,
                                  ag_error *err)
{
    for (size_t e = 0; e < nedit; e++)
        for (int c = 0; c < 6; c++)
            s->val[coord_id(e, c)] = ag_box_coord(&targets[e], c); /* targets are roots */
    if (s->frame == AG__FRAME_TARGETED && frame_target)
        for (int c = 0; c < 6; c++)
            s->val[coord_id(s->nunits, c)] = ag_box_coord(frame_target, c);
    memcpy(s->b, s->b0, s->nrows * sizeof *s->b);
    for (size_t k = 0; k < s->nterms_t; k++)
        s->b[s->trow[k]] -= s->tcoef[k] * s->val[s->troot[k]];
    ag_status st;
    if (s->lsq && (st = ag_lsq_solve(s->lsq, s->b, s->x, err)))
        return st;
    size_t nc = 6 * s->nslots;
    double *xv = malloc((nc + 1) * sizeof *xv);
    if (!xv)
        return nomem(err);
    for (size_t i = 0; i < nc; i++) {
        uint32_t r = s->croot[i];
        xv[i] = (s->fix[r] ? s->val[r] : s->x[s->col[r]]) + s->coff[i];
    }
    double maxres = 0;
    for (size_t h = 0; h < s->nhard; h++) {
        const ag__resize_hard *q = &s->hard[h];
        double other = q->other_coord == AG__RESIZE_CONST    ? q->d
                       : q->other_coord == AG__RESIZE_TARGET ? s->val[q->coord]
                                                             : xv[q->other_coord] + q->d;
        maxres = fmax(maxres, fabs(xv[q->coord] - other));
    }
    for (size_t q = 0; q < s->nslots; q++) {
        ag_box bx;
        for (int c = 0; c < 6; c++)
            ag_box_set_coord(&bx, c, xv[6 * q + c]);
        for (int a = 0; a < 3; a++) /* a flip collapses rather than inverts */
            if (bx.max[a] < bx.min[a])
                bx.min[a] = bx.max[a] = ag_box_centre_axis(&bx, a);
        boxes[q] = bx;
    }
    free(xv);
    if (residual)
        *residual = maxres;
    return AG_OK;
}
