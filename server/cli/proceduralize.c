/* archgram proceduralize IN --out DIR [--up y|z] [--tolerance REL] [--keep-groups] */
#include <errno.h>
#include <jansson.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/proc/proceduralize.h"
#include "../core/edit/edit.h"
#include "../io/edit_tree_json.h"
#include "../io/grammar_text.h"
#include "../io/import.h"
#include "../io/terminals.h"
#include "commands.h"

static int usage(void)
{
    fputs("usage: archgram proceduralize IN --out DIR [--up y|z] [--tolerance REL] "
          "[--exact REL] [--keep-groups]\n",
          stderr);
    return 2;
}

static json_t *vec3(const double *v)
{
    json_t *a = json_array();
    for (int i = 0; i < 3; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static int write_file(const char *path, const char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    int ok = f && fwrite(data, 1, len, f) == len;
    if (f && fclose(f))
        ok = 0;
    if (!ok)
        fprintf(stderr, "archgram: cannot write %s: %s\n", path, strerror(errno));
    return ok ? 0 : 1;
}

int ag_cli_proceduralize(int argc, char **argv)
{
    const char *in = NULL, *dir = NULL;
    ag_up_axis up = AG_UP_DEFAULT;
    ag_proceduralize_options po = {0};
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--out")) {
            if (++i >= argc)
                return usage();
            dir = argv[i];
        } else if (!strcmp(argv[i], "--up")) {
            if (++i >= argc || ag_cli_parse_up(argv[i], &up)) {
                fputs("archgram: --up takes y or z\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--tolerance")) {
            char *e;
            if (++i >= argc || (po.label.tolerance = strtod(argv[i], &e), *e) ||
                !(po.label.tolerance > 0 && po.label.tolerance < 0.1)) {
                fputs("archgram: --tolerance takes a number in (0, 0.1)\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--exact")) {
            char *e;
            if (++i >= argc || (po.label.exact = strtod(argv[i], &e), *e) ||
                !(po.label.exact > 0 && po.label.exact < 0.1)) {
                fputs("archgram: --exact takes a number in (0, 0.1)\n", stderr);
                return 2;
            }
        } else if (!strcmp(argv[i], "--keep-groups")) {
            po.segment.keep_groups = 1;
        } else if (!strcmp(argv[i], "--help")) {
            fputs("usage: archgram proceduralize IN --out DIR [--up y|z] [--tolerance REL] "
                  "[--keep-groups]\n",
                  stdout);
            return 0;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "archgram: proceduralize: unknown option %s\n", argv[i]);
            return usage();
        } else if (!in) {
            in = argv[i];
        } else {
            return usage();
        }
    }
    if (!in || !dir)
        return usage();

    double t_all = ag_cli_seconds(), t0 = ag_cli_seconds();
    ag_mesh *m = NULL;
    size_t bytes = 0;
    if (ag_cli_load_mesh(in, up, &m, &bytes))
        return 1;
    double t_import = ag_cli_seconds() - t0;

    ag_error err;
    ag_error_clear(&err);
    ag_proceduralize_result *r = NULL;
    if (ag_proceduralize_run(m, &po, &r, &err)) {
        ag_cli_report(in, &err);
        ag_mesh_free(m);
        return 1;
    }
    int rc = 1;
    char *text = NULL;
    size_t tlen = 0, term_bytes = 0;
    char path[4096];
    ag_grammar *back = NULL;
    ag_mesh *derived = NULL;
    json_t *j = NULL;

    t0 = ag_cli_seconds();
    if (ag_cli_make_dirs(dir)) {
        fprintf(stderr, "archgram: cannot create %s: %s\n", dir, strerror(errno));
        goto done;
    }
    if (ag_terminals_write(r->grammar, dir, &term_bytes, &err) ||
        ag_grammar_text_print(r->grammar, &text, &tlen, &err)) {
        ag_cli_report(dir, &err);
        goto done;
    }
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    if (write_file(path, text, tlen))
        goto done;
    double t_export = r->seconds[AG_STAGE_EXPORT] + (ag_cli_seconds() - t0);
    double t_total = ag_cli_seconds() - t_all;

    /* verify the files as written: parse, load terminals, derive, compare */
    t0 = ag_cli_seconds();
    long col = 0;
    ag_fidelity fid = {0};
    if (ag_grammar_text_read_file(path, &back, &err, &col)) {
        fprintf(stderr, "archgram: %s:%ld:%ld: %s\n", path, err.element, col, err.text);
        goto done;
    }
    if (ag_terminals_load(back, dir, &err) || ag_grammar_derive(back, NULL, &derived, &err) ||
        ag_grammar_fidelity(r->mesh, derived, 10 * r->labels->tol, &fid, &err)) {
        ag_cli_report(path, &err);
        goto done;
    }
    double t_verify = ag_cli_seconds() - t0;

    /* tree.json: the tree `archgram edit` reads this folder as (the grammar derived and
     * proceduralized again, as ag_edit_model_from_grammar does), so its ids are the ones
     * edit ops name */
    {
        ag_edit_model *em = NULL;
        if (ag_edit_model_from_grammar(back, NULL, &em, &err)) {
            ag_cli_report(path, &err);
            goto done;
        }
        char tpath[4096];
        snprintf(tpath, sizeof tpath, "%s/tree.json", dir);
        json_t *tj = ag_edit_tree_json(em->proc);
        int bad = !tj || json_dump_file(tj, tpath, JSON_INDENT(1) | JSON_REAL_PRECISION(12));
        json_decref(tj);
        ag_edit_model_free(em);
        if (bad) {
            fprintf(stderr, "archgram: cannot write %s\n", tpath);
            goto done;
        }
    }

    ag_splittree_stats ts = ag_splittree_stats_of(r->tree);
    j = json_object();
    json_t *ji = json_object();
    json_object_set_new(ji, "file", json_string(in));
    json_object_set_new(ji, "triangles", json_integer((json_int_t)m->ntris));
    json_object_set_new(ji, "vertices", json_integer((json_int_t)m->nverts));
    json_object_set_new(ji, "components", json_integer((json_int_t)r->mesh->ncomponents));
    json_object_set_new(ji, "groups", json_integer((json_int_t)m->ngroups));
    json_object_set_new(ji, "bytes", json_integer((json_int_t)bytes));
    /* what import did to reach z-up metres (see io/import.h and io/assimp_import.h) */
    ag_format fmt = ag_format_sniff(NULL, 0, in);
    int zup = up == AG_UP_Z ||
              (up == AG_UP_DEFAULT && (fmt == AG_FORMAT_PLY || fmt == AG_FORMAT_STL));
    char norm[160];
    snprintf(norm, sizeof norm, "%s; %s", zup ? "input taken as z-up, kept" :
             "y-up input turned to z-up: (x, y, z) -> (x, -z, y)",
             fmt == AG_FORMAT_FBX ? "FBX units (UnitScaleFactor) converted to metres"
                                  : "units taken as metres");
    json_object_set_new(ji, "format", json_string(ag_format_name(fmt)));
    json_object_set_new(ji, "up", json_string(zup ? "z" : "y"));
    json_object_set_new(ji, "normalization", json_string(norm));
    json_object_set_new(ji, "groups_split", json_integer((json_int_t)r->segment.groups_split));
    json_object_set_new(ji, "planar_fallback", json_boolean(r->segment.planar_fallback));
    json_object_set_new(j, "input", ji);

    const ag_labels *L = r->labels;
    json_t *jl = json_array();
    for (size_t l = 0; l < L->nlabels; l++) {
        json_t *o = json_object();
        uint32_t ex = L->exemplar[l];
        double size[3];
        for (int a = 0; a < 3; a++)
            size[a] = L->box[ex].max[a] - L->box[ex].min[a];
        json_object_set_new(o, "label", json_integer((json_int_t)l));
        json_t *tv = json_array();
        for (size_t v = 0; v < L->nvariants; v++) {
            int32_t ti = r->info.terminal_of_variant ? r->info.terminal_of_variant[v] : -1;
            if (L->variant_label[v] == (int32_t)l && ti >= 0)
                json_array_append_new(tv, json_string(r->grammar->terminals[ti].name));
        }
        json_object_set_new(o, "terminals", tv);
        json_object_set_new(o, "count", json_integer(L->count[l]));
        json_object_set_new(o, "triangles", json_integer(L->ntris[ex]));
        json_object_set_new(o, "size", vec3(size));
        json_array_append_new(jl, o);
    }
    json_object_set_new(j, "labels", jl);

    json_t *jc = json_array();
    for (size_t c = 0; c < r->mesh->ncomponents; c++) {
        json_t *o = json_object();
        int32_t g = r->mesh->component_group[c];
        json_object_set_new(o, "index", json_integer((json_int_t)c));
        json_object_set_new(o, "group", g >= 0 ? json_string(r->mesh->group_names[g]) : json_null());
        json_object_set_new(o, "label", L->label[c] >= 0 ? json_integer(L->label[c]) : json_null());
        json_object_set_new(o, "variant",
                            L->variant[c] >= 0 ? json_integer(L->variant[c]) : json_null());
        json_object_set_new(o, "rot", json_integer(90 * L->rot[c]));
        json_object_set_new(o, "node", r->tree->comp_node[c] >= 0
                                           ? json_integer(r->tree->comp_node[c])
                                           : json_null());
        json_array_append_new(jc, o);
    }
    json_object_set_new(j, "components", jc);

    json_t *jt = json_object();
    json_object_set_new(jt, "nodes", json_integer((json_int_t)ts.nodes));
    json_object_set_new(jt, "visible", json_integer((json_int_t)ts.visible));
    json_object_set_new(jt, "invisible", json_integer((json_int_t)ts.invisible));
    json_object_set_new(jt, "depth", json_integer((json_int_t)ts.depth));
    json_object_set_new(jt, "adjacent_pairs", json_integer((json_int_t)r->tree->nadj));
    json_object_set_new(j, "tree", jt);
    json_object_set_new(j, "rules", json_integer((json_int_t)r->grammar->nrules));
    json_object_set_new(j, "terminals", json_integer((json_int_t)r->grammar->nterminals));

    json_t *jp = json_array();
    for (size_t p = 0; p < r->tree->npatterns; p++) {
        const ag_pattern *pt = &r->tree->patterns[p];
        int32_t ri = r->info.rule_of_class ? r->info.rule_of_class[pt->rule] : -1;
        json_t *o = json_object();
        json_object_set_new(o, "rule", ri >= 0 ? json_string(r->grammar->rules[ri].name) : json_null());
        json_t *cnt = json_array();
        for (int a = 0; a < 3; a++)
            json_array_append_new(cnt, json_integer(pt->counts[a]));
        json_object_set_new(o, "counts", cnt);
        json_object_set_new(o, "step", vec3(pt->step));
        json_object_set_new(o, "kind", json_string(pt->nvec ? "repeat" : "subdivide"));
        if (pt->nvec) {
            json_t *vs = json_array();
            for (int k = 0; k < pt->nvec; k++)
                json_array_append_new(vs, vec3(pt->vec[k]));
            json_object_set_new(o, "vectors", vs);
        }
        json_object_set_new(o, "rot", json_integer(90 * pt->rot));
        json_object_set_new(o, "instances",
                            json_integer((json_int_t)pt->counts[0] * pt->counts[1] * pt->counts[2]));
        json_array_append_new(jp, o);
    }
    json_object_set_new(j, "patterns", jp);
    json_object_set_new(j, "grammar_bytes", json_integer((json_int_t)tlen));
    json_object_set_new(j, "terminal_bytes", json_integer((json_int_t)term_bytes));
    json_t *jf = json_object();
    json_object_set_new(jf, "max_error", json_real(fid.max_error));
    json_object_set_new(jf, "relative", json_real(fid.relative));
    json_object_set_new(jf, "unmatched", json_integer((json_int_t)fid.unmatched));
    json_object_set_new(jf, "derived_triangles", json_integer((json_int_t)fid.derived_triangles));
    json_object_set_new(j, "fidelity", jf);
    json_t *js = json_object();
    json_object_set_new(js, "import", json_real(t_import));
    json_object_set_new(js, "segment", json_real(r->seconds[AG_STAGE_SEGMENT]));
    json_object_set_new(js, "label", json_real(r->seconds[AG_STAGE_LABEL]));
    json_object_set_new(js, "tree", json_real(r->seconds[AG_STAGE_TREE]));
    json_object_set_new(js, "rules", json_real(r->seconds[AG_STAGE_RULES]));
    json_object_set_new(js, "patterns", json_real(r->seconds[AG_STAGE_PATTERNS]));
    json_object_set_new(js, "export", json_real(t_export));
    json_object_set_new(js, "total", json_real(t_total));
    json_object_set_new(js, "verify", json_real(t_verify));
    json_object_set_new(j, "seconds", js);

    snprintf(path, sizeof path, "%s/summary.json", dir);
    if (json_dump_file(j, path, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10))) {
        fprintf(stderr, "archgram: cannot write %s\n", path);
        goto done;
    }
    printf("%s: %zu triangles, %zu components, %zu labels (%zu variants), %zu rules, %zu patterns, "
           "%zu terminals; grammar %zu + terminals %zu bytes (input %zu); "
           "max error %.3g (%.3g of the diagonal), %zu unmatched; %.3f s\n",
           in, m->ntris, r->mesh->ncomponents, L->nlabels, L->nvariants, r->grammar->nrules,
           r->tree->npatterns, r->grammar->nterminals, tlen, term_bytes, bytes, fid.max_error,
           fid.relative, fid.unmatched, t_total);
    rc = fid.unmatched ? 1 : 0;
    if (fid.unmatched)
        fprintf(stderr, "archgram: %s: the grammar does not reproduce %zu input triangles\n", in,
                fid.unmatched);
done:
    json_decref(j);
    ag_mesh_free(derived);
    ag_grammar_free(back);
    free(text);
    ag_proceduralize_result_free(r);
    ag_mesh_free(m);
    return rc;
}
