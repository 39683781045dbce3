#include "points_folder_ws.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../core/base/clock.h"
#include "../core/points/proceduralize_cloud.h"
#include "../core/proc/splittree.h"
#include "../io/cloud_import.h"
#include "../io/edit_op_json.h"
#include "../io/filemap.h"
#include "folder_ws.h"
#include "model_tree.h"
#include "points_state.h"

static void blame(ag_points_folder_ws *w, const char *file)
{
    snprintf(w->blame, sizeof w->blame, "%s", file ? file : "");
    w->blamed = 1;
}

/* ---- reading ------------------------------------------------------------------------------ */

static ag_status read_text(const char *path, char **text, size_t *len, ag_error *err)
{
    ag_filemap fm;
    ag_status st = ag_filemap_open(path, &fm, err);
    if (st != AG_OK)
        return st;
    *text = malloc(fm.len + 1);
    if (!*text) {
        ag_filemap_close(&fm);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    memcpy(*text, fm.data, fm.len);
    (*text)[fm.len] = 0;
    *len = fm.len;
    ag_filemap_close(&fm);
    return AG_OK;
}

/* Terminal files below a folder (paths checked by the point terminal reader's rule). */
static ag_status dir_lookup(void *user, const char *path, char **data, size_t *len,
                            ag_error *err)
{
    const char *dir = user;
    if (!ag_terminals_path_is_safe(path))
        return ag_error_set(err, AG_ERR_INVALID, 0, "terminal path '%s' is unsafe or empty",
                            path);
    char full[4200];
    snprintf(full, sizeof full, "%s/%s", dir, path);
    ag_error e = {0};
    ag_status st = read_text(full, data, len, &e);
    if (st != AG_OK)
        return ag_error_set(err, st, 0, "terminal file %s: %s", path, e.text);
    return AG_OK;
}

ag_status ag_points_folder_read_grammar(const char *grammar_path, ag_pointmodel **out,
                                        ag_error *err, long *col)
{
    *out = NULL;
    char *text = NULL;
    size_t len = 0;
    ag_status st = read_text(grammar_path, &text, &len, err);
    if (st != AG_OK)
        return st;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", grammar_path);
    char *slash = strrchr(dir, '/');
    if (slash)
        *slash = 0;
    else
        snprintf(dir, sizeof dir, ".");
    st = ag_points_state_read(text, len, dir_lookup, dir, out, err, col);
    free(text);
    return st;
}

int ag_points_grammar_file_is_points(const char *grammar_path)
{
    /* a cheap look at the declarations: a terminal naming a .ply file */
    FILE *f = fopen(grammar_path, "r");
    if (!f)
        return 0;
    char line[4096];
    int points = 0;
    while (fgets(line, sizeof line, f)) {
        const char *s = line;
        while (*s == ' ' || *s == '\t')
            s++;
        if (strncmp(s, "terminal", 8) || (s[8] != ' ' && s[8] != '\t'))
            continue;
        const char *q = strchr(s, '"'), *e = q ? strchr(q + 1, '"') : NULL;
        points = e && e - q > 4 && !strncasecmp(e - 4, ".ply", 4);
        break;
    }
    fclose(f);
    return points;
}

int ag_points_folder_is_point_model(const char *dir)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    return ag_points_grammar_file_is_points(path);
}

/* The cloud file, with every property (a folder keeps no segmentation of it). */
static ag_status input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                             ag_cloud_state *cs, ag_error *err)
{
    (void)with_properties;
    ag_points_folder_ws *w = (ag_points_folder_ws *)ws;
    blame(w, w->o.cloud_path);
    if (need_segmentation)
        return ag_error_set(err, AG_ERR_CONFLICT, 0, "a cloud file has no segmentation to use");
    double t0 = ag_clock_seconds();
    struct stat sb;
    w->input_bytes = stat(w->o.cloud_path, &sb) ? 0 : (size_t)sb.st_size;
    ag_status st = ag_cloud_import_file(w->o.cloud_path, &cs->cloud, err);
    w->read_s = ag_clock_seconds() - t0;
    if (st == AG_OK)
        cs->had_normals = cs->cloud->normals != NULL;
    return st;
}

static ag_status read_folder(ag_points_folder_ws *w, const char *dir, ag_pointmodel **pm,
                             ag_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    blame(w, path);
    long col = 0;
    ag_status st = ag_points_folder_read_grammar(path, pm, err, &col);
    if (st == AG_ERR_PARSE && col)
        ag_error_set(err, st, err->element, "%ld: %.200s", col, err->text);
    return st;
}

static ag_status open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                   ag_pointmodel **pm, const ag_pointmodel **source,
                                   ag_error *err)
{
    ag_points_folder_ws *w = (ag_points_folder_ws *)ws;
    ag_status st = read_folder(w, w->o.in_dir, &w->pm, err);
    if (st != AG_OK)
        return st;
    if (from && from->model) {
        blame(w, w->o.op_path);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "source_model: names a model of the service; an op file names the "
                            "folder to paste from with source_dir");
    }
    if (from && from->dir) {
        char dir[4096];
        const char *oppath = w->o.op_path ? w->o.op_path : "";
        const char *slash = strrchr(oppath, '/');
        if (from->dir[0] == '/' || !slash)
            snprintf(dir, sizeof dir, "%s", from->dir);
        else
            snprintf(dir, sizeof dir, "%.*s/%s", (int)(slash - oppath), oppath, from->dir);
        blame(w, oppath);
        struct stat sb;
        if (stat(dir, &sb) || !S_ISDIR(sb.st_mode))
            return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "source_dir: %s is not a folder", dir);
        if (!ag_points_folder_is_point_model(dir))
            return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                                "source_dir: %s holds no point model (run `archgram "
                                "proceduralize CLOUD --out %s`)",
                                dir, dir);
        if ((st = read_folder(w, dir, &w->source, err)) != AG_OK)
            return st;
    }
    *pm = w->pm;
    *source = w->source;
    w->blamed = 0; /* from here on, problems are the op's or the model's */
    return AG_OK;
}

/* ---- writing ------------------------------------------------------------------------------ */

static ag_status write_file(ag_points_folder_ws *w, const char *path, const char *data,
                            size_t len, ag_error *err)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, len, f) == len;
    int e = errno;
    if (f && fclose(f))
        ok = 0, e = errno;
    if (ok)
        return AG_OK;
    blame(w, NULL);
    return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(e));
}

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
static void shift_tree_boxes(json_t *tree, const double offset[3])
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
    ag_splittree_stats ts = ag_splittree_stats_of(r->tree);
    json_t *jt = json_object();
    json_object_set_new(jt, "nodes", json_integer((json_int_t)ts.nodes));
    json_object_set_new(jt, "visible", json_integer((json_int_t)ts.visible));
    json_object_set_new(jt, "invisible", json_integer((json_int_t)ts.invisible));
    json_object_set_new(jt, "depth", json_integer((json_int_t)ts.depth));
    json_object_set_new(jt, "adjacent_pairs", json_integer((json_int_t)r->tree->nadj));
    json_object_set_new(j, "tree", jt);
    json_object_set_new(j, "terminals", json_integer((json_int_t)pm->nterminals));
    json_object_set_new(j, "placements", json_integer((json_int_t)pm->nplacements));
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    json_t *jp = json_array();
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        json_t *po = json_object(), *cnt = json_array();
        for (int a = 0; a < 3; a++)
            json_array_append_new(cnt, json_integer(pt->counts[a]));
        json_object_set_new(po, "counts", cnt);
        json_object_set_new(po, "kind", json_string(pt->nvec ? "repeat" : "subdivide"));
        json_object_set_new(po, "step", vec3(pt->step));
        json_object_set_new(po, "instances",
                            json_integer((json_int_t)pt->counts[0] * pt->counts[1] * pt->counts[2]));
        json_array_append_new(jp, po);
    }
    json_object_set_new(j, "patterns", jp);
    json_object_set_new(j, "grammar_bytes", json_integer((json_int_t)st->text_len));
    json_object_set_new(j, "terminal_bytes", json_integer((json_int_t)st->terms.bytes));
    json_object_set_new(j, "spacing", json_real(pm->spacing));
}

static json_t *proc_summary(const ag_points_folder_ws *w, const ag_points_state *st,
                            const ag_points_outcome *o, double write_s)
{
    const ag_proceduralize_cloud_result *r = o->proc;
    const ag_segment_cloud_result *sg = r->seg;
    const ag_cloud *c = o->input;
    json_t *j = json_object();
    json_object_set_new(j, "kind", json_string("pointcloud"));
    json_t *ji = json_object();
    json_object_set_new(ji, "file", json_string(w->o.cloud_path));
    json_object_set_new(ji, "bytes", json_integer((json_int_t)w->input_bytes));
    json_object_set_new(ji, "points", json_integer((json_int_t)c->n));
    json_object_set_new(ji, "offset", vec3(c->offset));
    json_t *props = json_array();
    for (size_t p = 0; p < c->nprops; p++)
        json_array_append_new(props, json_string(c->props[p].name));
    json_object_set_new(ji, "properties", props);
    json_object_set_new(ji, "normals", json_boolean(c->normals != NULL));
    json_object_set_new(j, "input", ji);

    json_t *sec = json_object(), *cpu = json_object(), *segs = json_object();
    json_object_set_new(sec, "read", json_real(w->read_s));
    for (int s = 0; s < AG_PCLOUD_STAGES; s++) {
        json_object_set_new(sec, ag_proceduralize_cloud_stage_name(s), json_real(r->seconds[s]));
        json_object_set_new(cpu, ag_proceduralize_cloud_stage_name(s),
                            json_real(r->cpu_seconds[s]));
    }
    for (int s = 0; s < AG_SEGMENT_CLOUD_STAGES; s++)
        json_object_set_new(segs, ag_segment_cloud_stage_name(s), json_real(sg->seconds[s]));
    json_object_set_new(sec, "verify", json_real(o->verify_s));
    json_object_set_new(sec, "write", json_real(write_s));
    json_object_set_new(sec, "total", json_real(o->total_s));
    json_object_set_new(j, "seconds", sec);
    json_object_set_new(j, "cpu_seconds", cpu);
    json_object_set_new(j, "segment_seconds", segs);

    json_t *js = json_object();
    json_object_set_new(js, "segments", json_integer((json_int_t)sg->nsegments));
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

static json_t *edit_summary(const ag_points_state *st, const ag_edit_outcome *o)
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

static ag_status save_points(ag_workspace *ws, ag_points_state *st, const ag_points_outcome *proc,
                             const ag_edit_outcome *edit, ag_error *err)
{
    ag_points_folder_ws *w = (ag_points_folder_ws *)ws;
    double t0 = ag_clock_seconds();
    const char *dir = w->o.out_dir;
    char path[4200];
    ag_status s = AG_OK;
    if (ag_folder_ws_make_dirs(dir)) {
        blame(w, NULL);
        s = ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", dir, strerror(errno));
        goto done;
    }
    snprintf(path, sizeof path, "%s/terminals", dir);
    if (st->terms.n && ag_folder_ws_make_dirs(path)) {
        blame(w, NULL);
        s = ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
        goto done;
    }
    for (size_t i = 0; s == AG_OK && i < st->terms.n; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, st->terms.path[i]);
        s = write_file(w, path, st->terms.obj[i], st->terms.len[i], err);
    }
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    if (s == AG_OK)
        s = write_file(w, path, st->text, st->text_len, err);
    if (s == AG_OK) {
        json_t *tree = ag_model_tree_folder(st->pm->em);
        if (tree)
            shift_tree_boxes(tree, st->pm->offset);
        snprintf(path, sizeof path, "%s/tree.json", dir);
        if (!tree || json_dump_file(tree, path, JSON_INDENT(1) | JSON_REAL_PRECISION(12))) {
            blame(w, NULL);
            s = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s", path);
        }
        json_decref(tree);
    }
    if (s == AG_OK) {
        json_t *j = proc ? proc_summary(w, st, proc, ag_clock_seconds() - t0)
                         : edit_summary(st, edit);
        snprintf(path, sizeof path, "%s/summary.json", dir);
        if (!j || json_dump_file(j, path,
                                 JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6))) {
            blame(w, NULL);
            s = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s", path);
        }
        json_decref(j);
    }
done:
    ag_points_state_clear(st);
    return s;
}

static void ws_close(ag_workspace *ws)
{
    ag_points_folder_ws *w = (ag_points_folder_ws *)ws;
    ag_pointmodel_free(w->pm);
    ag_pointmodel_free(w->source);
    w->pm = w->source = NULL;
}

static const ag_workspace_ops points_folder_ops = {
    .input_cloud = input_cloud,
    .open_point_models = open_point_models,
    .save_points = save_points,
    .close = ws_close,
};

void ag_points_folder_ws_init(ag_points_folder_ws *w, const ag_points_folder_ws_options *o)
{
    memset(w, 0, sizeof *w);
    w->ws.ops = &points_folder_ops;
    w->o = *o;
}
