#include "model_tree.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "../io/numtext.h"


static const char *kind_name(int k)
{
    switch (k) {
    case AG_NODE_ROOT:
        return "root";
    case AG_NODE_SPLIT:
        return "split";
    case AG_NODE_COMPONENT:
        return "component";
    case AG_NODE_PATTERN:
        return "pattern";
    default:
        return "dead";
    }
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

static json_t *vec_json(const double *v)
{
    json_t *a = json_array();
    for (int k = 0; k < 3; k++)
        json_array_append_new(a, json_real(v[k] == 0 ? 0 : v[k]));
    return a;
}

/* The label of a visible node: its component's group in the model's mesh. */
static const char *label_of(const ag_proceduralize_result *r, const ag_tnode *x, char fallback[32])
{
    const ag_mesh *m = r->mesh;
    if (x->component >= 0 && (size_t)x->component < m->ncomponents) {
        int32_t g = m->component_group[x->component];
        if (g >= 0 && (size_t)g < m->ngroups)
            return m->group_names[g];
    }
    if (x->label < 0)
        return NULL;
    snprintf(fallback, 32, "L%d", x->label + 1);
    return fallback;
}

/* The grammar rule of a rule class, NULL when the class is inlined. */
static const char *rule_name(const ag_proceduralize_result *r, int32_t cls)
{
    if (cls < 0 || (size_t)cls >= r->tree->nrules || !r->info.rule_of_class)
        return NULL;
    int32_t ri = r->info.rule_of_class[cls];
    return ri >= 0 && (size_t)ri < r->grammar->nrules ? r->grammar->rules[ri].name : NULL;
}

static const char *terminal_name(const ag_proceduralize_result *r, const ag_tnode *x)
{
    if (x->variant < 0 || !r->info.terminal_of_variant ||
        (size_t)x->variant >= r->labels->nvariants)
        return NULL;
    int32_t ti = r->info.terminal_of_variant[x->variant];
    return ti >= 0 && (size_t)ti < r->grammar->nterminals ? r->grammar->terminals[ti].name : NULL;
}

static const ag_pattern *pattern_of(const ag_splittree *t, const ag_tnode *x)
{
    if (x->kind != AG_NODE_PATTERN || x->pattern < 0 || (size_t)x->pattern >= t->npatterns)
        return NULL;
    return &t->patterns[x->pattern];
}

static json_t *pattern_json(const ag_pattern *p)
{
    json_t *o = json_object();
    /* a lattice has counts per vector; the axes it does not use count 1 */
    json_t *counts = json_array();
    for (int k = 0; k < 3; k++)
        json_array_append_new(counts, json_integer(p->nvec && k >= p->nvec ? 1 : p->counts[k]));
    json_object_set_new(o, "counts", counts);
    if (p->nvec) {
        json_object_set_new(o, "step", json_null());
        json_t *vs = json_array();
        for (int k = 0; k < p->nvec; k++)
            json_array_append_new(vs, vec_json(p->vec[k]));
        json_object_set_new(o, "vectors", vs);
    } else {
        json_object_set_new(o, "step", vec_json(p->step));
    }
    if (p->rot)
        json_object_set_new(o, "rot", json_integer(90 * p->rot));
    return o;
}

static json_t *children_json(const ag_splittree *t, const ag_tnode *x)
{
    json_t *ch = json_array();
    for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling)
        json_array_append_new(ch, json_integer(c));
    return ch;
}

/* The served tree; with_nodes = 0 leaves out "root" and "nodes" (the text form prints them
 * itself). */
static json_t *served(const ag_edit_model *em, int with_nodes)
{
    const ag_proceduralize_result *r = em->proc;
    const ag_splittree *t = r->tree;
    json_t *root = json_object(), *nodes = json_array(), *labels = json_array();
    json_t *index = json_object(); /* label → position in labels */
    size_t *apps = calloc(t->nrules + 1, sizeof *apps);
    if (!root || !nodes || !labels || !index || !apps)
        goto fail;
    size_t visible = 0, live = 0;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        json_t *o = with_nodes ? json_object() : NULL;
        if (with_nodes && !o)
            goto fail;
        json_array_append_new(nodes, o);
        int dead = x->kind == AG_NODE_DEAD;
        live += !dead;
        if (o && dead) { /* only its id: see the header */
            json_object_set_new(o, "id", json_integer((json_int_t)n));
            json_object_set_new(o, "kind", json_string(kind_name(x->kind)));
            continue;
        }
        if (o) {
            json_object_set_new(o, "id", json_integer((json_int_t)n));
            json_object_set_new(o, "parent",
                                x->parent >= 0 ? json_integer(x->parent) : json_null());
            json_object_set_new(o, "children", children_json(t, x));
            json_object_set_new(o, "kind", json_string(kind_name(x->kind)));
            json_object_set_new(o, "box", box_json(&x->box));
            json_object_set_new(o, "visible", json_boolean(x->kind == AG_NODE_COMPONENT));
        }
        const ag_pattern *p = dead ? NULL : pattern_of(t, x);
        char fallback[32];
        const char *label = x->kind == AG_NODE_COMPONENT ? label_of(r, x, fallback) : NULL;
        int32_t cls = dead ? -1 : p ? p->rule : x->rule;
        const char *rule = rule_name(r, cls);
        if (rule && !p && cls >= 0)
            apps[cls]++;
        if (o) {
            json_object_set_new(o, "label", label ? json_string(label) : json_null());
            json_object_set_new(o, "rule", rule ? json_string(rule) : json_null());
            const char *term = x->kind == AG_NODE_COMPONENT ? terminal_name(r, x) : NULL;
            json_object_set_new(o, "terminal", term ? json_string(term) : json_null());
            json_object_set_new(o, "component", x->kind == AG_NODE_COMPONENT && x->component >= 0
                                                    ? json_integer(x->component)
                                                    : json_null());
            json_object_set_new(o, "pattern", p ? pattern_json(p) : json_null());
        }
        if (x->kind == AG_NODE_COMPONENT && x->component >= 0)
            visible++;
        if (x->kind != AG_NODE_COMPONENT || !label)
            continue;
        json_t *at = json_object_get(index, label);
        if (at) {
            json_t *l = json_array_get(labels, (size_t)json_integer_value(at));
            json_object_set_new(l, "count",
                                json_integer(json_integer_value(json_object_get(l, "count")) + 1));
            continue;
        }
        char color[8];
        ag_model_tree_label_color(label, color);
        json_object_set_new(index, label, json_integer((json_int_t)json_array_size(labels)));
        json_array_append_new(labels, json_pack("{s:s, s:i, s:s}", "label", label, "count", 1,
                                                "color", color));
    }
    json_t *rules = json_array();
    for (size_t ri = 0; rules && ri < r->grammar->nrules; ri++) {
        size_t n = 0;
        for (size_t c = 0; c < t->nrules; c++)
            if (r->info.rule_of_class && r->info.rule_of_class[c] == (int32_t)ri)
                n += apps[c];
        json_array_append_new(rules, json_pack("{s:s, s:I}", "name", r->grammar->rules[ri].name,
                                               "instances", (json_int_t)n));
    }
    ag_splittree_stats st = ag_splittree_stats_of(t);
    if (with_nodes) {
        json_object_set_new(root, "root", json_integer(0));
        json_object_set_new(root, "nodes", nodes);
    } else {
        json_decref(nodes);
    }
    json_object_set_new(root, "labels", labels);
    json_object_set_new(root, "rules", rules);
    json_object_set_new(root, "stats",
                        json_pack("{s:I, s:I, s:I, s:I, s:I, s:I}", "nodes", (json_int_t)live,
                                  "visible", (json_int_t)st.visible, "invisible",
                                  (json_int_t)(live - st.visible), "depth", (json_int_t)st.depth,
                                  "components", (json_int_t)visible, "patterns",
                                  (json_int_t)t->npatterns));
    json_decref(index);
    free(apps);
    return root;
fail:
    json_decref(root);
    json_decref(nodes);
    json_decref(labels);
    json_decref(index);
    free(apps);
    return NULL;
}

json_t *ag_model_tree_served(const ag_edit_model *em)
{
    return served(em, 1);
}

/* ---- the served tree as text: the nodes printed directly -------------------------------- */

/* The tree is stored with every edit; printing its nodes through jansson objects took most
 * of an edit's time on large buildings, so they are printed here, as jansson would print
 * them (REAL_PRECISION(15), compact), and the small rest (labels, rules, stats) through it. */
typedef struct {
    char *p;
    size_t n, cap;
    int fail;
} text_out;

static void out_reserve(text_out *o, size_t more)
{
    if (!o->fail && o->n + more + 1 > o->cap)
        o->fail = AG_ARRAY_RESERVE_MORE(o->p, o->cap, o->n, more + 1) != AG_OK;
}

static void out_str(text_out *o, const char *s, size_t n)
{
    out_reserve(o, n);
    if (o->fail)
        return;
    memcpy(o->p + o->n, s, n);
    o->n += n;
    o->p[o->n] = '\0';
}

#define OUT_LIT(o, lit) out_str(o, lit, sizeof lit - 1)

static void out_int(text_out *o, long long v)
{
    char b[AG_NUMTEXT_MAX + 1];
    size_t n = 0;
    if (v < 0)
        b[n++] = '-';
    n += ag_numtext_u64(b + n, v < 0 ? 0 - (unsigned long long)v : (unsigned long long)v);
    out_str(o, b, n);
}

/* A real as jansson prints it with REAL_PRECISION(15): %.15g, ".0" added to integral forms
 * (15 digits: a box at UTM coordinates to the nanometre). */
static void out_real(text_out *o, double v)
{
    char b[40];
    if (v == 0)
        v = 0; /* no "-0.0" */
    int n = (int)ag_numtext_double_g15(b, v); /* "%.15g", fast */
    char *e = strchr(b, 'e');
    if (e) { /* jansson drops the exponent's '+' and leading zeros: 1e-07 is 1e-7, 1e+20 1e20 */
        char *d = e + 1;
        if (*d == '-')
            d++;
        char *z = *d == '+' ? d + 1 : d;
        while (*z == '0' && z[1])
            z++;
        if (z != d) {
            memmove(d, z, strlen(z) + 1);
            n = (int)strlen(b);
        }
    }
    if (!strpbrk(b, ".eE") && n + 2 < (int)sizeof b) {
        b[n++] = '.';
        b[n++] = '0';
        b[n] = '\0';
    }
    out_str(o, b, (size_t)n);
}

/* A JSON string (or null for a name that is not valid UTF-8, which jansson would not take). */
static void out_name(text_out *o, const char *s)
{
    if (!s) {
        OUT_LIT(o, "null");
        return;
    }
    size_t len = 0;
    while (s[len] && s[len] >= 0x20 && s[len] < 0x7f && s[len] != '"' && s[len] != '\\')
        len++;
    if (!s[len]) { /* plain ASCII (label, rule and terminal names): as it is */
        out_reserve(o, len + 2);
        OUT_LIT(o, "\"");
        out_str(o, s, len);
        OUT_LIT(o, "\"");
        return;
    }
    json_t *j = json_string(s);
    if (!j) {
        OUT_LIT(o, "null");
        return;
    }
    /* anything else: jansson escapes it as it would */
    char *e = json_dumps(j, JSON_ENCODE_ANY);
    json_decref(j);
    if (!e) {
        o->fail = 1;
        return;
    }
    out_str(o, e, strlen(e));
    free(e);
}

static void out_vec(text_out *o, const double *v)
{
    OUT_LIT(o, "[");
    for (int k = 0; k < 3; k++) {
        if (k)
            OUT_LIT(o, ",");
        out_real(o, v[k]);
    }
    OUT_LIT(o, "]");
}

static void out_pattern(text_out *o, const ag_pattern *p)
{
    OUT_LIT(o, "{\"counts\":[");
    for (int k = 0; k < 3; k++) {
        if (k)
            OUT_LIT(o, ",");
        out_int(o, p->nvec && k >= p->nvec ? 1 : p->counts[k]);
    }
    OUT_LIT(o, "],\"step\":");
    if (p->nvec) {
        OUT_LIT(o, "null,\"vectors\":[");
        for (int k = 0; k < p->nvec; k++) {
            if (k)
                OUT_LIT(o, ",");
            out_vec(o, p->vec[k]);
        }
        OUT_LIT(o, "]");
    } else {
        out_vec(o, p->step);
    }
    if (p->rot) {
        OUT_LIT(o, ",\"rot\":");
        out_int(o, 90 * p->rot);
    }
    OUT_LIT(o, "}");
}

static void out_node(text_out *o, const ag_proceduralize_result *r, size_t n)
{
    const ag_splittree *t = r->tree;
    const ag_tnode *x = &t->nodes[n];
    int dead = x->kind == AG_NODE_DEAD;
    OUT_LIT(o, "{\"id\":");
    out_int(o, (long long)n);
    if (dead) { /* only its id: after many edits most of a tree's ids are dead ones */
        OUT_LIT(o, ",\"kind\":\"dead\"}");
        return;
    }
    OUT_LIT(o, ",\"parent\":");
    if (x->parent >= 0)
        out_int(o, x->parent);
    else
        OUT_LIT(o, "null");
    OUT_LIT(o, ",\"children\":[");
    for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling) {
        if (c != x->first_child)
            OUT_LIT(o, ",");
        out_int(o, c);
    }
    OUT_LIT(o, "],\"kind\":\"");
    const char *k = kind_name(x->kind);
    out_str(o, k, strlen(k));
    OUT_LIT(o, "\",\"box\":[");
    for (int a = 0; a < 6; a++) {
        if (a)
            OUT_LIT(o, ",");
        out_real(o, a < 3 ? x->box.min[a] : x->box.max[a - 3]);
    }
    OUT_LIT(o, "],\"visible\":");
    if (x->kind == AG_NODE_COMPONENT)
        OUT_LIT(o, "true");
    else
        OUT_LIT(o, "false");
    const ag_pattern *p = pattern_of(t, x);
    char fallback[32];
    OUT_LIT(o, ",\"label\":");
    out_name(o, x->kind == AG_NODE_COMPONENT ? label_of(r, x, fallback) : NULL);
    OUT_LIT(o, ",\"rule\":");
    out_name(o, rule_name(r, p ? p->rule : x->rule));
    OUT_LIT(o, ",\"terminal\":");
    out_name(o, x->kind == AG_NODE_COMPONENT ? terminal_name(r, x) : NULL);
    OUT_LIT(o, ",\"component\":");
    if (x->kind == AG_NODE_COMPONENT && x->component >= 0)
        out_int(o, x->component);
    else
        OUT_LIT(o, "null");
    OUT_LIT(o, ",\"pattern\":");
    if (p)
        out_pattern(o, p);
    else
        OUT_LIT(o, "null");
    OUT_LIT(o, "}");
}

char *ag_model_tree_served_text(const ag_edit_model *em)
{
    json_t *rest = served(em, 0);
    char *tail = rest ? json_dumps(rest, JSON_COMPACT | JSON_PRESERVE_ORDER) : NULL;
    json_decref(rest);
    if (!tail || tail[0] != '{') {
        free(tail);
        return NULL;
    }
    const ag_splittree *t = em->proc->tree;
    text_out o = {0};
    size_t dead = 0;
    for (size_t n = 0; n < t->nnodes; n++)
        dead += t->nodes[n].kind == AG_NODE_DEAD;
    out_reserve(&o, 256 * (t->nnodes - dead) + 32 * dead + strlen(tail) + 64);
    OUT_LIT(&o, "{\"root\":0,\"nodes\":[");
    for (size_t n = 0; n < t->nnodes && !o.fail; n++) {
        if (n)
            OUT_LIT(&o, ",");
        out_node(&o, em->proc, n);
    }
    OUT_LIT(&o, "]");
    if (tail[1] != '}')
        OUT_LIT(&o, ",");
    out_str(&o, tail + 1, strlen(tail + 1));
    free(tail);
    if (o.fail) {
        free(o.p);
        return NULL;
    }
    return o.p;
}

json_t *ag_model_tree_boxes(const ag_splittree *t)
{
    json_t *nodes = json_array();
    json_t *tree = nodes ? json_pack("{s:o}", "nodes", nodes) : NULL;
    for (size_t n = 0; tree && n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        json_t *j = json_pack("{s:I, s:s}", "id", (json_int_t)n, "kind", kind_name(x->kind));
        if (j && x->kind != AG_NODE_DEAD)
            json_object_set_new(j, "box",
                                json_pack("[f,f,f,f,f,f]", x->box.min[0], x->box.min[1],
                                          x->box.min[2], x->box.max[0], x->box.max[1],
                                          x->box.max[2]));
        if (!j || json_array_append_new(nodes, j)) {
            json_decref(tree);
            tree = NULL;
        }
    }
    return tree;
}

json_t *ag_model_tree_folder_stats(const ag_edit_model *em)
{
    const ag_splittree *t = em->proc->tree;
    ag_splittree_stats st = ag_splittree_stats_of(t);
    return json_pack("{s:I,s:I,s:I,s:I,s:I,s:I}", "nodes", (json_int_t)st.nodes, "visible",
                     (json_int_t)st.visible, "invisible", (json_int_t)st.invisible, "depth",
                     (json_int_t)st.depth, "patterns", (json_int_t)t->npatterns, "rules",
                     (json_int_t)t->nrules);
}

json_t *ag_model_tree_folder(const ag_edit_model *em)
{
    const ag_proceduralize_result *r = em->proc;
    const ag_splittree *t = r->tree;
    json_t *o = json_object(), *nodes = json_array();
    if (!o || !nodes)
        goto fail;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_DEAD)
            continue;
        json_t *j = json_object();
        if (!j)
            goto fail;
        json_array_append_new(nodes, j);
        json_object_set_new(j, "id", json_integer((json_int_t)n));
        json_object_set_new(j, "parent", x->parent >= 0 ? json_integer(x->parent) : json_null());
        json_object_set_new(j, "kind", json_string(kind_name(x->kind)));
        json_object_set_new(j, "box", box_json(&x->box));
        json_object_set_new(j, "children", children_json(t, x));
        if (x->kind == AG_NODE_COMPONENT) {
            char fallback[32];
            const char *label = label_of(r, x, fallback);
            json_object_set_new(j, "label", label ? json_string(label) : json_null());
            json_object_set_new(j, "component", json_integer(x->component));
            json_object_set_new(j, "rule", x->rule >= 0 ? json_integer(x->rule) : json_null());
        }
        const ag_pattern *p = pattern_of(t, x);
        if (p)
            json_object_set_new(j, "counts", json_pack("[I,I,I]", (json_int_t)p->counts[0],
                                                       (json_int_t)p->counts[1],
                                                       (json_int_t)p->counts[2]));
    }
    json_object_set_new(o, "root", json_integer(0));
    json_object_set_new(o, "nodes", nodes);
    json_object_set_new(o, "stats", ag_model_tree_folder_stats(em));
    return o;
fail:
    json_decref(o);
    json_decref(nodes);
    return NULL;
}

/* ---- the folder's tree.json as text ------------------------------------------------------ */

/* tree.json of a folder is printed directly too (it took most of `archgram proceduralize`'s
 * time on large buildings through jansson objects): character for character what
 * json_dumps(ag_model_tree_folder(em), JSON_INDENT(1) | JSON_REAL_PRECISION(15)) prints. */
static void out_indent(text_out *o, int depth)
{
    static const char line[] = "\n        "; /* the tree's indents are at most 4 */
    if (depth < (int)sizeof line - 1) {
        out_str(o, line, (size_t)depth + 1);
        return;
    }
    OUT_LIT(o, "\n");
    for (int i = 0; i < depth; i++)
        OUT_LIT(o, " ");
}

/* ",\n<indent>\"key\": " (the comma unless first) */
static void out_key(text_out *o, int depth, const char *key, int first)
{
    if (!first)
        OUT_LIT(o, ",");
    out_indent(o, depth);
    OUT_LIT(o, "\"");
    out_str(o, key, strlen(key));
    OUT_LIT(o, "\": ");
}

static void out_int_list(text_out *o, int depth, const long long *v, size_t n)
{
    if (!n) {
        OUT_LIT(o, "[]");
        return;
    }
    OUT_LIT(o, "[");
    for (size_t i = 0; i < n; i++) {
        if (i)
            OUT_LIT(o, ",");
        out_indent(o, depth + 1);
        out_int(o, v[i]);
    }
    out_indent(o, depth);
    OUT_LIT(o, "]");
}

char *ag_model_tree_folder_text(const ag_edit_model *em)
{
    const ag_proceduralize_result *r = em->proc;
    const ag_splittree *t = r->tree;
    text_out o = {0};
    long long *ids = NULL;
    size_t cap_ids = 0;
    out_reserve(&o, 160 * t->nnodes + 256);
    OUT_LIT(&o, "{");
    out_key(&o, 1, "root", 1);
    OUT_LIT(&o, "0");
    out_key(&o, 1, "nodes", 0);
    int any = 0;
    for (size_t n = 0; n < t->nnodes && !o.fail; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_DEAD)
            continue;
        out_str(&o, any ? "," : "[", 1);
        any = 1;
        out_indent(&o, 2);
        OUT_LIT(&o, "{");
        out_key(&o, 3, "id", 1);
        out_int(&o, (long long)n);
        out_key(&o, 3, "parent", 0);
        if (x->parent >= 0)
            out_int(&o, x->parent);
        else
            OUT_LIT(&o, "null");
        out_key(&o, 3, "kind", 0);
        out_name(&o, kind_name(x->kind));
        out_key(&o, 3, "box", 0);
        OUT_LIT(&o, "[");
        for (int a = 0; a < 6; a++) {
            if (a)
                OUT_LIT(&o, ",");
            out_indent(&o, 4);
            out_real(&o, a < 3 ? x->box.min[a] : x->box.max[a - 3]);
        }
        out_indent(&o, 3);
        OUT_LIT(&o, "]");
        out_key(&o, 3, "children", 0);
        size_t nc = 0;
        for (int32_t c = x->first_child; c >= 0 && !o.fail; c = t->nodes[c].next_sibling) {
            if (AG_ARRAY_RESERVE(ids, cap_ids, nc + 1))
                o.fail = 1;
            else
                ids[nc++] = c;
        }
        out_int_list(&o, 3, ids, nc);
        if (x->kind == AG_NODE_COMPONENT) {
            char fallback[32];
            const char *label = label_of(r, x, fallback);
            json_t *js = label ? json_string(label) : NULL;
            if (!label || js) { /* a name jansson refuses (not UTF-8) leaves the key out */
                out_key(&o, 3, "label", 0);
                out_name(&o, label);
            }
            json_decref(js);
            out_key(&o, 3, "component", 0);
            out_int(&o, x->component);
            out_key(&o, 3, "rule", 0);
            if (x->rule >= 0)
                out_int(&o, x->rule);
            else
                OUT_LIT(&o, "null");
        }
        const ag_pattern *p = pattern_of(t, x);
        if (p) {
            long long c3[3] = {p->counts[0], p->counts[1], p->counts[2]};
            out_key(&o, 3, "counts", 0);
            out_int_list(&o, 3, c3, 3);
        }
        out_indent(&o, 2);
        OUT_LIT(&o, "}");
    }
    if (any) {
        out_indent(&o, 1);
        OUT_LIT(&o, "]");
    } else {
        OUT_LIT(&o, "[]");
    }
    ag_splittree_stats st = ag_splittree_stats_of(t);
    const char *names[] = {"nodes", "visible", "invisible", "depth", "patterns", "rules"};
    long long vals[] = {(long long)st.nodes, (long long)st.visible, (long long)st.invisible,
                        (long long)st.depth, (long long)t->npatterns, (long long)t->nrules};
    out_key(&o, 1, "stats", 0);
    OUT_LIT(&o, "{");
    for (int k = 0; k < 6; k++) {
        out_key(&o, 2, names[k], k == 0);
        out_int(&o, vals[k]);
    }
    out_indent(&o, 1);
    OUT_LIT(&o, "}");
    out_indent(&o, 0);
    OUT_LIT(&o, "}");
    free(ids);
    if (o.fail) {
        free(o.p);
        return NULL;
    }
    return o.p;
}

ag_status ag_model_tree_check_node(const ag_edit_model *em, int32_t id, const char *field,
                                   ag_error *err)
{
    const ag_splittree *t = em->proc->tree;
    if (id < 0 || (size_t)id >= t->nnodes)
        return ag_error_set(err, AG_ERR_NOT_FOUND, id,
                            "%s: node %d is not in the model's split tree (nodes 0..%zu)", field,
                            (int)id, t->nnodes ? t->nnodes - 1 : 0);
    if (t->nodes[id].kind == AG_NODE_DEAD)
        return ag_error_set(err, AG_ERR_NOT_FOUND, id,
                            "%s: node %d of the split tree cannot be edited (proceduralization "
                            "removed it when it found a pattern)",
                            field, (int)id);
    return AG_OK;
}

void ag_model_tree_label_color(const char *label, char out[8])
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

ag_status ag_model_tree_component_meta(const char *json, size_t ncomponents,
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
