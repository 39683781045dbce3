#include "edit_tree_json.h"

#include <stdio.h>

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

json_t *ag_edit_tree_json_stats(const ag_proceduralize_result *r)
{
    ag_splittree_stats st = ag_splittree_stats_of(r->tree);
    return json_pack("{s:I,s:I,s:I,s:I,s:I,s:I}", "nodes", (json_int_t)st.nodes, "visible",
                     (json_int_t)st.visible, "invisible", (json_int_t)st.invisible, "depth",
                     (json_int_t)st.depth, "patterns", (json_int_t)r->tree->npatterns, "rules",
                     (json_int_t)r->tree->nrules);
}

json_t *ag_edit_tree_json(const ag_proceduralize_result *r)
{
    const ag_splittree *t = r->tree;
    json_t *o = json_object(), *nodes = json_array();
    if (!o || !nodes)
        goto fail;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_tnode *x = &t->nodes[n];
        if (x->kind == AG_NODE_DEAD)
            continue;
        json_t *j = json_object(), *box = json_array(), *ch = json_array();
        if (!j || !box || !ch) {
            json_decref(j);
            json_decref(box);
            json_decref(ch);
            goto fail;
        }
        for (int a = 0; a < 3; a++)
            json_array_append_new(box, json_real(x->box.min[a]));
        for (int a = 0; a < 3; a++)
            json_array_append_new(box, json_real(x->box.max[a]));
        for (int32_t c = x->first_child; c >= 0; c = t->nodes[c].next_sibling)
            json_array_append_new(ch, json_integer(c));
        json_object_set_new(j, "id", json_integer((json_int_t)n));
        json_object_set_new(j, "parent", x->parent >= 0 ? json_integer(x->parent) : json_null());
        json_object_set_new(j, "kind", json_string(kind_name(x->kind)));
        json_object_set_new(j, "box", box);
        json_object_set_new(j, "children", ch);
        if (x->kind == AG_NODE_COMPONENT) {
            char name[32];
            snprintf(name, sizeof name, "L%d", x->label + 1);
            json_object_set_new(j, "label", x->label >= 0 ? json_string(name) : json_null());
            json_object_set_new(j, "component", json_integer(x->component));
            json_object_set_new(j, "rule", x->rule >= 0 ? json_integer(x->rule) : json_null());
        }
        if (x->kind == AG_NODE_PATTERN && x->pattern >= 0 && (size_t)x->pattern < t->npatterns) {
            const ag_pattern *p = &t->patterns[x->pattern];
            json_object_set_new(j, "counts", json_pack("[I,I,I]", (json_int_t)p->counts[0],
                                                       (json_int_t)p->counts[1],
                                                       (json_int_t)p->counts[2]));
        }
        json_array_append_new(nodes, j);
    }
    json_object_set_new(o, "root", json_integer(0));
    json_object_set_new(o, "nodes", nodes);
    json_object_set_new(o, "stats", ag_edit_tree_json_stats(r));
    return o;
fail:
    json_decref(o);
    json_decref(nodes);
    return NULL;
}
