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
ag_status ag__folder_ws_input_cloud(ag_workspace *ws, int with_properties, int need_segmentation,
                                    ag_cloud_state *cs, ag_error *err)
{
    (void)with_properties;
    ag_folder_ws *w = (ag_folder_ws *)ws;
    ag__folder_ws_blame(w, w->o.cloud_path);
    if (need_segmentation)
        return ag_error_set(err, AG_ERR_CONFLICT, 0, "a cloud file has no segmentation to use");
    double t0 = ag_clock_seconds();
    struct stat sb;
    w->input_bytes = stat(w->o.cloud_path, &sb) ? 0 : (size_t)sb.st_size;
    ag_status st = ag_cloud_import_file(w->o.cloud_path, &cs->cloud, err);
    w->import_s = ag_clock_seconds() - t0;
    if (st == AG_OK)
        cs->had_normals = cs->cloud->normals != NULL;
    return st;
}

static ag_status read_folder(ag_folder_ws *w, const char *dir, ag_pointmodel **pm,
                             ag_error *err)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/grammar.txt", dir);
    ag__folder_ws_blame(w, path);
    long col = 0;
    ag_status st = ag_points_folder_read_grammar(path, pm, err, &col);
    if (st == AG_ERR_PARSE && col)
        ag_error_set(err, st, err->element, "%ld: %.200s", col, err->text);
    return st;
}

ag_status ag__folder_ws_open_point_models(ag_workspace *ws, const ag_edit_op_origin *from,
                                          ag_pointmodel **pm, const ag_pointmodel **source,
                                          ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    ag_status st = read_folder(w, w->o.in_dir, &w->pm, err);
    if (st == AG_OK)
        st = ag__folder_ws_check_origin(w, from, err);
    if (st != AG_OK)
        return st;
    if (from && from->dir) {
        char dir[4096];
        if ((st = ag__folder_ws_source_dir(w, from->dir, dir, sizeof dir, err)) != AG_OK)
            return st;
        if (!ag_points_folder_is_point_model(dir))
            return ag_error_set(err, AG_ERR_NOT_PROCEDURALIZED, 0,
                                "source_dir: %s holds no point model (run `archgram "
                                "proceduralize CLOUD --out %s`)",
                                dir, dir);
        if ((st = read_folder(w, dir, &w->pm_source, err)) != AG_OK)
            return st;
    }
    *pm = w->pm;
    *source = w->pm_source;
    w->blamed = 0; /* from here on, problems are the op's or the model's */
    return AG_OK;
}

/* ---- writing ------------------------------------------------------------------------------ */

ag_status ag__folder_ws_save_points(ag_workspace *ws, ag_points_state *st,
                                    const ag_points_outcome *proc, const ag_edit_outcome *edit,
                                    ag_error *err)
{
    ag_folder_ws *w = (ag_folder_ws *)ws;
    double t0 = ag_clock_seconds();
    const char *dir = w->o.out_dir;
    char path[4200];
    ag_status s = ag__folder_ws_write_grammar(w, st->text, st->text_len, &st->terms, err);
    if (s == AG_OK) {
        json_t *tree = ag_model_tree_folder(st->pm->em);
        if (tree)
            ag_points_summary_shift_tree(tree, st->pm->offset);
        snprintf(path, sizeof path, "%s/tree.json", dir);
        s = ag__folder_ws_write_json(w, path, tree, JSON_INDENT(1) | JSON_REAL_PRECISION(12), err);
        json_decref(tree);
    }
    if (s == AG_OK) {
        ag_points_summary_input in = {.file = w->o.cloud_path,
                                      .bytes = w->input_bytes,
                                      .read_s = w->import_s,
                                      .write_s = ag_clock_seconds() - t0};
        json_t *j = proc ? ag_points_summary_proc(st, proc, &in) : ag_points_summary_edit(st, edit);
        snprintf(path, sizeof path, "%s/summary.json", dir);
        s = ag__folder_ws_write_json(w, path, j,
                                     JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(6),
                                     err);
        json_decref(j);
    }
    ag_points_state_clear(st);
    return s;
}
