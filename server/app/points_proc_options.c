#include "points_proc_options.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int ag_points_proc_options_is_key(const char *key)
{
    return !strcmp(key, "templates") || !strcmp(key, "rois") || !strcmp(key, "auto");
}

/* A list of boxes: each six finite numbers, min <= max on each axis. */
static ag_status read_boxes(const json_t *list, const char *name, ag_box *out, size_t *n,
                            ag_error *err)
{
    *n = 0;
    if (!list)
        return AG_OK;
    if (!json_is_array(list) || json_array_size(list) > AG_POINTS_PROC_OPTIONS_MAX_BOXES)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%s: an array of at most %d boxes [x0, y0, z0, x1, y1, z1]", name,
                            AG_POINTS_PROC_OPTIONS_MAX_BOXES);
    size_t i;
    const json_t *b;
    json_array_foreach(list, i, b) {
        if (!json_is_array(b) || json_array_size(b) != 6)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "%s[%zu]: a box [x0, y0, z0, x1, y1, z1] of six numbers", name, i);
        double v[6];
        for (size_t k = 0; k < 6; k++) {
            const json_t *x = json_array_get(b, k);
            v[k] = json_number_value(x);
            if (!json_is_number(x) || !isfinite(v[k]))
                return ag_error_set(err, AG_ERR_INVALID, 0, "%s[%zu][%zu] is not a finite number",
                                    name, i, k);
        }
        for (int a = 0; a < 3; a++) {
            if (v[a] > v[3 + a])
                return ag_error_set(err, AG_ERR_INVALID, 0,
                                    "%s[%zu]: its minimum %g lies above its maximum %g on axis %c",
                                    name, i, v[a], v[3 + a], "xyz"[a]);
            out[i].min[a] = v[a];
            out[i].max[a] = v[3 + a];
        }
    }
    *n = json_array_size(list);
    return AG_OK;
}

ag_status ag_points_proc_options_read(const json_t *obj, ag_usecase_points_proceduralize_params *p,
                                      ag_box **boxes, ag_error *err)
{
    memset(p, 0, sizeof *p);
    *boxes = NULL;
    if (!obj)
        return AG_OK;
    if (!json_is_object(obj))
        return ag_error_set(err, AG_ERR_INVALID, 0, "the point cloud options must be an object");
    const char *key;
    const json_t *v;
    json_object_foreach((json_t *)obj, key, v) {
        if (!ag_points_proc_options_is_key(key))
            return ag_error_set(err, AG_ERR_INVALID, 0, "\"%s\" is not an option of proceduralize",
                                key);
    }
    const json_t *a = json_object_get(obj, "auto");
    if (a && !json_is_boolean(a))
        return ag_error_set(err, AG_ERR_INVALID, 0, "\"auto\" takes true or false");
    ag_box *b = malloc(2 * AG_POINTS_PROC_OPTIONS_MAX_BOXES * sizeof *b);
    if (!b)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    size_t nt = 0, nr = 0;
    ag_status s = read_boxes(json_object_get(obj, "templates"), "templates", b, &nt, err);
    if (s == AG_OK)
        s = read_boxes(json_object_get(obj, "rois"), "rois", b + nt, &nr, err);
    if (s != AG_OK) {
        free(b);
        return s;
    }
    p->options.templates = nt ? b : NULL;
    p->options.ntemplates = nt;
    p->options.rois = nr ? b + nt : NULL;
    p->options.nrois = nr;
    p->options.no_auto = a && json_is_false(a);
    p->boxes_in_input = 1;
    *boxes = b;
    return AG_OK;
}
