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
#include "points_summary.h"

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
            ag_points_summary_shift_tree(tree, st->pm->offset);
        snprintf(path, sizeof path, "%s/tree.json", dir);
        if (!tree || json_dump_file(tree, path, JSON_INDENT(1) | JSON_REAL_PRECISION(12))) {
            blame(w, NULL);
            s = ag_error_set(err, AG_ERR_IO, 0, "cannot write %s", path);
        }
        json_decref(tree);
    }
    if (s == AG_OK) {
        ag_points_summary_input in = {.file = w->o.cloud_path,
                                      .bytes = w->input_bytes,
                                      .read_s = w->read_s,
                                      .write_s = ag_clock_seconds() - t0};
        json_t *j = proc ? ag_points_summary_proc(st, proc, &in) : ag_points_summary_edit(st, edit);
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
