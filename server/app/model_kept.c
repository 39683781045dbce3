#include "model_kept.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../core/edit/rebuild.h"
#include "model_tree.h"

#define KEPT_FORMAT 1
#define NODE_INTS 13
#define NODE_FIELDS (NODE_INTS + 9)
#define PATTERN_FIELDS 19

/* ---- writing ----------------------------------------------------------------------------- */

static int push(json_t *a, json_t *v)
{
    return json_array_append_new(a, v);
}

static json_t *int_array(const int32_t *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        if (push(a, json_integer(v[i]))) {
            json_decref(a);
            return NULL;
        }
    return a;
}

static json_t *byte_array(const uint8_t *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        if (push(a, json_integer(v[i]))) {
            json_decref(a);
            return NULL;
        }
    return a;
}

static json_t *node_json(const ag_tnode *x)
{
    json_t *a = json_array();
    if (!a)
        return NULL;
    const json_int_t ints[NODE_INTS] = {x->kind,      x->parent,  x->first_child, x->last_child,
                                        x->next_sibling, x->component, x->label,  x->variant,
                                        x->rot,       x->octant,  x->rule_rot,    x->rule,
                                        x->pattern};
    int fail = 0;
    for (int k = 0; k < NODE_INTS; k++)
        fail |= push(a, json_integer(ints[k]));
    for (int k = 0; k < 3; k++)
        fail |= push(a, json_real(x->box.min[k]));
    for (int k = 0; k < 3; k++)
        fail |= push(a, json_real(x->box.max[k]));
    for (int k = 0; k < 3; k++)
        fail |= push(a, json_real(x->pivot[k]));
    if (fail) {
        json_decref(a);
        return NULL;
    }
    return a;
}

static json_t *pattern_json(const ag_pattern *p)
{
    json_t *a = json_array();
    if (!a)
        return NULL;
    int fail = push(a, json_integer(p->rule)) | push(a, json_integer(p->rot)) |
               push(a, json_integer(p->nvec));
    for (int k = 0; k < 3; k++)
        fail |= push(a, json_integer(p->counts[k]));
    for (int k = 0; k < 3; k++)
        fail |= push(a, json_real(p->step[k]));
    for (int v = 0; v < 3; v++)
        for (int k = 0; k < 3; k++)
            fail |= push(a, json_real(p->vec[v][k]));
    fail |= push(a, json_integer(p->node));
    if (fail) {
        json_decref(a);
        return NULL;
    }
    return a;
}

static json_t *kept_json(const ag_edit_model *em)
{
    const ag_splittree *t = em->proc->tree;
    const ag_labels *L = em->proc->labels;
    json_t *nodes = json_array(), *patterns = json_array(), *rules = json_array();
    json_t *classes = json_object(), *o = json_object();
    int fail = !nodes || !patterns || !rules || !classes || !o;
    for (size_t n = 0; !fail && n < t->nnodes; n++)
        fail = push(nodes, node_json(&t->nodes[n]));
    for (size_t p = 0; !fail && p < t->npatterns; p++)
        fail = push(patterns, pattern_json(&t->patterns[p]));
    for (size_t r = 0; !fail && r < t->nrules; r++)
        fail = push(rules, json_pack("[I,I]", (json_int_t)t->rule_count[r],
                                     (json_int_t)t->rule_rep[r]));
    if (!fail) {
        fail |= json_object_set_new(classes, "nlabels", json_integer((json_int_t)L->nlabels));
        fail |= json_object_set_new(classes, "nvariants",
                                    json_integer((json_int_t)L->nvariants));
        fail |= json_object_set_new(classes, "diagonal", json_real(L->diagonal));
        fail |= json_object_set_new(classes, "tol", json_real(L->tol));
        fail |= json_object_set_new(classes, "exact", json_real(L->exact));
        fail |= json_object_set_new(classes, "label", int_array(L->label, L->ncomponents));
        fail |= json_object_set_new(classes, "variant", int_array(L->variant, L->ncomponents));
        fail |= json_object_set_new(classes, "rot", byte_array(L->rot, L->ncomponents));
        fail |= json_object_set_new(classes, "vrot", byte_array(L->vrot, L->ncomponents));
        fail |= json_object_set_new(classes, "variant_label",
                                    int_array(L->variant_label, L->nvariants));
    }
    if (!fail) {
        fail |= json_object_set_new(o, "format", json_integer(KEPT_FORMAT));
        fail |= json_object_set_new(o, "tol", json_real(t->tol));
        fail |= json_object_set_new(o, "eps", json_real(t->eps));
        fail |= json_object_set_new(o, "ncomponents", json_integer((json_int_t)t->ncomponents));
        fail |= json_object_set_new(o, "nodes", nodes);
        fail |= json_object_set_new(o, "patterns", patterns);
        fail |= json_object_set_new(o, "rules", rules);
        fail |= json_object_set_new(o, "classes", classes);
        nodes = patterns = rules = classes = NULL; /* taken (or freed) by o */
    }
    json_decref(nodes);
    json_decref(patterns);
    json_decref(rules);
    json_decref(classes);
    if (fail) {
        json_decref(o);
        return NULL;
    }
    return o;
}

char *ag_model_kept_tree_text(const ag_edit_model *em)
{
    /* the served part keeps its own (shorter) printing; the kept member is exact */
    char *served = ag_model_tree_served_text(em);
    json_t *k = served ? kept_json(em) : NULL;
    char *kept = k ? json_dumps(k, JSON_COMPACT | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17))
                   : NULL;
    json_decref(k);
    char *out = NULL;
    size_t n = served ? strlen(served) : 0;
    if (kept && n >= 2 && served[n - 1] == '}') {
        size_t kn = strlen(kept);
        if ((out = malloc(n + kn + 16))) {
            memcpy(out, served, n - 1);
            size_t at = n - 1;
            memcpy(out + at, ",\"kept\":", 8);
            at += 8;
            memcpy(out + at, kept, kn);
            at += kn;
            out[at++] = '}';
            out[at] = '\0';
        }
    }
    free(served);
    free(kept);
    return out;
}

#define KEPT_MEMBER ",\"kept\":{\"format\":"

char *ag_model_kept_served_text(const char *tree_text)
{
    /* the kept member is written last and holds only numbers: its start is the last match */
    size_t n = strlen(tree_text);
    const char *at = NULL;
    for (const char *p = strstr(tree_text, KEPT_MEMBER); p; p = strstr(p + 1, KEPT_MEMBER))
        at = p;
    size_t keep = at && n && tree_text[n - 1] == '}' ? (size_t)(at - tree_text) : n;
    char *out = malloc(keep + 2);
    if (!out)
        return NULL;
    memcpy(out, tree_text, keep);
    if (keep < n)
        out[keep++] = '}';
    out[keep] = '\0';
    return out;
}

/* ---- reading ----------------------------------------------------------------------------- */

typedef struct {
    ag_error *err;
    ag_status st;
} reader;

static int bad(reader *R, const char *what)
{
    if (!R->st)
        R->st = ag_error_set(R->err, AG_ERR_PARSE, 0, "the kept model: %s", what);
    return 0;
}

/* An integer in [lo, hi]. */
static int get_int(reader *R, const json_t *v, json_int_t lo, json_int_t hi, json_int_t *out,
                   const char *what)
{
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi)
        return bad(R, what);
    *out = json_integer_value(v);
    return 1;
}

static int get_real(reader *R, const json_t *v, double *out, const char *what)
{
    if (!json_is_number(v) || !isfinite(json_number_value(v)))
        return bad(R, what);
    *out = json_number_value(v);
    return 1;
}

static const json_t *get_array(reader *R, const json_t *o, const char *key, size_t n,
                               const char *what)
{
    const json_t *a = json_object_get(o, key);
    if (!json_is_array(a) || (n != SIZE_MAX && json_array_size(a) != n)) {
        bad(R, what);
        return NULL;
    }
    return a;
}

static int read_node(reader *R, const json_t *a, const ag_splittree *t, size_t nlabels,
                     size_t nvariants, ag_tnode *x)
{
    if (!json_is_array(a) || json_array_size(a) != NODE_FIELDS)
        return bad(R, "a node is not an array of 22 numbers");
    json_int_t n = (json_int_t)t->nnodes, v[NODE_INTS];
    const json_int_t lo[NODE_INTS] = {AG_NODE_ROOT, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, -1, -1};
    const json_int_t hi[NODE_INTS] = {AG_NODE_DEAD,
                                      n - 1,
                                      n - 1,
                                      n - 1,
                                      n - 1,
                                      (json_int_t)t->ncomponents - 1,
                                      (json_int_t)nlabels - 1,
                                      (json_int_t)nvariants - 1,
                                      3,
                                      8,
                                      3,
                                      (json_int_t)t->nrules - 1,
                                      (json_int_t)t->npatterns - 1};
    for (int k = 0; k < NODE_INTS; k++)
        if (!get_int(R, json_array_get(a, k), lo[k], hi[k], &v[k],
                     "a node's field is out of range"))
            return 0;
    memset(x, 0, sizeof *x);
    x->kind = (uint8_t)v[0];
    x->parent = (int32_t)v[1];
    x->first_child = (int32_t)v[2];
    x->last_child = (int32_t)v[3];
    x->next_sibling = (int32_t)v[4];
    x->component = (int32_t)v[5];
    x->label = (int32_t)v[6];
    x->variant = (int32_t)v[7];
    x->rot = (uint8_t)v[8];
    x->octant = (uint8_t)v[9];
    x->rule_rot = (uint8_t)v[10];
    x->rule = (int32_t)v[11];
    x->pattern = (int32_t)v[12];
    double d[9];
    for (int k = 0; k < 9; k++)
        if (!get_real(R, json_array_get(a, NODE_INTS + k), &d[k], "a node's box or pivot"))
            return 0;
    for (int k = 0; k < 3; k++) {
        x->box.min[k] = d[k];
        x->box.max[k] = d[3 + k];
        x->pivot[k] = d[6 + k];
        if (x->box.max[k] < x->box.min[k])
            return bad(R, "a node's box is inverted");
    }
    return 1;
}

static int read_pattern(reader *R, const json_t *a, const ag_splittree *t, ag_pattern *p)
{
    if (!json_is_array(a) || json_array_size(a) != PATTERN_FIELDS)
        return bad(R, "a pattern is not an array of 19 numbers");
    json_int_t v;
    memset(p, 0, sizeof *p);
    if (!get_int(R, json_array_get(a, 0), -1, (json_int_t)t->nrules - 1, &v, "a pattern's rule"))
        return 0;
    p->rule = (int32_t)v;
    if (!get_int(R, json_array_get(a, 1), 0, 3, &v, "a pattern's turn"))
        return 0;
    p->rot = (uint8_t)v;
    if (!get_int(R, json_array_get(a, 2), 0, 3, &v, "a pattern's lattice"))
        return 0;
    p->nvec = (uint8_t)v;
    for (int k = 0; k < 3; k++) {
        if (!get_int(R, json_array_get(a, 3 + k), 0, UINT32_MAX, &v, "a pattern's counts"))
            return 0;
        p->counts[k] = (uint32_t)v;
    }
    for (int k = 0; k < 3; k++)
        if (!get_real(R, json_array_get(a, 6 + k), &p->step[k], "a pattern's step"))
            return 0;
    for (int q = 0; q < 3; q++)
        for (int k = 0; k < 3; k++)
            if (!get_real(R, json_array_get(a, 9 + 3 * q + k), &p->vec[q][k],
                          "a pattern's vectors"))
                return 0;
    if (!get_int(R, json_array_get(a, 18), -1, (json_int_t)t->nnodes - 1, &v,
                 "a pattern's node")) /* -1: a pattern dissolved */
        return 0;
    p->node = (int32_t)v;
    return 1;
}

/* The links make one tree from node 0: every node reached once, by its parent's list, each
 * list ending at its last child; every component named by at most one visible node. */
static int check_links(reader *R, const ag_splittree *t)
{
    if (!t->nnodes || t->nodes[0].kind != AG_NODE_ROOT || t->nodes[0].parent != -1)
        return bad(R, "node 0 is not the root");
    uint8_t *seen = calloc(t->nnodes, 1), *named = calloc(t->ncomponents + 1, 1);
    int32_t *stack = malloc(t->nnodes * sizeof *stack);
    if (!seen || !named || !stack) {
        free(seen);
        free(named);
        free(stack);
        if (!R->st)
            R->st = ag_error_set(R->err, AG_ERR_NOMEM, 0, "out of memory");
        return 0;
    }
    int ok = 1;
    size_t top = 0;
    stack[top++] = 0;
    seen[0] = 1;
    while (top && ok) {
        int32_t p = stack[--top];
        int32_t last = -1;
        for (int32_t c = t->nodes[p].first_child; c >= 0 && ok; c = t->nodes[c].next_sibling) {
            if (seen[c] || t->nodes[c].parent != p || t->nodes[c].kind == AG_NODE_ROOT ||
                t->nodes[c].kind == AG_NODE_DEAD)
                ok = bad(R, "the nodes' links do not make a tree");
            else {
                seen[c] = 1;
                stack[top++] = c;
                last = c;
            }
        }
        if (ok && last != t->nodes[p].last_child)
            ok = bad(R, "a node's last child is not the end of its list");
    }
    for (size_t n = 0; ok && n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (!seen[n] && x->kind != AG_NODE_DEAD) /* dead nodes keep their old links */
            ok = bad(R, "a node outside the tree is not dead");
        else if (x->kind == AG_NODE_COMPONENT && x->component >= 0 && named[x->component]++)
            ok = bad(R, "two nodes hold one component");
        else if (x->kind == AG_NODE_PATTERN &&
                 (x->pattern < 0 || t->patterns[x->pattern].node != (int32_t)n))
            ok = bad(R, "a pattern node and its pattern disagree");
    }
    free(seen);
    free(named);
    free(stack);
    return ok;
}

static int read_classes(reader *R, const json_t *c, size_t ncomp, ag_rebuild_classes *k,
                        int32_t **label, int32_t **variant, uint8_t **rot, uint8_t **vrot,
                        int32_t **vlabel)
{
    json_int_t nl, nv;
    if (!json_is_object(c) ||
        !get_int(R, json_object_get(c, "nlabels"), 0, INT32_MAX, &nl, "the number of labels") ||
        !get_int(R, json_object_get(c, "nvariants"), 0, INT32_MAX, &nv,
                 "the number of variants") ||
        !get_real(R, json_object_get(c, "diagonal"), &k->diagonal, "the labels' diagonal") ||
        !get_real(R, json_object_get(c, "tol"), &k->tol, "the labels' tolerance") ||
        !get_real(R, json_object_get(c, "exact"), &k->exact, "the variants' tolerance"))
        return 0;
    k->ncomponents = ncomp;
    k->nlabels = (size_t)nl;
    k->nvariants = (size_t)nv;
    const json_t *la = get_array(R, c, "label", ncomp, "the components' labels");
    const json_t *va = get_array(R, c, "variant", ncomp, "the components' variants");
    const json_t *ra = get_array(R, c, "rot", ncomp, "the components' turns");
    const json_t *wa = get_array(R, c, "vrot", ncomp, "the components' variant turns");
    const json_t *vl = get_array(R, c, "variant_label", (size_t)nv, "the variants' labels");
    if (!la || !va || !ra || !wa || !vl)
        return 0;
    *label = malloc((ncomp + 1) * sizeof **label);
    *variant = malloc((ncomp + 1) * sizeof **variant);
    *rot = malloc(ncomp + 1);
    *vrot = malloc(ncomp + 1);
    *vlabel = malloc(((size_t)nv + 1) * sizeof **vlabel);
    if (!*label || !*variant || !*rot || !*vrot || !*vlabel) {
        R->st = ag_error_set(R->err, AG_ERR_NOMEM, 0, "out of memory");
        return 0;
    }
    json_int_t v;
    for (size_t i = 0; i < ncomp; i++) {
        if (!get_int(R, json_array_get(la, i), -1, nl - 1, &v, "a component's label"))
            return 0;
        (*label)[i] = (int32_t)v;
        if (!get_int(R, json_array_get(va, i), -1, nv - 1, &v, "a component's variant"))
            return 0;
        (*variant)[i] = (int32_t)v;
        if (!get_int(R, json_array_get(ra, i), 0, 3, &v, "a component's turn"))
            return 0;
        (*rot)[i] = (uint8_t)v;
        if (!get_int(R, json_array_get(wa, i), 0, 3, &v, "a component's variant turn"))
            return 0;
        (*vrot)[i] = (uint8_t)v;
    }
    for (size_t i = 0; i < (size_t)nv; i++) {
        if (!get_int(R, json_array_get(vl, i), -1, nl - 1, &v, "a variant's label"))
            return 0;
        (*vlabel)[i] = (int32_t)v;
    }
    k->label = *label;
    k->variant = *variant;
    k->rot = *rot;
    k->vrot = *vrot;
    k->variant_label = *vlabel;
    return 1;
}

static ag_splittree *read_tree(reader *R, const json_t *k, const ag_mesh *mesh, size_t nlabels,
                               size_t nvariants)
{
    json_int_t format, ncomp;
    if (!get_int(R, json_object_get(k, "format"), KEPT_FORMAT, KEPT_FORMAT, &format,
                 "an unknown format") ||
        !get_int(R, json_object_get(k, "ncomponents"), 0, INT32_MAX, &ncomp,
                 "the number of components"))
        return NULL;
    if ((size_t)ncomp != mesh->ncomponents) {
        bad(R, "it names another number of components than the mesh has");
        return NULL;
    }
    const json_t *nodes = get_array(R, k, "nodes", SIZE_MAX, "no nodes");
    const json_t *pats = get_array(R, k, "patterns", SIZE_MAX, "no patterns");
    const json_t *rules = get_array(R, k, "rules", SIZE_MAX, "no rules");
    if (!nodes || !pats || !rules)
        return NULL;
    if (json_array_size(nodes) > INT32_MAX || json_array_size(pats) > INT32_MAX ||
        json_array_size(rules) > INT32_MAX) {
        bad(R, "too many nodes");
        return NULL;
    }
    ag_splittree *t = calloc(1, sizeof *t);
    if (!t) {
        R->st = ag_error_set(R->err, AG_ERR_NOMEM, 0, "out of memory");
        return NULL;
    }
    t->nnodes = t->cap = json_array_size(nodes);
    t->npatterns = t->cap_patterns = json_array_size(pats);
    t->nrules = json_array_size(rules);
    t->ncomponents = (size_t)ncomp;
    t->nodes = malloc((t->nnodes + 1) * sizeof *t->nodes);
    t->patterns = malloc((t->npatterns + 1) * sizeof *t->patterns);
    t->rule_count = malloc((t->nrules + 1) * sizeof *t->rule_count);
    t->rule_rep = malloc((t->nrules + 1) * sizeof *t->rule_rep);
    if (!t->nodes || !t->patterns || !t->rule_count || !t->rule_rep) {
        R->st = ag_error_set(R->err, AG_ERR_NOMEM, 0, "out of memory");
        ag_splittree_free(t);
        return NULL;
    }
    int ok = get_real(R, json_object_get(k, "tol"), &t->tol, "the tree's tolerance") &&
             get_real(R, json_object_get(k, "eps"), &t->eps, "the tree's coincidence");
    for (size_t r = 0; ok && r < t->nrules; r++) {
        const json_t *a = json_array_get(rules, r);
        json_int_t c, rep;
        ok = json_is_array(a) && json_array_size(a) == 2 ? 1 : bad(R, "a rule is not a pair");
        ok = ok && get_int(R, json_array_get(a, 0), 0, UINT32_MAX, &c, "a rule's count") &&
             get_int(R, json_array_get(a, 1), -1, (json_int_t)t->nnodes - 1, &rep,
                     "a rule's representative");
        if (ok) {
            t->rule_count[r] = (uint32_t)c;
            t->rule_rep[r] = (int32_t)rep;
        }
    }
    for (size_t p = 0; ok && p < t->npatterns; p++)
        ok = read_pattern(R, json_array_get(pats, p), t, &t->patterns[p]);
    for (size_t n = 0; ok && n < t->nnodes; n++)
        ok = read_node(R, json_array_get(nodes, n), t, nlabels, nvariants, &t->nodes[n]);
    if (ok)
        ok = check_links(R, t);
    if (!ok) {
        ag_splittree_free(t);
        return NULL;
    }
    return t;
}

ag_status ag_model_kept_reload(const ag_mesh *mesh, const char *tree_text, ag_edit_model **em,
                               ag_error *err)
{
    *em = NULL;
    json_error_t je;
    json_t *doc = json_loads(tree_text, 0, &je);
    if (!doc)
        return ag_error_set(err, AG_ERR_PARSE, 0, "the stored tree is not JSON: %s", je.text);
    const json_t *k = json_object_get(doc, "kept");
    if (!json_is_object(k)) {
        json_decref(doc);
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "the stored tree keeps no model");
    }
    reader R = {.err = err};
    ag_rebuild_classes classes = {0};
    int32_t *label = NULL, *variant = NULL, *vlabel = NULL;
    uint8_t *rot = NULL, *vrot = NULL;
    ag_splittree *t = NULL;
    if (read_classes(&R, json_object_get(k, "classes"), mesh->ncomponents, &classes, &label,
                     &variant, &rot, &vrot, &vlabel))
        t = read_tree(&R, k, mesh, classes.nlabels, classes.nvariants);
    json_decref(doc);
    ag_status st = R.st;
    ag_mesh *m = NULL;
    if (!st && !(m = ag_mesh_clone(mesh)))
        st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_proceduralize_result *r = NULL;
    if (!st) {
        st = ag_rebuild_finish(m, t, &classes, &r, err); /* takes m and t */
        m = NULL;
        t = NULL;
    }
    ag_proceduralize_options opt = {.segment.keep_groups = 1}; /* as ag_edit_model_create */
    if (!st && (st = ag_edit_model_wrap(r, &opt, em, err)))
        ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    ag_splittree_free(t);
    free(label);
    free(variant);
    free(rot);
    free(vrot);
    free(vlabel);
    return st;
}
