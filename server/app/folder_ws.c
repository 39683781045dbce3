#include "folder_ws.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "../core/base/array.h"
#include "../io/grammar_text.h"
#include "../io/numtext.h"
#include "../io/import.h"
#include "../io/part_bundle.h"
#include "usecase_compose.h"
#include "model_tree.h"
#include "threads.h"
#include "usecase_import.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

void ag__folder_ws_blame(ag_folder_ws *w, const char *file)
{
    snprintf(w->blame, sizeof w->blame, "%s", file ? file : "");
    w->blamed = 1;
}

int ag_folder_ws_make_dirs(const char *dir)
{
    char p[4096];
    snprintf(p, sizeof p, "%s", dir);
    for (char *s = p + 1; *s; s++)
        if (*s == '/') {
            *s = 0;
            if (mkdir(p, 0777) && errno != EEXIST)
                return -1;
            *s = '/';
        }
    return mkdir(p, 0777) && errno != EEXIST ? -1 : 0;
}

ag_status ag__folder_ws_write_file(ag_folder_ws *w, const char *path, const char *data,
                                   size_t len, ag_error *err)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, len, f) == len;
    int e = errno;
    if (f && fclose(f))
        ok = 0, e = errno;
    if (ok)
        return AG_OK;
    ag__folder_ws_blame(w, NULL);
    return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s: %s", path, strerror(e));
}

ag_status ag__folder_ws_write_json(ag_folder_ws *w, const char *path, json_t *j, size_t flags,
                                   ag_error *err)
{
    if (j && json_dump_file(j, path, flags) == 0)
        return AG_OK;
    ag__folder_ws_blame(w, NULL);
    return ag_error_set(err, AG_ERR_IO, 0, "cannot write %s", path);
}

/* --- reading --------------------------------------------------------------------------- */

static ag_status input_mesh(ag_workspace *ws, ag_mesh **mesh, ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    double t0 = now();
    ag_mesh_source src = {.path = w->o.mesh_path, .up = w->o.up, .own_file = 1};
    ag_mesh_file file;
    ag__folder_ws_blame(w, w->o.mesh_path);
    ag_status s = ag_usecase_import_read(&src, NULL, NULL, mesh, &file, err);
    w->input_bytes = file.len;
    w->up = file.up;
    ag_usecase_import_release(&file);
    w->import_s = now() - t0;
    return s;
}

/* A proceduralized folder read as its grammar derived and proceduralized anew. */
static ag_status read_folder(ag_folder_ws *w, const char *dir, ag_edit_model **em, ag_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    ag__folder_ws_blame(w, path);
    ag_grammar *g = NULL;
    ag_mesh *d = NULL;
    long col = 0;
    ag_status s = ag_grammar_text_read_file(path, &g, err, &col);
    if (s == AG_OK && (s = ag_terminals_load(g, dir, err)) == AG_OK &&
        (s = ag_grammar_derive(g, NULL, &d, err)) == AG_OK)
        s = ag_model_state_reload(d, em, err);
    ag_mesh_free(d);
    ag_grammar_free(g);
    return s;
}

ag_status ag__folder_ws_source_dir(ag_folder_ws *w, const char *sdir, char *dir, size_t cap,
                                   ag_error *err)
{
    const char *oppath = w->o.op_path ? w->o.op_path : "";
    const char *slash = strrchr(oppath, '/');
    if (sdir[0] == '/' || !slash)
        snprintf(dir, cap, "%s", sdir);
    else
        snprintf(dir, cap, "%.*s/%s", (int)(slash - oppath), oppath, sdir);
    ag__folder_ws_blame(w, oppath);
    struct stat sb;
    if (stat(dir, &sb) || !S_ISDIR(sb.st_mode))
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "source_dir: %s is not a folder", dir);
    return AG_OK;
}

ag_status ag__folder_ws_check_origin(ag_folder_ws *w, const ag_edit_op_origin *from,
                                     ag_error *err)
{
    if (!from || !from->model)
        return AG_OK;
    ag__folder_ws_blame(w, w->o.op_path);
    return ag_error_set(err, AG_ERR_INVALID, 0,
                        "source_model: names a model of the service; an op file names the "
                        "folder to paste from with source_dir");
}

/* The folder a paste copies from ("source_dir", relative to the op file's folder). */
static ag_status read_source(ag_folder_ws *w, const char *sdir, ag_error *err)
{
    char dir[4096], path[4200];
    ag_status s = ag__folder_ws_source_dir(w, sdir, dir, sizeof dir, err);
    if (s != AG_OK)
        return s;
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    if (access(path, R_OK))
        return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                            "source_dir: %s is not proceduralized (no grammar.txt; run `archgram "
                            "proceduralize MESH --out %s`)",
                            dir, dir);
    return read_folder(w, dir, &w->source, err);
}

static ag_status open_models(ag_workspace *ws, const ag_edit_op_origin *from, ag_edit_model **em,
                             const ag_edit_model **source, int64_t *source_version, ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    (void)source_version;
    ag_status s = read_folder(w, w->o.in_dir, &w->em, err);
    if (s == AG_OK)
        s = ag__folder_ws_check_origin(w, from, err);
    if (s != AG_OK)
        return s;
    if (from && from->dir && (s = read_source(w, from->dir, err)) != AG_OK)
        return s;
    *em = w->em;
    *source = w->source;
    /* problems from here on are the op's (a field) or the model's */
    w->blamed = 0;
    return AG_OK;
}

/* --- writing --------------------------------------------------------------------------- */

ag_status ag__folder_ws_make_out(ag_folder_ws *w, int terminals, ag_error *err)
{
    const char *dir = w->o.out_dir;
    char path[4200];
    if (ag_folder_ws_make_dirs(dir)) {
        ag__folder_ws_blame(w, NULL);
        return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", dir, strerror(errno));
    }
    if (terminals) {
        snprintf(path, sizeof path, "%s/terminals", dir);
        if (ag_folder_ws_make_dirs(path)) {
            ag__folder_ws_blame(w, dir);
            return ag_error_set(err, AG_ERR_IO, 0, "cannot create %s: %s", path, strerror(errno));
        }
    }
    return AG_OK;
}

static json_t *vec3(const double *v);

/* The patterns of a proceduralized model and the bytes of its save, the tail of the mesh
 * and point model summaries. */
void ag__folder_ws_model_figures(json_t *j, const ag_proceduralize_result *r, size_t grammar_bytes,
                                 size_t terminal_bytes)
{
    json_t *jp = json_array();
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        int32_t ri = r->info.rule_of_class ? r->info.rule_of_class[pt->rule] : -1;
        json_t *po = json_object();
        json_object_set_new(po, "rule", ri >= 0 ? json_string(r->grammar->rules[ri].name) : json_null());
        json_t *cnt = json_array();
        for (int a = 0; a < 3; a++)
            json_array_append_new(cnt, json_integer(pt->counts[a]));
        json_object_set_new(po, "counts", cnt);
        json_object_set_new(po, "step", vec3(pt->step));
        json_object_set_new(po, "kind", json_string(pt->nvec ? "repeat" : "subdivide"));
        if (pt->nvec) {
            json_t *vs = json_array();
            for (int k = 0; k < pt->nvec; k++)
                json_array_append_new(vs, vec3(pt->vec[k]));
            json_object_set_new(po, "vectors", vs);
        }
        json_object_set_new(po, "rot", json_integer(90 * pt->rot));
        json_object_set_new(po, "instances",
                            json_integer((json_int_t)pt->counts[0] * pt->counts[1] * pt->counts[2]));
        json_array_append_new(jp, po);
    }
    json_object_set_new(j, "patterns", jp);
    json_object_set_new(j, "grammar_bytes", json_integer((json_int_t)grammar_bytes));
    json_object_set_new(j, "terminal_bytes", json_integer((json_int_t)terminal_bytes));
}

json_t *ag__folder_ws_tree_figures(const ag_splittree *t)
{
    ag_splittree_stats ts = ag_splittree_stats_of(t);
    return json_pack("{s:I, s:I, s:I, s:I, s:I}", "nodes", (json_int_t)ts.nodes, "visible",
                     (json_int_t)ts.visible, "invisible", (json_int_t)ts.invisible, "depth",
                     (json_int_t)ts.depth, "adjacent_pairs", (json_int_t)t->nadj);
}

ag_status ag__folder_ws_write_grammar(ag_folder_ws *w, const char *text, size_t len,
                                      const ag_terminal_set *terms, ag_error *err)
{
    const char *dir = w->o.out_dir;
    char path[4200];
    ag_status s = ag__folder_ws_make_out(w, terms->n != 0, err);
    for (size_t i = 0; s == AG_OK && i < terms->n; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, terms->path[i]);
        s = ag__folder_ws_write_file(w, path, terms->obj[i], terms->len[i], err);
    }
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    return s == AG_OK ? ag__folder_ws_write_file(w, path, text, len, err) : s;
}

/* tree.json's text, printed on a thread beside the rest of a save (it reads st only). */
typedef struct {
    const ag_model_state *st;
    char *text;
    ag_beside thread;
} tree_text;

static void *print_tree(void *arg)
{
    tree_text *t = arg;
    t->text = ag_model_tree_folder_text(t->st->em); /* the served tree's precision */
    return NULL;
}

static void tree_text_start(tree_text *t, const ag_model_state *st)
{
    t->st = st;
    t->text = NULL;
    ag_beside_start(&t->thread, print_tree, t);
}

/* grammar.txt, terminals/ and tree.json of st; tree, when given, is tree.json's text
 * printing beside (waited for and freed here). */
static ag_status write_model_with(ag_folder_ws *w, const ag_model_state *st, tree_text *beside,
                                  ag_error *err)
{
    const char *dir = w->o.out_dir;
    char path[4200];
    ag_status s = ag__folder_ws_write_grammar(w, st->text, st->text_len, &st->terms, err);
    snprintf(path, sizeof path, "%s/tree.json", dir);
    char *tree = NULL;
    if (beside) {
        ag_beside_join(&beside->thread);
        tree = beside->text;
    }
    if (s != AG_OK) {
        free(tree);
        return s;
    }
    if (!beside) /* the served tree's precision (model_tree.c), printed directly */
        tree = ag_model_tree_folder_text(st->em);
    if (!tree) {
        ag__folder_ws_blame(w, NULL);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing %s", path);
    }
    s = ag__folder_ws_write_file(w, path, tree, strlen(tree), err);
    free(tree);
    return s;
}

static ag_status write_model(ag_folder_ws *w, const ag_model_state *st, ag_error *err)
{
    return write_model_with(w, st, NULL, err);
}

static json_t *vec3(const double *v)
{
    json_t *a = json_array();
    for (int i = 0; i < 3; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

/* summary.json's "components" list (one object per component) is printed directly and
 * spliced into jansson's dump of the rest at a marker: through jansson objects it took a
 * sixth of `archgram proceduralize` on a 2M-triangle block. The text is what jansson prints
 * with JSON_INDENT(2) (test_folder_summary compares the two). */
#define COMPONENTS_MARK "\x01" "components" "\x01"
static const char components_at[] = "\n  \"components\": \"\\u0001components\\u0001\"";

typedef struct {
    char *p;
    size_t n, cap;
    int fail;
} text_buf;

static void put(text_buf *b, const char *s, size_t n)
{
    if (b->fail || (b->fail = AG_ARRAY_RESERVE_MORE(b->p, b->cap, b->n, n + 1) != AG_OK))
        return;
    memcpy(b->p + b->n, s, n);
    b->n += n;
    b->p[b->n] = '\0';
}

#define PUT_LIT(b, lit) put(b, lit, sizeof lit - 1)

static void put_key_int(text_buf *b, const char *key_line, size_t key_len, int64_t v)
{
    put(b, key_line, key_len);
    if (v < 0) {
        PUT_LIT(b, "null");
        return;
    }
    char d[AG_NUMTEXT_MAX];
    put(b, d, ag_numtext_u64(d, (uint64_t)v));
}
#define PUT_KEY_INT(b, key_line, v) put_key_int(b, key_line, sizeof key_line - 1, v)

static char *components_text(const ag_proceduralize_result *r)
{
    const ag_labels *L = r->labels;
    const ag_mesh *m = r->mesh;
    text_buf b = {0};
    if (!m->ncomponents) {
        PUT_LIT(&b, "[]");
        return b.fail ? (free(b.p), NULL) : b.p;
    }
    for (size_t c = 0; c < m->ncomponents && !b.fail; c++) {
        if (c)
            PUT_LIT(&b, ",\n    {");
        else
            PUT_LIT(&b, "[\n    {");
        PUT_KEY_INT(&b, "\n      \"index\": ", (int64_t)c);
        int32_t g = m->component_group[c];
        const char *name = g >= 0 ? m->group_names[g] : NULL;
        size_t len = 0;
        while (name && name[len] >= 0x20 && name[len] < 0x7f && name[len] != '"' &&
               name[len] != '\\')
            len++;
        if (!name) {
            PUT_LIT(&b, ",\n      \"group\": null");
        } else if (!name[len]) { /* plain ASCII: as it is */
            PUT_LIT(&b, ",\n      \"group\": \"");
            put(&b, name, len);
            PUT_LIT(&b, "\"");
        } else { /* escaped as jansson escapes it; a name it refuses (not UTF-8) has no key */
            json_t *js = json_string(name);
            char *e = js ? json_dumps(js, JSON_ENCODE_ANY) : NULL;
            if (js && !e)
                b.fail = 1;
            if (e) {
                PUT_LIT(&b, ",\n      \"group\": ");
                put(&b, e, strlen(e));
            }
            free(e);
            json_decref(js);
        }
        PUT_KEY_INT(&b, ",\n      \"label\": ", L->label[c]);
        PUT_KEY_INT(&b, ",\n      \"variant\": ", L->variant[c]);
        PUT_KEY_INT(&b, ",\n      \"rot\": ", 90 * (int64_t)L->rot[c]);
        if (L->mirror[c])
            PUT_LIT(&b, ",\n      \"mirror\": true");
        else
            PUT_LIT(&b, ",\n      \"mirror\": false");
        PUT_KEY_INT(&b, ",\n      \"node\": ", r->tree->comp_node[c]);
        PUT_LIT(&b, "\n    }");
    }
    PUT_LIT(&b, "\n  ]");
    if (b.fail) {
        free(b.p);
        return NULL;
    }
    return b.p;
}

/* The proceduralize summary: jansson's dump with the components list put in at its marker. */
static ag_status write_proc_summary(ag_folder_ws *w, const char *path, json_t *j,
                                    const char *comps, ag_error *err)
{
    char *rest = j ? json_dumps(j, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))
                   : NULL;
    char *at = rest && comps ? strstr(rest, components_at) : NULL;
    ag_status s;
    if (!at) {
        ag__folder_ws_blame(w, NULL);
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing %s", path);
    } else {
        text_buf b = {0};
        put(&b, rest, (size_t)(at - rest));
        PUT_LIT(&b, "\n  \"components\": ");
        put(&b, comps, strlen(comps));
        const char *tail = at + sizeof components_at - 1;
        put(&b, tail, strlen(tail));
        if (b.fail) {
            ag__folder_ws_blame(w, NULL);
            s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory writing %s", path);
        } else {
            s = ag__folder_ws_write_file(w, path, b.p, b.n, err);
        }
        free(b.p);
    }
    free(rest);
    return s;
}

/* The file's length unit and why (core/proc/units.h), as the up axis is reported. */
static json_t *units_json(const ag_units *u)
{
    json_t *j = json_pack("{s:s, s:f, s:s}", "unit", u->name ? u->name : "m", "metres_per_unit",
                          u->metres_per_unit > 0 ? u->metres_per_unit : 1.0, "decided",
                          u->given ? "request" : "content");
    if (j && !u->given)
        json_object_set_new(j, "evidence", json_pack("{s:f, s:f}", "height", u->height,
                                                     "median_part", u->median_part));
    return j;
}

/* summary.json of `archgram proceduralize`. */
static json_t *proc_summary(const ag_folder_ws *w, const ag_model_state *st,
                            const ag_proc_outcome *o, double write_s)
{
    const ag_proceduralize_result *r = o->proc;
    const ag_mesh *m = o->input;
    const char *in = w->o.mesh_path;
    json_t *j = json_object();
    json_t *ji = json_object();
    json_object_set_new(ji, "file", json_string(in));
    json_object_set_new(ji, "triangles", json_integer((json_int_t)m->ntris));
    json_object_set_new(ji, "vertices", json_integer((json_int_t)m->nverts));
    json_object_set_new(ji, "components", json_integer((json_int_t)r->mesh->ncomponents));
    json_object_set_new(ji, "groups", json_integer((json_int_t)m->ngroups));
    json_object_set_new(ji, "bytes", json_integer((json_int_t)w->input_bytes));
    /* what import did to reach z-up metres (see io/import.h and io/assimp_import.h) */
    ag_format fmt = ag_format_sniff(NULL, 0, in);
    int zup = w->up.axis == AG_UP_Z;
    char norm[160];
    snprintf(norm, sizeof norm, "%s; %s",
             zup ? "input taken as z-up, kept" : "y-up input turned to z-up: (x, y, z) -> (x, -z, y)",
             fmt == AG_FORMAT_FBX ? "FBX units (UnitScaleFactor) converted to metres"
                                  : "coordinates kept in the file's unit (labeling.units)");
    json_object_set_new(ji, "format", json_string(ag_format_name(fmt)));
    json_object_set_new(ji, "up", ag_import_up_json(&w->up));
    json_object_set_new(ji, "normalization", json_string(norm));
    json_object_set_new(ji, "groups_split", json_integer((json_int_t)r->segment.groups_split));
    json_object_set_new(ji, "planar_fallback", json_boolean(r->segment.planar_fallback));
    json_object_set_new(j, "input", ji);

    const ag_labels *L = r->labels;
    json_t *jl = json_array();
    for (size_t l = 0; l < L->nlabels; l++) {
        json_t *lo = json_object();
        uint32_t ex = L->exemplar[l];
        double size[3];
        for (int a = 0; a < 3; a++)
            size[a] = L->box[ex].max[a] - L->box[ex].min[a];
        json_object_set_new(lo, "label", json_integer((json_int_t)l));
        json_t *tv = json_array();
        for (size_t v = 0; v < L->nvariants; v++) {
            int32_t ti = r->info.terminal_of_variant ? r->info.terminal_of_variant[v] : -1;
            if (L->variant_label[v] == (int32_t)l && ti >= 0)
                json_array_append_new(tv, json_string(r->grammar->terminals[ti].name));
        }
        json_object_set_new(lo, "terminals", tv);
        json_object_set_new(lo, "count", json_integer(L->count[l]));
        json_object_set_new(lo, "triangles", json_integer(L->ntris[ex]));
        json_object_set_new(lo, "size", vec3(size));
        json_array_append_new(jl, lo);
    }
    json_object_set_new(j, "labels", jl);
    /* how labels and shared terminals were decided (README, "Labels and shared terminals") */
    json_object_set_new(j, "labeling",
                        json_pack("{s:f, s:f, s:b, s:I, s:o}", "tolerance", L->tol, "share",
                                  L->share, "exact_copies", L->exact_copies,
                                  "surface_checks", (json_int_t)L->surface_checks, "units",
                                  units_json(&L->units)));

    /* one object per component: printed directly in save (components_text) */
    json_object_set_new(j, "components", json_string(COMPONENTS_MARK));

    json_object_set_new(j, "tree", ag__folder_ws_tree_figures(r->tree));
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    json_object_set_new(j, "terminals", json_integer((json_int_t)r->grammar->nterminals));

    ag__folder_ws_model_figures(j, r, st->text_len, st->terms.bytes);
    json_t *jf = json_object();
    json_object_set_new(jf, "max_error", json_real(o->fidelity.max_error));
    json_object_set_new(jf, "relative", json_real(o->fidelity.relative));
    json_object_set_new(jf, "unmatched", json_integer((json_int_t)o->fidelity.unmatched));
    json_object_set_new(jf, "spurious", json_integer((json_int_t)o->fidelity.spurious));
    json_object_set_new(jf, "derived_triangles",
                        json_integer((json_int_t)o->fidelity.derived_triangles));
    json_object_set_new(j, "fidelity", jf);
    json_t *js = json_object();
    json_object_set_new(js, "import", json_real(w->import_s));
    for (int s = AG_STAGE_SEGMENT; s < AG_STAGE_EXPORT; s++)
        json_object_set_new(js, ag_proceduralize_stage_name((ag_stage)s), json_real(o->seconds[s]));
    /* the export includes writing the files */
    json_object_set_new(js, "export", json_real(o->seconds[AG_STAGE_EXPORT] + write_s));
    json_object_set_new(js, "total", json_real(o->total_s + write_s));
    json_object_set_new(js, "verify", json_real(o->seconds[AG_STAGE_VERIFY]));
    json_object_set_new(j, "seconds", js);
    return j;
}

/* summary.json of `archgram edit`. */
static json_t *edit_summary(const ag_model_state *st, const ag_edit_outcome *o)
{
    json_t *j = ag_edit_op_json_report(&o->report);
    if (j) {
        json_object_set_new(j, "op", ag_edit_op_json_to_ex(o->op, o->from));
        json_object_set_new(j, "tree", ag_model_tree_folder_stats(st->em));
        json_object_set_new(j, "seconds", json_pack("{s:f,s:f}", "load", o->load_ms / 1e3,
                                                    "edit", o->edit_ms / 1e3));
    }
    return j;
}

/* --- parts ------------------------------------------------------------------------------- */

static ag_status open_part(ag_workspace *ws, const ag_part_ref *ref, const ag_part **part,
                           ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    if (!ref->path) {
        ag__folder_ws_blame(w, "");
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a folder composes a part from a bundle file; name one");
    }
    if (!w->parts) {
        ag_status s = ag_part_bundle_read_file(ref->path, &w->parts, &w->nparts, err);
        if (s != AG_OK) {
            ag__folder_ws_blame(w, ref->path);
            if (err)
                err->element = 0; /* the message names the place in the bundle */
            return s;
        }
    }
    const ag_part *found = NULL;
    for (size_t i = 0; i < w->nparts && !found; i++)
        if (ref->name ? !strcmp(w->parts[i]->name, ref->name) : w->nparts == 1)
            found = w->parts[i];
    if (!found) {
        ag__folder_ws_blame(w, ref->path);
        if (ref->name)
            return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "no part named '%s'", ref->name);
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "the bundle holds %zu parts; name one with --name", w->nparts);
    }
    *part = found;
    return AG_OK;
}

/* The folder's own name: provenance names the model, never a path of this machine. */
static void folder_name(const char *dir, char *out, size_t cap)
{
    size_t n = strlen(dir);
    while (n > 1 && dir[n - 1] == '/')
        n--;
    size_t b = n;
    while (b > 0 && dir[b - 1] != '/')
        b--;
    snprintf(out, cap, "%.*s", (int)(n - b), dir + b);
}

static ag_status save_part(ag_workspace *ws, ag_part *part, const ag_part_outcome *o,
                           ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    (void)o;
    char name[1024];
    folder_name(w->o.in_dir ? w->o.in_dir : "", name, sizeof name);
    free(part->source);
    part->source = name[0] ? strdup(name) : NULL;
    part->source_version = 0;
    ag_status s = AG_OK;
    if (name[0] && !part->source)
        s = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    const ag_part *one[1] = {part};
    if (s == AG_OK && !w->o.bundle_out)
        s = ag_error_set(err, AG_ERR_INVALID, 0, "no bundle file to save the part in");
    if (s == AG_OK && (s = ag_part_bundle_write_file(one, 1, w->o.bundle_out, err)) != AG_OK)
        ag__folder_ws_blame(w, w->o.bundle_out);
    ag_part_free(part);
    return s;
}

/* summary.json of `archgram part compose`. */
static json_t *compose_summary(const ag_model_state *st, const ag_compose_outcome *o)
{
    json_t *j = ag_usecase_compose_report_json(o);
    if (j) {
        json_object_set_new(j, "op", json_pack("{s:s,s:I,s:s,s:s}", "kind", "compose", "target",
                                               (json_int_t)o->op->target, "mode",
                                               ag_compose_mode_name(o->op->mode), "scope",
                                               ag_compose_scope_name(o->op->scope)));
        json_object_set_new(j, "tree", ag_model_tree_folder_stats(st->em));
        json_object_set_new(j, "seconds", json_pack("{s:f,s:f,s:f}", "load", o->load_ms / 1e3,
                                                    "compose", o->compose_ms / 1e3, "state",
                                                    o->state_ms / 1e3));
    }
    return j;
}

static ag_status save_composed(ag_workspace *ws, ag_model_state *st, const ag_compose_outcome *o,
                               ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    ag_status s = ag_model_state_checked(st, err); /* the composition's read-back */
    if (s == AG_OK)
        s = write_model(w, st, err);
    if (s == AG_OK) {
        char path[4200];
        snprintf(path, sizeof path, "%s/summary.json", w->o.out_dir);
        json_t *j = compose_summary(st, o);
        s = ag__folder_ws_write_json(w, path, j, JSON_INDENT(1) | JSON_REAL_PRECISION(12), err);
        json_decref(j);
    }
    ag_model_state_clear(st);
    return s;
}

static ag_status save(ag_workspace *ws, ag_model_state *st, const ag_proc_outcome *proc,
                      const ag_edit_outcome *edit, ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    double t0 = now();
    char *comps = NULL;
    ag_status s = ag_model_state_checked(st, err);
    if (s == AG_OK) {
        /* tree.json printed beside the components of summary.json and the grammar's files */
        tree_text tree;
        tree_text_start(&tree, st);
        if (proc)
            comps = components_text(proc->proc);
        s = write_model_with(w, st, &tree, err);
    }
    double write_s = now() - t0;
    if (s == AG_OK) {
        char path[4200];
        snprintf(path, sizeof path, "%s/summary.json", w->o.out_dir);
        json_t *j = proc ? proc_summary(w, st, proc, write_s) : edit_summary(st, edit);
        if (proc)
            s = write_proc_summary(w, path, j, comps, err);
        else
            s = ag__folder_ws_write_json(w, path, j, JSON_INDENT(1) | JSON_REAL_PRECISION(12), err);
        json_decref(j);
    }
    free(comps);
    ag_model_state_clear(st);
    return s;
}

static void close_ws(ag_workspace *ws)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    ag_edit_model_free(w->em);
    ag_edit_model_free(w->source);
    w->em = w->source = NULL;
    ag_pointmodel_free(w->pm);
    ag_pointmodel_free(w->pm_source);
    w->pm = w->pm_source = NULL;
    ag_part_bundle_free(w->parts, w->nparts);
    w->parts = NULL;
    w->nparts = 0;
}

static const ag_workspace_ops folder_ops = {
    .input_mesh = input_mesh,
    .open_models = open_models,
    .save = save,
    .open_part = open_part,
    .save_part = save_part,
    .save_composed = save_composed,
    .input_cloud = ag__folder_ws_input_cloud,
    .open_point_models = ag__folder_ws_open_point_models,
    .save_points = ag__folder_ws_save_points,
    .close = close_ws,
    .state_flags = AG_MODEL_READ_BACK,
};

void ag_folder_ws_init(ag_folder_ws *w, const ag_folder_ws_options *o)
{
    memset(w, 0, sizeof *w);
    w->ws.ops = &folder_ops;
    w->o = *o;
}
