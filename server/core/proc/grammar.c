#include "grammar.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../base/array.h"
#include "../base/tolerance.h"
#include "gframe.h"
#include "surface.h"
#include "weld.h"

/* Work limits: a subdivide or repeat of more cells is refused (its derivation would not fit
 * in memory); a derivation stops past this many triangles (unless the caller sets its own)
 * or rules nested this deep (a rule calling itself). */
#define GRAMMAR_MAX_CELLS 1e7
#define DERIVE_MAX_TRIANGLES 50000000
#define DERIVE_MAX_DEPTH 512

/* ---- building blocks -------------------------------------------------------------------- */

ag_grammar *ag_grammar_create(void)
{
    return calloc(1, sizeof(ag_grammar));
}

static void free_rule(ag_grule *r)
{
    for (size_t i = 0; i < r->nstmts; i++) {
        free(r->stmts[i].node);
        free(r->stmts[i].parent);
        free(r->stmts[i].callee);
    }
    free(r->stmts);
    free(r->name);
}

void ag_grammar_free(ag_grammar *g)
{
    if (!g)
        return;
    for (size_t i = 0; i < g->nterminals; i++) {
        free(g->terminals[i].name);
        free(g->terminals[i].path);
        free(g->terminals[i].label_name);
        free(g->terminals[i].pos);
        free(g->terminals[i].tri);
    }
    free(g->terminals);
    for (size_t i = 0; i < g->nrules; i++)
        free_rule(&g->rules[i]);
    free(g->rules);
    free_rule(&g->axiom);
    free(g);
}

ag_status ag_grammar_add_terminal(ag_grammar *g, const char *name, const double size[3],
                                  size_t *index)
{
    ag_status st = AG_ARRAY_RESERVE(g->terminals, g->cap_terminals, g->nterminals + 1);
    if (st)
        return st;
    ag_gterminal *t = &g->terminals[g->nterminals];
    memset(t, 0, sizeof *t);
    t->name = strdup(name);
    if (!t->name)
        return AG_ERR_NOMEM;
    memcpy(t->size, size, sizeof t->size);
    t->label = -1;
    if (index)
        *index = g->nterminals;
    g->nterminals++;
    return AG_OK;
}

ag_status ag_grammar_add_rule(ag_grammar *g, const char *name, const double size[3],
                              size_t *index)
{
    ag_status st = AG_ARRAY_RESERVE(g->rules, g->cap_rules, g->nrules + 1);
    if (st)
        return st;
    ag_grule *r = &g->rules[g->nrules];
    memset(r, 0, sizeof *r);
    r->name = strdup(name);
    if (!r->name)
        return AG_ERR_NOMEM;
    memcpy(r->size, size, sizeof r->size);
    if (index)
        *index = g->nrules;
    g->nrules++;
    return AG_OK;
}

static ag_gstmt *new_stmt(ag_grule *r)
{
    if (AG_ARRAY_RESERVE(r->stmts, r->cap, r->nstmts + 1))
        return NULL;
    ag_gstmt *s = &r->stmts[r->nstmts++];
    memset(s, 0, sizeof *s);
    s->node_ix = s->parent_ix = s->callee_ix = -1;
    return s;
}

ag_status ag_grammar_add_split(ag_grule *r, const char *node, const char *parent,
                               const double v[3], int octant, long line, long col)
{
    ag_gstmt *s = new_stmt(r);
    if (!s)
        return AG_ERR_NOMEM;
    s->kind = AG_GSTMT_SPLIT;
    s->node = strdup(node);
    s->parent = strdup(parent);
    memcpy(s->v, v, sizeof s->v);
    s->octant = octant;
    s->line = line;
    s->col = col;
    return s->node && s->parent ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_grammar_add_apply(ag_grule *r, const char *callee, const char *node, int rot,
                               const uint32_t *counts, const double *step, long line, long col)
{
    ag_gstmt *s = new_stmt(r);
    if (!s)
        return AG_ERR_NOMEM;
    s->kind = AG_GSTMT_APPLY;
    s->callee = strdup(callee);
    s->node = strdup(node);
    s->rot = rot;
    if (counts) {
        s->subdivide = 1;
        memcpy(s->counts, counts, sizeof s->counts);
        memcpy(s->step, step, sizeof s->step);
    }
    s->line = line;
    s->col = col;
    return s->callee && s->node ? AG_OK : AG_ERR_NOMEM;
}

ag_status ag_grammar_add_repeat(ag_grule *r, const char *callee, const char *node, int rot,
                                int nvec, const uint32_t *counts, const double vec[][3],
                                long line, long col)
{
    ag_status st = ag_grammar_add_apply(r, callee, node, rot, NULL, NULL, line, col);
    if (st)
        return st;
    ag_gstmt *s = &r->stmts[r->nstmts - 1];
    s->subdivide = 2;
    s->nvec = nvec < 1 ? 1 : nvec > 3 ? 3 : nvec;
    for (int k = 0; k < 3; k++) {
        s->counts[k] = k < s->nvec ? counts[k] : 1;
        for (int a = 0; a < 3; a++)
            s->vec[k][a] = k < s->nvec ? vec[k][a] : 0;
    }
    return AG_OK;
}

ag_status ag_grammar_set_terminal_geometry(ag_gterminal *t, const double *pos, size_t nverts,
                                           const uint32_t *tri, size_t ntris)
{
    double *p = malloc((3 * nverts + 1) * sizeof *p);
    uint32_t *q = malloc((3 * ntris + 1) * sizeof *q);
    if (!p || !q) {
        free(p);
        free(q);
        return AG_ERR_NOMEM;
    }
    memcpy(p, pos, 3 * nverts * sizeof *p);
    memcpy(q, tri, 3 * ntris * sizeof *q);
    free(t->pos);
    free(t->tri);
    t->pos = p;
    t->tri = q;
    t->nverts = nverts;
    t->ntris = ntris;
    return AG_OK;
}

/* ---- resolve ---------------------------------------------------------------------------- */

static ag_status rerr(ag_error *err, long *col, long line, long c, const char *fmt, const char *a)
{
    if (col)
        *col = c;
    return ag_error_set(err, AG_ERR_PARSE, line, fmt, a ? a : "");
}

/* Node names of one body: an open-addressing table over string hashes. */
typedef struct {
    char **names;
    int32_t *slot; /* index into names, -1 empty */
    size_t n, cap;
} nametab;

static uint64_t str_hash(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    while (*s)
        h = (h ^ (unsigned char)*s++) * 0x100000001b3ULL;
    return h;
}

static int find_node(const nametab *t, const char *s)
{
    size_t i = str_hash(s) & (t->cap - 1);
    while (t->slot[i] >= 0) {
        if (!strcmp(t->names[t->slot[i]], s))
            return t->slot[i];
        i = (i + 1) & (t->cap - 1);
    }
    return -1;
}

static void add_node(nametab *t, char *s)
{
    size_t i = str_hash(s) & (t->cap - 1);
    while (t->slot[i] >= 0)
        i = (i + 1) & (t->cap - 1);
    t->slot[i] = (int32_t)t->n;
    t->names[t->n++] = s;
}

/* Terminal and rule names: index by hash as well, rules only up to `limit`. */
static int find_callee(const ag_grammar *g, const nametab *rt, const nametab *tt, const char *s,
                       size_t limit, int *is_rule)
{
    int k = find_node(rt, s);
    if (k >= 0 && (size_t)k < limit) {
        *is_rule = 1;
        return k;
    }
    k = find_node(tt, s);
    *is_rule = 0;
    (void)g;
    return k;
}

static int tab_init(nametab *t, size_t n)
{
    t->n = 0;
    if (ag_array_hash_size(n + 1, &t->cap))
        return -1;
    t->names = malloc((n + 1) * sizeof *t->names);
    t->slot = malloc(t->cap * sizeof *t->slot);
    if (!t->names || !t->slot)
        return -1;
    for (size_t i = 0; i < t->cap; i++)
        t->slot[i] = -1;
    return 0;
}

static ag_status resolve_rule(ag_grammar *g, ag_grule *r, size_t nrules_before, const nametab *rt,
                              const nametab *tt, ag_error *err, long *col)
{
    nametab nt = {0};
    if (tab_init(&nt, r->nstmts)) {
        free(nt.names);
        free(nt.slot);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    add_node(&nt, "p");
    ag_status st = AG_OK;
    for (size_t i = 0; i < r->nstmts && !st; i++) {
        ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            int p = find_node(&nt, s->parent);
            if (p < 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is not defined", s->parent);
                break;
            }
            if (find_node(&nt, s->node) >= 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is defined twice", s->node);
                break;
            }
            if (s->octant < 1 || s->octant > 8) {
                st = rerr(err, col, s->line, s->col, "octant must be 1 to 8%s", "");
                break;
            }
            for (int a = 0; a < 3; a++)
                if (!isfinite(s->v[a])) {
                    st = rerr(err, col, s->line, s->col, "pivot is not finite%s", "");
                    break;
                }
            if (st)
                break;
            s->parent_ix = p;
            s->node_ix = (int32_t)nt.n;
            add_node(&nt, s->node);
        } else {
            int p = find_node(&nt, s->node);
            if (p < 0) {
                st = rerr(err, col, s->line, s->col, "node '%s' is not defined", s->node);
                break;
            }
            s->node_ix = p;
            int is_rule = 0;
            s->callee_ix = find_callee(g, rt, tt, s->callee, nrules_before, &is_rule);
            s->callee_is_rule = is_rule;
            if (s->callee_ix < 0) {
                int later = find_node(rt, s->callee) >= 0;
                st = rerr(err, col, s->line, s->col,
                          later ? "rule '%s' is used before it is declared"
                                : "'%s' is neither a terminal nor a rule",
                          s->callee);
                break;
            }
            if (s->rot < 0 || s->rot > 3) {
                st = rerr(err, col, s->line, s->col, "rot must be 0, 90, 180 or 270%s", "");
                break;
            }
            if (s->subdivide) {
                double cells = 1;
                for (int a = 0; a < 3; a++) {
                    int bad = s->counts[a] < 1 || !isfinite(s->step[a]);
                    for (int b = 0; b < 3; b++)
                        bad |= !isfinite(s->vec[a][b]);
                    if (bad) {
                        st = rerr(err, col, s->line, s->col,
                                  "%s needs counts >= 1 and finite steps",
                                  s->subdivide == 2 ? "repeat" : "subdivide");
                        break;
                    }
                    cells *= s->counts[a];
                }
                if (!st && cells > GRAMMAR_MAX_CELLS)
                    st = rerr(err, col, s->line, s->col, "subdivide has too many cells%s", "");
            }
        }
    }
    r->nnodes = nt.n;
    free(nt.names);
    free(nt.slot);
    return st;
}

ag_status ag_grammar_resolve(ag_grammar *g, ag_error *err, long *col)
{
    if (col)
        *col = 0;
    nametab rt = {0}, tt = {0};
    ag_status st = AG_OK;
    if (tab_init(&rt, g->nrules) || tab_init(&tt, g->nterminals)) {
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < g->nterminals && !st; i++) {
        ag_gterminal *t = &g->terminals[i];
        if (find_node(&tt, t->name) >= 0) {
            st = rerr(err, col, 0, 0, "terminal '%s' is declared twice", t->name);
            break;
        }
        add_node(&tt, t->name);
        for (int a = 0; a < 3; a++)
            if (!(t->size[a] >= 0) || !isfinite(t->size[a])) {
                st = rerr(err, col, 0, 0, "terminal '%s' has a bad size", t->name);
                break;
            }
    }
    for (size_t i = 0; i < g->nrules && !st; i++) {
        ag_grule *r = &g->rules[i];
        if (find_node(&rt, r->name) >= 0) {
            st = rerr(err, col, r->line, r->col, "rule '%s' is declared twice", r->name);
            break;
        }
        if (find_node(&tt, r->name) >= 0) {
            st = rerr(err, col, r->line, r->col, "'%s' names a terminal and a rule", r->name);
            break;
        }
        add_node(&rt, r->name);
        for (int a = 0; a < 3; a++)
            if (!(r->size[a] >= 0) || !isfinite(r->size[a])) {
                st = rerr(err, col, r->line, r->col, "rule '%s' has a bad size", r->name);
                break;
            }
    }
    /* bodies: a rule may call only the rules before it */
    for (size_t i = 0; i < g->nrules && !st; i++)
        st = resolve_rule(g, &g->rules[i], i, &rt, &tt, err, col);
    if (!st && !g->has_axiom)
        st = rerr(err, col, 0, 0, "the grammar has no axiom%s", "");
    if (!st)
        st = resolve_rule(g, &g->axiom, g->nrules, &rt, &tt, err, col);
done:
    free(rt.names);
    free(rt.slot);
    free(tt.names);
    free(tt.slot);
    return st;
}

/* ---- export ----------------------------------------------------------------------------- */

typedef struct {
    const ag_mesh *m;
    const ag_labels *L;
    const ag_splittree *t;
    ag_grammar *g;
    int pass;            /* 1: count applications, 2: emit */
    uint32_t *apps;      /* per class */
    int32_t *exemplar;   /* per class: node */
    uint8_t *visited;    /* per class */
    uint8_t *in_pattern; /* per class: used by a subdivide */
    int32_t *rule_of;    /* per class: grammar rule */
    int32_t *term_of;    /* per variant: terminal */
    uint32_t *wslot;     /* scratch: terminal vertices by position (index + 1, 0 empty) */
    size_t wcap;         /* its size, a power of two */
    uint32_t *wused;     /* per terminal vertex: its slot, to empty the table again */
    double *tpos;
    uint32_t *ttri;
    ag_status st;
} exctx;

static ag_grule scratch_rule; /* never used in pass 2 */

static int is_rule(exctx *x, int32_t cls)
{
    if (cls < 0)
        return 0;
    if (x->pass == 1)
        return x->t->rule_count[cls] >= 2;
    /* a repeated lone terminal is placed directly unless a pattern needs it as a rule */
    if (x->apps[cls] < 2)
        return 0;
    return x->t->nodes[x->exemplar[cls]].first_child >= 0 || x->in_pattern[cls];
}

static void emit_content(exctx *x, ag_grule *r, int32_t v, const char *vname, unsigned *counter);

static int32_t terminal_for(exctx *x, int32_t variant)
{
    if (x->term_of[variant] >= 0)
        return x->term_of[variant];
    const ag_labels *L = x->L;
    uint32_t c = L->variant_exemplar[variant];
    const ag_box *nb = &x->t->nodes[x->t->comp_node[c]].box;
    double size[3];
    ag_box_extents(nb, size);
    char name[32];
    snprintf(name, sizeof name, "T%zu", x->g->nterminals + 1);
    size_t ti;
    if ((x->st = ag_grammar_add_terminal(x->g, name, size, &ti)))
        return 0;
    x->g->terminals[ti].label = L->variant_label[variant];
    snprintf(name, sizeof name, "L%d", L->variant_label[variant] + 1);
    if (!(x->g->terminals[ti].label_name = strdup(name))) {
        x->st = AG_ERR_NOMEM;
        return 0;
    }
    /* vertices at the same position are one terminal vertex: files that repeat a vertex for
     * every polygon (most exports) store it once */
    size_t nv = 0, nt = 0;
    for (uint32_t s = L->tri_start[c]; s < L->tri_start[c + 1]; s++) {
        uint32_t tr = L->tris[s];
        for (int k = 0; k < 3; k++) {
            const double *p = x->m->pos + 3 * (size_t)x->m->tri[3 * tr + k];
            double q[3] = {p[0] - nb->min[0], p[1] - nb->min[1], p[2] - nb->min[2]};
            uint64_t bits[3];
            memcpy(bits, q, sizeof bits);
            size_t h = ag__mix64(bits[0] ^ ag__mix64(bits[1] + 0x632BE59BD9B4E019ULL) ^
                                 ag__mix64(bits[2] * 0x85EBCA77C2B2AE63ULL + 1)) &
                       (x->wcap - 1);
            uint32_t id;
            for (;;) {
                uint32_t w = x->wslot[h];
                if (!w) {
                    id = (uint32_t)nv++;
                    memcpy(x->tpos + 3 * id, q, sizeof q);
                    x->wslot[h] = id + 1;
                    x->wused[id] = (uint32_t)h;
                    break;
                }
                if (!memcmp(x->tpos + 3 * (w - 1), q, sizeof q)) {
                    id = w - 1;
                    break;
                }
                h = (h + 1) & (x->wcap - 1);
            }
            x->ttri[3 * nt + k] = id;
        }
        nt++;
    }
    for (size_t i = 0; i < nv; i++)
        x->wslot[x->wused[i]] = 0;
    if ((x->st = ag_grammar_set_terminal_geometry(&x->g->terminals[ti], x->tpos, nv, x->ttri, nt)))
        return 0;
    x->term_of[variant] = (int32_t)ti;
    return (int32_t)ti;
}

static const char *node_name(unsigned *counter, char *buf, size_t cap)
{
    snprintf(buf, cap, "n%u", ++*counter);
    return buf;
}

/* Makes sure class cls is available; returns the grammar rule index in pass 2. */
static int32_t use_rule(exctx *x, int32_t cls, int32_t node, int weight)
{
    if (x->pass == 1) {
        x->apps[cls] += (uint32_t)weight;
        if (weight > 1)
            x->in_pattern[cls] = 1;
        if (!x->visited[cls]) {
            x->visited[cls] = 1;
            x->exemplar[cls] = node;
            unsigned counter = 0;
            emit_content(x, &scratch_rule, node, "p", &counter);
        }
        return -1;
    }
    if (x->rule_of[cls] >= 0)
        return x->rule_of[cls];
    /* body into a detached rule first: nested rules are declared while it is emitted */
    ag_grule body;
    memset(&body, 0, sizeof body);
    unsigned counter = 0;
    int32_t ex = x->exemplar[cls];
    emit_content(x, &body, ex, "p", &counter);
    double size[3];
    ag_box_extents(&x->t->nodes[ex].box, size);
    char name[32];
    snprintf(name, sizeof name, "R%zu", x->g->nrules + 1);
    size_t ri;
    if (!x->st)
        x->st = ag_grammar_add_rule(x->g, name, size, &ri);
    if (x->st) {
        free_rule(&body);
        return -1;
    }
    ag_grule *r = &x->g->rules[ri];
    r->stmts = body.stmts;
    r->nstmts = body.nstmts;
    r->cap = body.cap;
    x->rule_of[cls] = (int32_t)ri;
    return (int32_t)ri;
}

static void emit_content(exctx *x, ag_grule *r, int32_t v, const char *vname, unsigned *counter)
{
    const ag_splittree *t = x->t;
    const ag_tnode *n = &t->nodes[v];
    int emit = x->pass == 2;
    if (x->st)
        return;
    if (n->kind == AG_NODE_COMPONENT && emit) {
        int32_t ti = terminal_for(x, n->variant);
        if (x->st)
            return;
        x->st = ag_grammar_add_apply(r, x->g->terminals[ti].name, vname, n->rot, NULL, NULL, 0, 0);
    }
    for (int32_t s = n->first_child; s >= 0 && !x->st; s = t->nodes[s].next_sibling) {
        char prev[24], cur[24];
        snprintf(prev, sizeof prev, "%s", vname);
        int32_t k = s;
        for (;;) {
            node_name(counter, cur, sizeof cur);
            if (emit && (x->st = ag_grammar_add_split(r, cur, prev, t->nodes[k].pivot,
                                                      t->nodes[k].octant, 0, 0)))
                return;
            memcpy(prev, cur, sizeof prev);
            if (t->nodes[k].kind != AG_NODE_SPLIT)
                break;
            k = t->nodes[k].first_child;
        }
        const ag_tnode *e = &t->nodes[k];
        if (e->kind == AG_NODE_PATTERN) {
            const ag_pattern *p = &t->patterns[e->pattern];
            int32_t ri = use_rule(x, p->rule, e->first_child, 2);
            if (emit && !x->st) {
                int rot = (p->rot - t->nodes[x->exemplar[p->rule]].rule_rot) & 3;
                if (p->nvec)
                    x->st = ag_grammar_add_repeat(r, x->g->rules[ri].name, cur, rot, p->nvec,
                                                  p->counts, p->vec, 0, 0);
                else
                    x->st = ag_grammar_add_apply(r, x->g->rules[ri].name, cur, rot, p->counts,
                                                 p->step, 0, 0);
            }
        } else if (e->kind == AG_NODE_COMPONENT && is_rule(x, e->rule)) {
            int32_t ri = use_rule(x, e->rule, k, 1);
            if (emit && !x->st) {
                int rot = (e->rule_rot - t->nodes[x->exemplar[e->rule]].rule_rot) & 3;
                x->st = ag_grammar_add_apply(r, x->g->rules[ri].name, cur, rot, NULL, NULL, 0, 0);
            }
        } else {
            emit_content(x, r, k, cur, counter);
        }
    }
}

void ag_grammar_export_info_free(ag_grammar_export_info *info)
{
    if (!info)
        return;
    free(info->rule_of_class);
    free(info->terminal_of_variant);
    memset(info, 0, sizeof *info);
}

ag_status ag_grammar_export(const ag_mesh *m, const ag_labels *L, const ag_splittree *t,
                            ag_grammar **out, ag_grammar_export_info *info, ag_error *err)
{
    *out = NULL;
    exctx x = {.m = m, .L = L, .t = t};
    size_t nc = t->nrules;
    size_t maxt = 0;
    for (size_t c = 0; c < L->ncomponents; c++)
        if (L->ntris[c] > maxt)
            maxt = L->ntris[c];
    x.g = ag_grammar_create();
    x.apps = calloc(nc + 1, sizeof *x.apps);
    x.exemplar = malloc((nc + 1) * sizeof *x.exemplar);
    x.visited = calloc(nc + 1, 1);
    x.in_pattern = calloc(nc + 1, 1);
    x.rule_of = malloc((nc + 1) * sizeof *x.rule_of);
    x.term_of = malloc((L->nvariants + 1) * sizeof *x.term_of);
    /* maxt < 2^32 (triangle indices are 32 bits): the table's size always fits */
    if (ag_array_hash_size(3 * maxt, &x.wcap))
        x.wcap = 0;
    x.wslot = x.wcap ? calloc(x.wcap, sizeof *x.wslot) : NULL;
    x.wused = malloc((3 * maxt + 3) * sizeof *x.wused);
    x.tpos = malloc((9 * maxt + 3) * sizeof *x.tpos);
    x.ttri = malloc((3 * maxt + 3) * sizeof *x.ttri);
    ag_status st = AG_ERR_NOMEM;
    if (!x.g || !x.apps || !x.exemplar || !x.visited || !x.in_pattern || !x.rule_of || !x.term_of || !x.wslot ||
        !x.wused || !x.tpos || !x.ttri)
        goto done;
    for (size_t i = 0; i < nc; i++)
        x.rule_of[i] = -1;
    for (size_t i = 0; i < L->nvariants; i++)
        x.term_of[i] = -1;
    unsigned counter = 0;
    x.pass = 1;
    emit_content(&x, &scratch_rule, 0, "p", &counter);
    x.pass = 2;
    counter = 0;
    x.g->has_axiom = 1;
    x.g->axiom.box = t->nodes[0].box;
    emit_content(&x, &x.g->axiom, 0, "p", &counter);
    st = x.st;
    if (st)
        goto done;
    {
        long col;
        ag_error why;
        ag_error_clear(&why);
        st = ag_grammar_resolve(x.g, &why, &col);
        if (st) {
            /* the reason is copied first: err may not be both the source and the target */
            st = ag_error_set(err, AG_ERR_INTERNAL, 0, "exported grammar does not resolve: %s",
                              why.text);
            goto done;
        }
    }
    if (info) {
        info->rule_of_class = x.rule_of;
        info->terminal_of_variant = x.term_of;
        info->nclasses = nc;
        info->nvariants = L->nvariants;
        x.rule_of = NULL;
        x.term_of = NULL;
    }
    *out = x.g;
    x.g = NULL;
    st = AG_OK;
done:
    if (st == AG_ERR_NOMEM)
        ag_error_set(err, st, 0, "out of memory while exporting the grammar");
    ag_grammar_free(x.g);
    free(x.apps);
    free(x.exemplar);
    free(x.visited);
    free(x.in_pattern);
    free(x.rule_of);
    free(x.term_of);
    free(x.wslot);
    free(x.wused);
    free(x.tpos);
    free(x.ttri);
    return st;
}

/* ---- derivation ------------------------------------------------------------------------- */

typedef struct {
    const ag_grammar *g;
    ag_mesh *out;
    size_t max_tris;
    int32_t *tgroup; /* per terminal: group of the derived mesh */
    ag_status st;
    ag_error *err;
} dctx;

static void derive_body(dctx *d, const ag_grule *r, const ag_box *p, const ag_gframe *F, int depth);

static void apply_one(dctx *d, const ag_gstmt *s, const ag_box *B, const ag_gframe *F, int depth)
{
    if (d->st)
        return;
    /* derivation takes a resolved grammar: every callee is an index */
    assert(s->callee_ix >= 0 &&
           (size_t)s->callee_ix < (s->callee_is_rule ? d->g->nrules : d->g->nterminals));
    if (s->callee_is_rule) {
        const ag_grule *r = &d->g->rules[s->callee_ix];
        ag_gframe G = ag_gframe_place(F, r->size, s->rot, B);
        ag_box lb = {{0, 0, 0}, {r->size[0], r->size[1], r->size[2]}};
        derive_body(d, r, &lb, &G, depth + 1);
        return;
    }
    const ag_gterminal *T = &d->g->terminals[s->callee_ix];
    if (!T->pos && T->ntris) {
        d->st = ag_error_set(d->err, AG_ERR_INVALID, s->line,
                             "terminal '%s' has no geometry loaded", T->name);
        return;
    }
    if (d->out->ntris + T->ntris > d->max_tris) {
        d->st = ag_error_set(d->err, AG_ERR_TOO_LARGE, s->line,
                             "the derivation exceeds %zu triangles", d->max_tris);
        return;
    }
    ag_gframe G = ag_gframe_place(F, T->size, s->rot, B);
    ag_mesh *m = d->out;
    size_t base = m->nverts, comp;
    if ((d->st = ag_mesh_add_component(m, d->tgroup[s->callee_ix], &comp)))
        return;
    for (size_t v = 0; v < T->nverts; v++) {
        double y[3];
        ag_gframe_apply(&G, T->pos + 3 * v, y);
        if ((d->st = ag_mesh_add_vertex(m, y[0], y[1], y[2])))
            return;
    }
    for (size_t t = 0; t < T->ntris; t++) {
        const uint32_t *q = T->tri + 3 * t;
        if (q[0] >= T->nverts || q[1] >= T->nverts || q[2] >= T->nverts) {
            d->st = ag_error_set(d->err, AG_ERR_INVALID, 0, "terminal '%s' has a bad index",
                                 T->name);
            return;
        }
        if ((d->st = ag_mesh_add_triangle(m, (uint32_t)(base + q[0]), (uint32_t)(base + q[1]),
                                          (uint32_t)(base + q[2]), (uint32_t)comp)))
            return;
    }
}

static void derive_body(dctx *d, const ag_grule *r, const ag_box *p, const ag_gframe *F, int depth)
{
    if (d->st)
        return;
    if (depth > DERIVE_MAX_DEPTH) {
        d->st = ag_error_set(d->err, AG_ERR_TOO_LARGE, r->line,
                             "rules are nested more than %d deep", DERIVE_MAX_DEPTH);
        return;
    }
    ag_box stackb[64];
    ag_box *b = r->nnodes <= 64 ? stackb : malloc(r->nnodes * sizeof *b);
    if (!b) {
        d->st = AG_ERR_NOMEM;
        return;
    }
    b[0] = *p;
    for (size_t i = 0; i < r->nstmts && !d->st; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            b[s->node_ix] = ag_splittree_child_box(&b[s->parent_ix], s->v, s->octant);
            continue;
        }
        const ag_box *B = &b[s->node_ix];
        if (!s->subdivide) {
            apply_one(d, s, B, F, depth);
            continue;
        }
        ag_gframe_cells cells;
        ag_gframe_cells_of(s, B, &cells);
        for (uint32_t k = 0; k < s->counts[2] && !d->st; k++)
            for (uint32_t j = 0; j < s->counts[1] && !d->st; j++)
                for (uint32_t i2 = 0; i2 < s->counts[0] && !d->st; i2++) {
                    ag_box c = ag_gframe_cell(&cells, i2, j, k);
                    apply_one(d, s, &c, F, depth);
                }
    }
    if (b != stackb)
        free(b);
}

ag_status ag_grammar_derive(const ag_grammar *g, const ag_grammar_derive_options *opt,
                            ag_mesh **out, ag_error *err)
{
    *out = NULL;
    if (!g->has_axiom)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the grammar has no axiom");
    dctx d = {.g = g, .err = err};
    d.max_tris = opt && opt->max_triangles ? opt->max_triangles : DERIVE_MAX_TRIANGLES;
    d.out = ag_mesh_create();
    if (!d.out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    d.tgroup = malloc((g->nterminals + 1) * sizeof *d.tgroup);
    if (!d.tgroup)
        d.st = AG_ERR_NOMEM;
    for (size_t i = 0; i < g->nterminals && !d.st; i++) {
        const char *gn = g->terminals[i].label_name ? g->terminals[i].label_name
                                                    : g->terminals[i].name;
        size_t k = 0;
        while (k < d.out->ngroups && strcmp(d.out->group_names[k], gn))
            k++;
        if (k == d.out->ngroups)
            d.st = ag_mesh_add_group(d.out, gn, &k);
        d.tgroup[i] = (int32_t)k;
    }
    if (!d.st)
        derive_body(&d, &g->axiom, &g->axiom.box, &ag_gframe_identity, 0);
    free(d.tgroup);
    if (d.st) {
        ag_mesh_free(d.out);
        if (d.st == AG_ERR_NOMEM)
            ag_error_set(err, d.st, 0, "out of memory while deriving");
        return d.st;
    }
    if (d.out->ntris == 0) {
        ag_mesh_free(d.out);
        return ag_error_set(err, AG_ERR_EMPTY, 0, "the grammar derives no triangle");
    }
    *out = d.out;
    return AG_OK;
}

/* ---- fidelity ------------------------------------------------------------------------- */

/* Triangles of a mesh grouped by component, with each component's box. */
typedef struct {
    uint32_t *start, *tris;
    ag_box *box;
    size_t n;
} bycomp;

static void bycomp_free(bycomp *b)
{
    free(b->start);
    free(b->tris);
    free(b->box);
}

static int bycomp_of(const ag_mesh *m, bycomp *b)
{
    b->n = m->ncomponents;
    b->start = calloc(b->n + 2, sizeof *b->start);
    b->tris = malloc((m->ntris + 1) * sizeof *b->tris);
    b->box = malloc((b->n + 1) * sizeof *b->box);
    uint32_t *fill = malloc((b->n + 1) * sizeof *fill);
    if (!b->start || !b->tris || !b->box || !fill) {
        free(fill);
        return -1;
    }
    for (size_t c = 0; c < b->n; c++)
        b->box[c] = ag_box_empty();
    for (size_t t = 0; t < m->ntris; t++) {
        uint32_t c = m->tri_component[t];
        b->start[c + 1]++;
        for (int v = 0; v < 3; v++)
            ag_box_extend_point(&b->box[c], m->pos + 3 * (size_t)m->tri[3 * t + v]);
    }
    for (size_t c = 0; c < b->n; c++)
        b->start[c + 1] += b->start[c];
    memcpy(fill, b->start, b->n * sizeof *fill);
    for (size_t t = 0; t < m->ntris; t++)
        b->tris[fill[m->tri_component[t]]++] = (uint32_t)t;
    free(fill);
    return 0;
}

/* The triangles l (n of them) as a soup relative to origin o. */
static void soup_of(const ag_mesh *m, const uint32_t *l, size_t n, const double o[3], double *s)
{
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            for (int a = 0; a < 3; a++)
                s[9 * i + 3 * k + a] = m->pos[3 * (size_t)m->tri[3 * (size_t)l[i] + k] + a] - o[a];
}

typedef struct {
    uint64_t key;
    int32_t head;
} pslot;

typedef struct {
    double dev;
    int32_t d;
} pcand;

static int cmp_cand(const void *a, const void *b)
{
    const pcand *x = a, *y = b;
    if (x->dev != y->dev)
        return x->dev < y->dev ? -1 : 1;
    return (x->d > y->d) - (x->d < y->d);
}

/* A's triangles l (n of them) on surface B: the count not within tol, and the bound. */
static void cover_count(const ag_mesh *A, const uint32_t *l, size_t n, ag_surface *B,
                        const double o[3], double tol, double *scratch, double *upper,
                        size_t *missing)
{
    soup_of(A, l, n, o, scratch);
    ag_surface_cover_result r;
    ag_surface_cover(B, scratch, n, tol, 0, 0, &r);
    if (r.upper > *upper)
        *upper = r.upper;
    *missing += r.uncovered;
}

ag_status ag_grammar_fidelity(const ag_mesh *input, const ag_mesh *derived, double tol,
                              ag_fidelity *f, ag_error *err)
{
    memset(f, 0, sizeof *f);
    f->input_triangles = input->ntris;
    f->derived_triangles = derived->ntris;
    ag_box b = ag_mesh_bounds(input);
    double diag = ag_box_diagonal(&b);
    if (!(diag > 0))
        diag = 1;
    if (tol <= 0)
        tol = AG_PROC_FIDELITY * diag;
    /* components are paired by their boxes (a placed terminal spans its node's box, which
     * is its component's), then compared surface to surface; what pairs with nothing is
     * compared with the whole other mesh */
    double pair_tol = 2 * tol + AG_PROC_COINCIDENT * diag;
    double fast_tol = fmin(tol, AG_PROC_FIDELITY * diag);
    double cell = 2 * pair_tol;
    bycomp I = {0}, D = {0};
    pslot *tab = NULL;
    int32_t *next = NULL, *pair = NULL;
    uint8_t *taken = NULL;
    double *sa = NULL, *sb = NULL;
    pcand *cand = NULL;
    uint32_t *left_i = NULL, *left_d = NULL;
    size_t nli = 0, nld = 0, cap = 0, maxt = 0;
    ag_status st = AG_ERR_NOMEM;
    if (bycomp_of(input, &I) || bycomp_of(derived, &D) || ag_array_hash_size(D.n, &cap))
        goto done;
    tab = malloc(cap * sizeof *tab);
    next = malloc((D.n + 1) * sizeof *next);
    pair = malloc((I.n + 1) * sizeof *pair);
    taken = calloc(D.n + 1, 1);
    left_i = malloc((input->ntris + 1) * sizeof *left_i);
    left_d = malloc((derived->ntris + 1) * sizeof *left_d);
    if (!tab || !next || !pair || !taken || !left_i || !left_d)
        goto done;
    for (size_t i = 0; i < cap; i++)
        tab[i].head = -1;
    for (size_t c = 0; c < D.n; c++) {
        size_t k = D.start[c + 1] - D.start[c];
        if (k > maxt)
            maxt = k;
        if (!k)
            continue;
        const double *p = D.box[c].min;
        uint64_t key = ag__cell_hash((int64_t)floor(p[0] / cell), (int64_t)floor(p[1] / cell),
                                     (int64_t)floor(p[2] / cell));
        size_t h = key & (cap - 1);
        while (tab[h].head >= 0 && tab[h].key != key)
            h = (h + 1) & (cap - 1);
        tab[h].key = key;
        next[c] = tab[h].head;
        tab[h].head = (int32_t)c;
    }
    for (size_t c = 0; c < I.n; c++) {
        size_t k = I.start[c + 1] - I.start[c];
        if (k > maxt)
            maxt = k;
    }
    sa = malloc((9 * maxt + 1) * sizeof *sa);
    sb = malloc((9 * maxt + 1) * sizeof *sb);
    cand = malloc((D.n + 1) * sizeof *cand);
    if (!sa || !sb || !cand)
        goto done;
    /* pass 0: copies by their triangle lists; 1: surfaces at a finer tolerance (a certified
     * bound is only as fine as the tolerance it was proven at, so a close match reports a
     * close bound); 2: surfaces at tol; 3: what is left is a difference. Each pass runs
     * over every component before the next, so a loose match never takes a component's
     * partner from a closer one. pair: -1 open, -2 done without a partner. */
    for (size_t c = 0; c < I.n; c++)
        pair[c] = I.start[c + 1] > I.start[c] ? -1 : -2;
    for (int pass = 0; pass < 4; pass++)
        for (size_t c = 0; c < I.n; c++) {
            if (pair[c] != -1)
                continue;
            const uint32_t *li = I.tris + I.start[c];
            size_t ni = I.start[c + 1] - I.start[c];
            /* the derived components on the same box, closest first */
            const double *p = I.box[c].min;
            int64_t k0 = (int64_t)floor(p[0] / cell), k1 = (int64_t)floor(p[1] / cell),
                    k2 = (int64_t)floor(p[2] / cell);
            size_t nc = 0;
            for (int nb = 0; nb < 27; nb++) {
                uint64_t key =
                    ag__cell_hash(k0 + nb % 3 - 1, k1 + nb / 3 % 3 - 1, k2 + nb / 9 - 1);
                size_t h = key & (cap - 1);
                while (tab[h].head >= 0 && tab[h].key != key)
                    h = (h + 1) & (cap - 1);
                for (int32_t d = tab[h].head; d >= 0; d = next[d]) {
                    if (taken[d])
                        continue;
                    double dev = 0;
                    for (int a = 0; a < 3; a++)
                        dev = fmax(dev, fmax(fabs(D.box[d].min[a] - I.box[c].min[a]),
                                             fabs(D.box[d].max[a] - I.box[c].max[a])));
                    if (dev <= pair_tol) {
                        cand[nc].dev = dev;
                        cand[nc++].d = d;
                    }
                }
            }
            qsort(cand, nc, sizeof *cand, cmp_cand);
            double o[3];
            ag_box_centre(&I.box[c], o);
            soup_of(input, li, ni, o, sa);
            if (pass < 3) {
                /* several components on one box (copies in one place, a wall and its
                 * opening's frame): the closest that matches */
                for (size_t j = 0; j < nc; j++) {
                    int32_t d = cand[j].d;
                    const uint32_t *ld = D.tris + D.start[d];
                    size_t nd = D.start[d + 1] - D.start[d];
                    if (pass == 0 && nd != ni)
                        continue;
                    soup_of(derived, ld, nd, o, sb);
                    double w;
                    int same;
                    if (pass == 0) {
                        /* copies, at a tolerance tight enough that the pairing of triangles
                         * is the true one (a loose one could pair neighbours and report
                         * their gap) */
                        if ((same = ag_label_soups_match(sb, nd, sa, ni, fast_tol, &w)) < 0)
                            goto done;
                    } else {
                        double t = pass == 1 ? tol / AG_PROC_FIDELITY_REFINE : tol;
                        if ((same = ag_label_same_surface(sa, ni, sb, nd, t, &w)) < 0)
                            goto done;
                    }
                    if (same) {
                        pair[c] = d;
                        taken[d] = 1;
                        f->max_error = fmax(f->max_error, w);
                        break;
                    }
                }
                continue;
            }
            if (!nc) {
                pair[c] = -2;
                memcpy(left_i + nli, li, ni * sizeof *li);
                nli += ni;
                continue;
            }
            /* a difference: counted both ways */
            int32_t d = cand[0].d;
            pair[c] = d;
            taken[d] = 1;
            const uint32_t *ld = D.tris + D.start[d];
            size_t nd = D.start[d + 1] - D.start[d];
            soup_of(derived, ld, nd, o, sb);
            ag_surface S;
            if (ag_surface_init(&S, sb, nd)) {
                ag_surface_free(&S);
                goto done;
            }
            ag_surface_cover_result r;
            ag_surface_cover(&S, sa, ni, tol, 0, 0, &r);
            ag_surface_free(&S);
            f->unmatched += r.uncovered;
            f->max_error = fmax(f->max_error, r.upper);
            if (ag_surface_init(&S, sa, ni)) {
                ag_surface_free(&S);
                goto done;
            }
            ag_surface_cover(&S, sb, nd, tol, 0, 0, &r);
            ag_surface_free(&S);
            f->spurious += r.uncovered;
            f->max_error = fmax(f->max_error, r.upper);
        }
    for (size_t d = 0; d < D.n; d++)
        if (!taken[d]) {
            size_t nd = D.start[d + 1] - D.start[d];
            memcpy(left_d + nld, D.tris + D.start[d], nd * sizeof *left_d);
            nld += nd;
        }
    if (nli || nld) {
        /* what did not pair, against the whole of the other mesh */
        double o[3];
        ag_box_centre(&b, o);
        size_t most = derived->ntris > input->ntris ? derived->ntris : input->ntris;
        size_t part_n = nli > nld ? nli : nld;
        double *whole = malloc((9 * most + 1) * sizeof *whole);
        double *part = malloc((9 * part_n + 1) * sizeof *part);
        uint32_t *every = malloc((most + 1) * sizeof *every);
        int ok = whole && part && every;
        for (size_t t = 0; ok && t < most; t++)
            every[t] = (uint32_t)t;
        for (int side = 0; side < 2 && ok; side++) {
            const ag_mesh *of = side ? derived : input, *on = side ? input : derived;
            const uint32_t *left = side ? left_d : left_i;
            size_t nleft = side ? nld : nli;
            if (!nleft)
                continue;
            ag_surface S;
            soup_of(on, every, on->ntris, o, whole);
            if (ag_surface_init(&S, whole, on->ntris) == AG_OK)
                cover_count(of, left, nleft, &S, o, tol, part, &f->max_error,
                            side ? &f->spurious : &f->unmatched);
            else
                ok = 0;
            ag_surface_free(&S);
        }
        free(whole);
        free(part);
        free(every);
        if (!ok)
            goto done;
    }
    f->relative = f->max_error / diag;
    st = AG_OK;
done:
    bycomp_free(&I);
    bycomp_free(&D);
    free(tab);
    free(next);
    free(pair);
    free(taken);
    free(sa);
    free(sb);
    free(cand);
    free(left_i);
    free(left_d);
    if (st)
        return ag_error_set(err, st, 0, "out of memory measuring the fidelity");
    return AG_OK;
}
