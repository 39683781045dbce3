#include "points_summary.h"

#include <stdio.h>

#include "../core/points/proceduralize_cloud.h"
#include "../core/proc/splittree.h"
#include "../io/edit_op_json.h"
#include "folder_ws.h"

static json_t *vec3(const double *v)
{
    json_t *a = json_array();
    for (int i = 0; i < 3; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *box_json(const ag_box *b, const double offset[3])
{
    json_t *a = json_array();
    for (int c = 0; c < 6; c++)
        json_array_append_new(a, json_real(ag_box_coord(b, c) + offset[c % 3]));
    return a;
}

/* The tree's boxes in the input's coordinates (the model keeps them local to its offset), as
 * edit ops give them. */
void ag_points_summary_shift_tree(json_t *tree, const double offset[3])
{
    json_t *nodes = json_object_get(tree, "nodes"), *node;
    size_t i;
    json_array_foreach(nodes, i, node) {
        json_t *box = json_object_get(node, "box");
        for (size_t c = 0; c < json_array_size(box) && c < 6; c++) {
            json_t *v = json_array_get(box, c);
            json_real_set(v, json_number_value(v) + offset[c % 3]);
        }
    }
}

/* The tree and grammar of the saved model, shared by both summaries. */
static void model_summary(json_t *j, const ag_points_state *st)
{
    const ag_pointmodel *pm = st->pm;
    const ag_proceduralize_result *r = pm->em->proc;
    json_object_set_new(j, "tree", ag__folder_ws_tree_figures(r->tree));
    json_object_set_new(j, "terminals", json_integer((json_int_t)pm->nterminals));
    json_object_set_new(j, "placements", json_integer((json_int_t)pm->nplacements));
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    ag__folder_ws_model_figures(j, r, st->text_len, st->terms.bytes);
    json_object_set_new(j, "spacing", json_real(pm->spacing));
}

json_t *ag_points_summary_proc(const ag_points_state *st, const ag_points_outcome *o,
                               const ag_points_summary_input *in)
{
    const ag_proceduralize_cloud_result *r = o->proc;
    const ag_segment_cloud_result *sg = r->seg;
    const ag_cloud *c = o->input;
    json_t *j = json_object();
    json_object_set_new(j, "kind", json_string("pointcloud"));
    json_t *ji = json_object();
    if (in && in->file) {
        json_object_set_new(ji, "file", json_string(in->file));
        json_object_set_new(ji, "bytes", json_integer((json_int_t)in->bytes));
    }
    json_object_set_new(ji, "points", json_integer((json_int_t)c->n));
    json_object_set_new(ji, "offset", vec3(c->offset));
    json_t *props = json_array();
    for (size_t p = 0; p < c->nprops; p++)
        json_array_append_new(props, json_string(c->props[p].name));
    json_object_set_new(ji, "properties", props);
    json_object_set_new(ji, "normals", json_boolean(c->normals != NULL));
    json_object_set_new(j, "input", ji);

    json_t *sec = json_object(), *cpu = json_object(), *segs = json_object();
    json_object_set_new(sec, "read", json_real(in ? in->read_s : 0));
    for (int s = 0; s < AG_PCLOUD_STAGES; s++) {
        json_object_set_new(sec, ag_proceduralize_cloud_stage_name(s), json_real(r->seconds[s]));
        json_object_set_new(cpu, ag_proceduralize_cloud_stage_name(s),
                            json_real(r->cpu_seconds[s]));
    }
    for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
        json_object_set_new(segs, ag_segment_cloud_stage_name(s), json_real(sg->seconds[s]));
    json_object_set_new(sec, "verify", json_real(o->verify_s));
    json_object_set_new(sec, "write", json_real(in ? in->write_s : 0));
    json_object_set_new(sec, "total", json_real(o->total_s));
    json_object_set_new(j, "seconds", sec);
    json_object_set_new(j, "cpu_seconds", cpu);
    json_object_set_new(j, "segment_seconds", segs);

    json_t *js = json_object();
    json_object_set_new(js, "segments", json_integer((json_int_t)ag_segment_cloud_in_use(sg)));
    json_object_set_new(js, "planes", json_integer((json_int_t)sg->nplanes));
    json_object_set_new(js, "clusters", json_integer((json_int_t)sg->nclusters));
    json_object_set_new(js, "elements", json_integer((json_int_t)sg->nelements));
    json_object_set_new(js, "labels", json_integer((json_int_t)sg->nlabels));
    json_object_set_new(js, "pieces", json_integer((json_int_t)sg->npieces));
    json_object_set_new(js, "diagonal", json_real(sg->diagonal));
    json_object_set_new(js, "spacing", json_real(sg->spacing));
    json_object_set_new(js, "coarse_threshold", json_real(sg->coarse_threshold));
    json_object_set_new(js, "fine_threshold", json_real(sg->fine_threshold));
    json_object_set_new(js, "cluster_tolerance", json_real(sg->cluster_tolerance));
    json_object_set_new(js, "absorbed", json_integer((json_int_t)r->absorbed));
    json_object_set_new(js, "outliers", json_integer((json_int_t)r->outliers));
    json_object_set_new(j, "segmentation", js);

    json_t *jr = json_object(), *jtm = json_array();
    for (size_t k = 0; k < r->ntemplates; k++) {
        const ag_repeat_report *t = &r->templates[k];
        json_t *to = json_object(), *mb = json_array();
        json_object_set_new(to, "matches", json_integer((json_int_t)t->nmatches));
        json_object_set_new(to, "positions", json_integer((json_int_t)t->positions));
        for (size_t m = 0; m < t->nmatches; m++) {
            json_t *mo = json_object();
            json_object_set_new(mo, "box", box_json(&t->matches[m].box, c->offset));
            json_object_set_new(mo, "explained", json_real(t->matches[m].explained));
            json_object_set_new(mo, "covered", json_real(t->matches[m].covered));
            json_object_set_new(mo, "points", json_integer((json_int_t)t->matches[m].points));
            json_array_append_new(mb, mo);
        }
        json_object_set_new(to, "found", mb);
        json_array_append_new(jtm, to);
    }
    json_object_set_new(jr, "templates", jtm);
    json_object_set_new(jr, "auto_elements", json_integer((json_int_t)r->auto_elements));
    json_object_set_new(j, "repetition", jr);

    json_t *jc = json_array();
    for (size_t k = 0; k < r->ncompletion; k++) {
        const ag_pcloud_completion *q = &r->completion[k];
        json_t *co = json_object();
        char name[32];
        snprintf(name, sizeof name, "L%d", (int)q->terminal + 1);
        json_object_set_new(co, "label", json_string(name));
        json_object_set_new(co, "members", json_integer((json_int_t)q->members));
        json_object_set_new(co, "merged", json_integer((json_int_t)q->merged));
        json_object_set_new(co, "points_before", json_integer((json_int_t)q->points_before));
        json_object_set_new(co, "mean_points_before", json_real(q->mean_before));
        json_object_set_new(co, "points_after", json_integer((json_int_t)q->points_after));
        json_object_set_new(co, "completion",
                            json_real(q->points_before ? (double)q->points_after /
                                                             (double)q->points_before
                                                       : 0));
        json_array_append_new(jc, co);
    }
    json_object_set_new(j, "completion", jc);
    model_summary(j, st);
    json_t *jf = json_object();
    json_object_set_new(jf, "coverage", json_real(o->fidelity.coverage));
    json_object_set_new(jf, "precision", json_real(o->fidelity.precision));
    json_object_set_new(jf, "tolerance", json_real(o->fidelity.tolerance));
    json_object_set_new(jf, "derived_points", json_integer((json_int_t)o->derived_points));
    json_object_set_new(j, "fidelity", jf);
    return j;
}

json_t *ag_points_summary_edit(const ag_points_state *st, const ag_edit_outcome *o)
{
    json_t *j = ag_edit_op_json_report(&o->report);
    if (!j)
        return NULL;
    json_object_set_new(j, "kind", json_string("pointcloud"));
    if (o->op)
        json_object_set_new(j, "op", ag_edit_op_json_to_ex(o->op, o->from));
    json_object_set_new(j, "load_ms", json_real(o->load_ms));
    json_object_set_new(j, "edit_ms", json_real(o->edit_ms));
    model_summary(j, st);
    return j;
}

