#include "splittree_json.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "../core/proc/gframe.h"

enum { K_ROOT, K_SPLIT, K_COMPONENT, K_PATTERN };
static const char *const kind_names[] = {"root", "split", "component", "pattern"};

typedef struct {
    ag_box box;             /* world */
    int32_t parent, first_child, last_child, next_sibling;
    int32_t rule;           /* grammar rule index, -1 */
    int32_t terminal;       /* grammar terminal index, -1 */
    int64_t component;      /* -1 */
    const ag_gstmt *pattern; /* the subdivide/repeat statement of a pattern node */
    uint8_t kind;
    uint16_t depth;
} tnode;

typedef struct {
    const ag_grammar *g;
    tnode *nodes;
    size_t n, cap, max_nodes;
    size_t ncomp;
    uint32_t *rule_apps;
    ag_status st;
    ag_error *err;
} walk;

static int32_t add_node(walk *w, int32_t parent, int kind, const ag_box *box)
{
    if (w->st)
        return -1;
    if (w->n >= w->max_nodes) {
        w->st = ag_error_set(w->err, AG_ERR_TOO_LARGE, 0,
                             "the split tree would have more than %zu nodes", w->max_nodes);
        return -1;
    }
    if (AG_ARRAY_RESERVE(w->nodes, w->cap, w->n + 1)) {
        w->st = ag_error_set(w->err, AG_ERR_NOMEM, 0, "out of memory building the tree");
        return -1;
    }
    int32_t id = (int32_t)w->n++;
    tnode *t = &w->nodes[id];
    memset(t, 0, sizeof *t);
    t->box = *box;
    t->parent = parent;
    t->first_child = t->last_child = t->next_sibling = -1;
    t->rule = t->terminal = -1;
    t->component = -1;
    t->kind = (uint8_t)kind;
    if (parent >= 0) {
        tnode *p = &w->nodes[parent];
        t->depth = (uint16_t)(p->depth + 1);
        if (p->last_child >= 0)
            w->nodes[p->last_child].next_sibling = id;
        else
            p->first_child = id;
        p->last_child = id;
    }
    return id;
}

/* A local box in world coordinates: frames are quarter turns about z and per-axis scales, so
 * the image of a box is the box of two opposite corners' images. */
static ag_box world_box(const ag_gframe *f, const ag_box *b)
{
    double lo[3], hi[3];
    ag_gframe_apply(f, b->min, lo);
    ag_gframe_apply(f, b->max, hi);
    ag_box o = ag_box_empty();
    ag_box_extend_point(&o, lo);
    ag_box_extend_point(&o, hi);
    return o;
}

static void walk_body(walk *w, const ag_grule *r, const ag_box *p, const ag_gframe *F,
                      int32_t pnode, int depth);

/* A node free to take a rule (or a terminal): a split node that has none yet. */
static int32_t target_for(walk *w, int32_t node, int want_terminal, const ag_gframe *F,
                          const ag_box *B)
{
    tnode *t = &w->nodes[node];
    if (t->kind == K_SPLIT || (t->kind == K_COMPONENT && !want_terminal)) {
        if (want_terminal ? t->terminal < 0 : t->rule < 0)
            return node;
    }
    ag_box wb = world_box(F, B);
    return add_node(w, node, want_terminal ? K_COMPONENT : K_SPLIT, &wb);
}

static void apply_one(walk *w, const ag_gstmt *s, const ag_box *B, const ag_gframe *F,
                      int32_t node, int depth)
{
    if (w->st)
        return;
    if (s->callee_is_rule) {
        int32_t n = target_for(w, node, 0, F, B);
        if (n < 0)
            return;
        const ag_grule *r = &w->g->rules[s->callee_ix];
        w->nodes[n].rule = s->callee_ix;
        w->rule_apps[s->callee_ix]++;
        ag_gframe G = ag_gframe_place(F, r->size, s->rot, B);
        ag_box lb = {{0, 0, 0}, {r->size[0], r->size[1], r->size[2]}};
        walk_body(w, r, &lb, &G, n, depth + 1);
        return;
    }
    int32_t n = target_for(w, node, 1, F, B);
    if (n < 0)
        return;
    tnode *t = &w->nodes[n];
    t->kind = K_COMPONENT;
    t->terminal = s->callee_ix;
    t->component = (int64_t)w->ncomp++;
}

static void walk_body(walk *w, const ag_grule *r, const ag_box *p, const ag_gframe *F,
                      int32_t pnode, int depth)
{
    if (w->st)
        return;
    if (depth > 512) {
        w->st = ag_error_set(w->err, AG_ERR_TOO_LARGE, r->line,
                             "rules are nested more than 512 deep");
        return;
    }
    size_t nn = r->nnodes ? r->nnodes : 1;
    ag_box *b = malloc(nn * sizeof *b);
    int32_t *ids = malloc(nn * sizeof *ids);
    if (!b || !ids) {
        free(b);
        free(ids);
        w->st = ag_error_set(w->err, AG_ERR_NOMEM, 0, "out of memory building the tree");
        return;
    }
    b[0] = *p;
    ids[0] = pnode;
    for (size_t i = 0; i < r->nstmts && !w->st; i++) {
        const ag_gstmt *s = &r->stmts[i];
        if (s->kind == AG_GSTMT_SPLIT) {
            b[s->node_ix] = ag_splittree_child_box(&b[s->parent_ix], s->v, s->octant);
            ag_box wb = world_box(F, &b[s->node_ix]);
            ids[s->node_ix] = add_node(w, ids[s->parent_ix], K_SPLIT, &wb);
            continue;
        }
        const ag_box *B = &b[s->node_ix];
        if (!s->subdivide) {
            apply_one(w, s, B, F, ids[s->node_ix], depth);
            continue;
        }
        /* the pattern: the node itself when it is a bare split node, else a child */
        int32_t pn = ids[s->node_ix];
        tnode *t = &w->nodes[pn];
        if (t->kind != K_SPLIT || t->rule >= 0 || t->terminal >= 0 || t->first_child >= 0) {
            ag_box wb = world_box(F, B);
            if ((pn = add_node(w, pn, K_PATTERN, &wb)) < 0)
                break;
        }
        w->nodes[pn].kind = K_PATTERN;
        w->nodes[pn].rule = s->callee_ix;
        w->nodes[pn].pattern = s;
        /* cells exactly as ag_grammar_derive places them */
        ag_gframe_cells cells;
        ag_gframe_cells_of(s, B, &cells);
        for (uint32_t k = 0; k < s->counts[2] && !w->st; k++)
            for (uint32_t j = 0; j < s->counts[1] && !w->st; j++)
                for (uint32_t i2 = 0; i2 < s->counts[0] && !w->st; i2++) {
                    ag_box c = ag_gframe_cell(&cells, i2, j, k);
                    ag_box wb = world_box(F, &c);
                    int32_t cell = add_node(w, pn, K_SPLIT, &wb);
                    if (cell >= 0)
                        apply_one(w, s, &c, F, cell, depth);
                }
    }
    free(b);
    free(ids);
}

void ag_splittree_json_label_color(const char *label, char out[8])
{
    unsigned long idx;
    char *end;
    if (label[0] == 'L' && label[1] >= '1' && label[1] <= '9' &&
        (idx = strtoul(label + 1, &end, 10), *end == '\0')) {
        idx -= 1;
    } else {
        uint32_t h = 2166136261u;
        for (const char *p = label; *p; p++)
            h = (h ^ (unsigned char)*p) * 16777619u;
        idx = h % 9973;
    }
    /* golden-ratio hue steps keep neighbouring labels apart */
    double hue = fmod((double)idx * 0.618033988749895, 1.0), x = hue * 6;
    int i = (int)x;
    double f = x - i, v = 0.85, s = 0.55;
    double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f)), r, g, b;
    switch (i % 6) {
    case 0: r = v, g = t, b = p; break;
    case 1: r = q, g = v, b = p; break;
    case 2: r = p, g = v, b = t; break;
    case 3: r = p, g = q, b = v; break;
    case 4: r = t, g = p, b = v; break;
    default: r = v, g = p, b = q; break;
    }
    snprintf(out, 8, "#%02x%02x%02x", (unsigned)lround(r * 255), (unsigned)lround(g * 255),
             (unsigned)lround(b * 255));
}

static const char *label_of(const ag_grammar *g, int32_t terminal)
{
    const ag_gterminal *t = &g->terminals[terminal];
    return t->label_name ? t->label_name : t->name;
}

static json_t *box_json(const ag_box *b)
{
    json_t *a = json_array();
    for (int k = 0; k < 6; k++) {
        double x = k < 3 ? b->min[k] : b->max[k - 3];
        json_array_append_new(a, json_real(x == 0 ? 0 : x));
    }
    return a;
}

static json_t *vec_json(const double *v, int n)
{
    json_t *a = json_array();
    for (int k = 0; k < n; k++)
        json_array_append_new(a, json_real(v[k] == 0 ? 0 : v[k]));
    return a;
}

static json_t *pattern_json(const ag_gstmt *s)
{
    json_t *o = json_object();
    json_t *counts = json_array();
    for (int k = 0; k < 3; k++)
        json_array_append_new(counts, json_integer(s->subdivide == 2 && k >= s->nvec ? 1 : s->counts[k]));
    json_object_set_new(o, "counts", counts);
    if (s->subdivide == 2) {
        json_object_set_new(o, "step", json_null());
        json_t *vs = json_array();
        for (int k = 0; k < s->nvec; k++)
            json_array_append_new(vs, vec_json(s->vec[k], 3));
        json_object_set_new(o, "vectors", vs);
    } else {
        json_object_set_new(o, "step", vec_json(s->step, 3));
    }
    if (s->rot)
        json_object_set_new(o, "rot", json_integer(90 * s->rot));
    return o;
}

static json_t *to_json(const walk *w)
{
    const ag_grammar *g = w->g;
    json_t *root = json_object();
    json_t *nodes = json_array();
    size_t visible = 0, depth = 0, npat = 0;
    for (size_t i = 0; i < w->n; i++) {
        const tnode *t = &w->nodes[i];
        json_t *children = json_array();
        for (int32_t c = t->first_child; c >= 0; c = w->nodes[c].next_sibling)
            json_array_append_new(children, json_integer(c));
        visible += t->kind == K_COMPONENT;
        npat += t->kind == K_PATTERN;
        if (t->depth > depth)
            depth = t->depth;
        json_t *o = json_object();
        json_object_set_new(o, "id", json_integer((json_int_t)i));
        json_object_set_new(o, "parent", t->parent >= 0 ? json_integer(t->parent) : json_null());
        json_object_set_new(o, "children", children);
        json_object_set_new(o, "kind", json_string(kind_names[t->kind]));
        json_object_set_new(o, "box", box_json(&t->box));
        json_object_set_new(o, "visible", json_boolean(t->kind == K_COMPONENT));
        json_object_set_new(o, "label", t->terminal >= 0 ? json_string(label_of(g, t->terminal))
                                                         : json_null());
        json_object_set_new(o, "rule", t->rule >= 0 ? json_string(g->rules[t->rule].name)
                                                     : json_null());
        json_object_set_new(o, "terminal", t->terminal >= 0
                                               ? json_string(g->terminals[t->terminal].name)
                                               : json_null());
        json_object_set_new(o, "component", t->component >= 0 ? json_integer(t->component)
                                                              : json_null());
        json_object_set_new(o, "pattern", t->pattern ? pattern_json(t->pattern) : json_null());
        json_array_append_new(nodes, o);
    }
    json_object_set_new(root, "root", json_integer(0));
    json_object_set_new(root, "nodes", nodes);

    /* labels in the order they first appear in the derivation */
    json_t *labels = json_array();
    json_t *index = json_object(); /* label → position in labels */
    for (size_t i = 0; i < w->n; i++) {
        const tnode *t = &w->nodes[i];
        if (t->terminal < 0)
            continue;
        const char *name = label_of(g, t->terminal);
        json_t *at = json_object_get(index, name);
        if (at) {
            json_t *o = json_array_get(labels, (size_t)json_integer_value(at));
            json_object_set_new(o, "count",
                                json_integer(json_integer_value(json_object_get(o, "count")) + 1));
            continue;
        }
        char color[8];
        ag_splittree_json_label_color(name, color);
        json_object_set_new(index, name, json_integer((json_int_t)json_array_size(labels)));
        json_array_append_new(labels, json_pack("{s:s, s:i, s:s}", "label", name, "count", 1,
                                                "color", color));
    }
    json_decref(index);
    json_object_set_new(root, "labels", labels);
    json_t *rules = json_array();
    for (size_t r = 0; r < g->nrules; r++)
        json_array_append_new(rules, json_pack("{s:s, s:I}", "name", g->rules[r].name,
                                               "instances", (json_int_t)w->rule_apps[r]));
    json_object_set_new(root, "rules", rules);
    json_object_set_new(root, "stats",
                        json_pack("{s:I, s:I, s:I, s:I, s:I, s:I}", "nodes", (json_int_t)w->n,
                                  "visible", (json_int_t)visible, "invisible",
                                  (json_int_t)(w->n - visible), "depth", (json_int_t)depth,
                                  "components", (json_int_t)w->ncomp, "patterns",
                                  (json_int_t)npat));
    return root;
}

ag_status ag_splittree_json_build(const ag_grammar *g, const ag_splittree_json_options *opt,
                                  char **json, size_t *ncomponents, ag_error *err)
{
    *json = NULL;
    *ncomponents = 0;
    if (!g->has_axiom)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the grammar has no axiom");
    walk w = {.g = g, .err = err};
    w.max_nodes = opt && opt->max_nodes ? opt->max_nodes : 4000000;
    w.rule_apps = calloc(g->nrules + 1, sizeof *w.rule_apps);
    if (!w.rule_apps)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory building the tree");
    ag_box lb = g->axiom.box;
    int32_t root = add_node(&w, -1, K_ROOT, &lb);
    if (root >= 0)
        walk_body(&w, &g->axiom, &lb, &ag_gframe_identity, root, 0);
    if (!w.st) {
        json_t *j = to_json(&w);
        *json = j ? json_dumps(j, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(12))
                  : NULL;
        json_decref(j);
        if (!*json)
            w.st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing the tree");
        *ncomponents = w.ncomp;
    }
    free(w.nodes);
    free(w.rule_apps);
    return w.st;
}

ag_status ag_splittree_json_component_meta(const char *json, size_t ncomponents,
                                           ag_glb_component_meta **meta, char **labels,
                                           ag_error *err)
{
    *meta = NULL;
    *labels = NULL;
    json_error_t je;
    json_t *tree = json_loads(json, 0, &je);
    json_t *nodes = json_object_get(tree, "nodes");
    if (!json_is_array(nodes)) {
        json_decref(tree);
        return ag_error_set(err, AG_ERR_PARSE, 0, "the stored split tree is not valid: %s",
                            tree ? "no nodes" : je.text);
    }
    /* first pass: room for the label strings */
    size_t bytes = 1, i;
    json_t *n;
    json_array_foreach(nodes, i, n) {
        const char *l = json_string_value(json_object_get(n, "label"));
        if (l && json_is_integer(json_object_get(n, "component")))
            bytes += strlen(l) + 1;
    }
    ag_glb_component_meta *m = malloc((ncomponents + 1) * sizeof *m);
    char *block = malloc(bytes), *at = block;
    if (!m || !block) {
        free(m);
        free(block);
        json_decref(tree);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    for (size_t c = 0; c < ncomponents; c++)
        m[c] = (ag_glb_component_meta){NULL, -1};
    json_array_foreach(nodes, i, n) {
        json_t *comp = json_object_get(n, "component");
        if (!json_is_integer(comp))
            continue;
        json_int_t c = json_integer_value(comp);
        if (c < 0 || (size_t)c >= ncomponents)
            continue;
        m[c].node = json_integer_value(json_object_get(n, "id"));
        const char *l = json_string_value(json_object_get(n, "label"));
        if (l) {
            size_t len = strlen(l) + 1;
            memcpy(at, l, len);
            m[c].label = at;
            at += len;
        }
    }
    json_decref(tree);
    *meta = m;
    *labels = block;
    return AG_OK;
}
