#include "edit_op_json.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const KINDS[] = {NULL, "resize", "split", "join", "paste", "remove"};

static ag_status node_ref(const json_t *v, const char *field, int32_t *out, ag_error *err)
{
    if (json_is_integer(v)) {
        json_int_t i = json_integer_value(v);
        if (i < 0 || i > INT32_MAX)
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s: node index %lld out of range",
                                field, (long long)i);
        *out = (int32_t)i;
        return AG_OK;
    }
    if (json_is_string(v)) {
        const char *s = json_string_value(v);
        if (!strcmp(s, "root")) {
            *out = AG_EDIT_ROOT;
            return AG_OK;
        }
        char *end;
        errno = 0;
        long i = strtol(s, &end, 10);
        if (*s >= '0' && *s <= '9' && !*end && !errno && i <= INT32_MAX) {
            *out = (int32_t)i;
            return AG_OK;
        }
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%s: \"%.40s\" is not a node (an index or \"root\")", field, s);
    }
    return ag_error_set(err, AG_ERR_INVALID, 0, "%s: a node is an index or \"root\"", field);
}

static ag_status numbers(const json_t *v, const char *field, size_t n, double *out,
                         ag_error *err)
{
    if (!json_is_array(v) || json_array_size(v) != n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s: expected an array of %zu numbers",
                            field, n);
    for (size_t i = 0; i < n; i++) {
        const json_t *x = json_array_get(v, i);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s[%zu]: expected a finite number",
                                field, i);
        out[i] = json_number_value(x);
    }
    return AG_OK;
}

static ag_status box_of(const json_t *v, const char *field, ag_box *b, ag_error *err)
{
    double x[6];
    ag_status st = numbers(v, field, 6, x, err);
    if (st)
        return st;
    for (int a = 0; a < 3; a++) {
        if (x[a] > x[a + 3])
            return ag_error_set(err, AG_ERR_INVALID, 0, "%s: min %c %g exceeds max %g", field,
                                "xyz"[a], x[a], x[a + 3]);
        b->min[a] = x[a];
        b->max[a] = x[a + 3];
    }
    return AG_OK;
}

static ag_status node_list(const json_t *v, const char *field, ag_edit_op *op, ag_error *err)
{
    if (!json_is_array(v) || !json_array_size(v))
        return ag_error_set(err, AG_ERR_INVALID, 0, "%s: expected a non-empty array of nodes",
                            field);
    size_t n = json_array_size(v);
    if (n > 1000000)
        return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%s: too many nodes", field);
    op->nodes = malloc(n * sizeof *op->nodes);
    if (!op->nodes)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < n; i++) {
        char f[64];
        snprintf(f, sizeof f, "%s[%zu]", field, i);
        ag_status st = node_ref(json_array_get(v, i), f, &op->nodes[i], err);
        if (st)
            return st;
        op->nnodes++;
    }
    return AG_OK;
}

static ag_status choice(const json_t *v, const char *field, const char *const *names, int n,
                        int *out, ag_error *err)
{
    if (json_is_string(v))
        for (int i = 0; i < n; i++)
            if (!strcmp(json_string_value(v), names[i])) {
                *out = i;
                return AG_OK;
            }
    char list[128] = "";
    for (int i = 0; i < n; i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s\"%s\"", i ? ", " : "",
                 names[i]);
    return ag_error_set(err, AG_ERR_INVALID, 0, "%s: expected one of %s", field, list);
}

static int allowed(const char *key, const char *const *keys)
{
    for (; *keys; keys++)
        if (!strcmp(key, *keys))
            return 1;
    return 0;
}

/* "source_model" / "source_dir" of a paste into *origin (NULL: the caller cannot load
 * another model, so both are refused). */
static ag_status origin_of(const json_t *o, ag_edit_op_origin *origin, ag_error *err)
{
    const json_t *m = json_object_get(o, "source_model"), *d = json_object_get(o, "source_dir");
    if (!m && !d)
        return AG_OK;
    const char *field = m ? "source_model" : "source_dir";
    if (!origin)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "%s: pasting from another model is not possible here", field);
    if (m && d)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "source_dir: give either source_model or source_dir, not both");
    if (m) {
        json_int_t id = json_is_integer(m) ? json_integer_value(m) : 0;
        if (json_is_string(m)) {
            const char *s = json_string_value(m);
            char *end;
            errno = 0;
            long long v = strtoll(s, &end, 10);
            if (*s >= '0' && *s <= '9' && !*end && !errno)
                id = (json_int_t)v;
        }
        if (id < 1)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "source_model: expected a model id (an integer >= 1)");
        origin->model = (int64_t)id;
        return AG_OK;
    }
    const char *s = json_string_value(d);
    size_t n = s ? json_string_length(d) : 0;
    if (!s || !n)
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "source_dir: expected the path of a proceduralized folder");
    if (n > 3000 || strlen(s) != n)
        return ag_error_set(err, AG_ERR_INVALID, 0, "source_dir: not a usable path");
    if (!(origin->dir = strdup(s)))
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    return AG_OK;
}

static ag_status parse(const json_t *o, ag_edit_op *op, ag_edit_op_origin *origin,
                       ag_error *err)
{
    if (!json_is_object(o))
        return ag_error_set(err, AG_ERR_INVALID, 0, "op: expected a JSON object");
    const json_t *k = json_object_get(o, "kind");
    if (!k)
        return ag_error_set(err, AG_ERR_INVALID, 0, "kind: missing");
    int kind;
    ag_status st = choice(k, "kind", KINDS + 1, 5, &kind, err);
    if (st)
        return st;
    op->kind = kind + 1;
    static const char *const fields[][8] = {
        {0},
        {"kind", "node", "box", "scale", "mode", "region", NULL},
        {"kind", "node", "axis", "at", NULL},
        {"kind", "nodes", NULL},
        {"kind", "source", "target", "placement", "fit", "source_model", "source_dir", NULL},
        {"kind", "nodes", NULL},
    };
    const char *key;
    json_t *val;
    json_object_foreach((json_t *)o, key, val)
    {
        if (!allowed(key, fields[op->kind]))
            return ag_error_set(err, AG_ERR_INVALID, 0, "%.60s: not a field of a %s op", key,
                                KINDS[op->kind]);
    }
    switch (op->kind) {
    case AG_EDIT_RESIZE: {
        const json_t *n = json_object_get(o, "node"), *b = json_object_get(o, "box"),
                     *s = json_object_get(o, "scale"), *m = json_object_get(o, "mode"),
                     *r = json_object_get(o, "region");
        if (!n)
            return ag_error_set(err, AG_ERR_INVALID, 0, "node: missing");
        if ((st = node_ref(n, "node", &op->node, err)))
            return st;
        if (!b == !s)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                b ? "scale: give either box or scale, not both"
                                  : "box: a resize needs a box or a scale");
        if (b) {
            if ((st = box_of(b, "box", &op->box, err)))
                return st;
            op->has_box = 1;
        } else {
            if ((st = numbers(s, "scale", 3, op->scale, err)))
                return st;
            for (int a = 0; a < 3; a++)
                if (!(op->scale[a] > 0))
                    return ag_error_set(err, AG_ERR_INVALID, 0,
                                        "scale[%d]: must be positive", a);
            op->has_scale = 1;
        }
        static const char *const modes[] = {"global", "local"};
        if (m && (st = choice(m, "mode", modes, 2, &op->mode, err)))
            return st;
        if (r) {
            if (op->mode != AG_EDIT_LOCAL)
                return ag_error_set(err, AG_ERR_INVALID, 0,
                                    "region: only with \"mode\": \"local\"");
            if ((st = box_of(r, "region", &op->region, err)))
                return st;
            op->has_region = 1;
        }
        return AG_OK;
    }
    case AG_EDIT_SPLIT: {
        const json_t *n = json_object_get(o, "node"), *a = json_object_get(o, "axis"),
                     *at = json_object_get(o, "at");
        if (!n)
            return ag_error_set(err, AG_ERR_INVALID, 0, "node: missing");
        if ((st = node_ref(n, "node", &op->node, err)))
            return st;
        static const char *const axes[] = {"x", "y", "z"};
        if (!a)
            return ag_error_set(err, AG_ERR_INVALID, 0, "axis: missing");
        if ((st = choice(a, "axis", axes, 3, &op->axis, err)))
            return st;
        if (!at)
            return ag_error_set(err, AG_ERR_INVALID, 0, "at: missing");
        if (!json_is_number(at) || !isfinite(json_number_value(at)))
            return ag_error_set(err, AG_ERR_INVALID, 0, "at: expected a number (metres)");
        op->at = json_number_value(at);
        return AG_OK;
    }
    case AG_EDIT_JOIN:
    case AG_EDIT_REMOVE: {
        const json_t *n = json_object_get(o, "nodes");
        if (!n)
            return ag_error_set(err, AG_ERR_INVALID, 0, "nodes: missing");
        if ((st = node_list(n, "nodes", op, err)))
            return st;
        if (op->kind == AG_EDIT_JOIN && op->nnodes < 2)
            return ag_error_set(err, AG_ERR_INVALID, 0, "nodes: a join needs two nodes or more");
        return AG_OK;
    }
    case AG_EDIT_PASTE: {
        const json_t *s = json_object_get(o, "source"), *t = json_object_get(o, "target"),
                     *p = json_object_get(o, "placement"), *f = json_object_get(o, "fit");
        if (!s)
            return ag_error_set(err, AG_ERR_INVALID, 0, "source: missing");
        if ((st = node_list(s, "source", op, err)))
            return st;
        if (!t)
            return ag_error_set(err, AG_ERR_INVALID, 0, "target: missing");
        if ((st = node_ref(t, "target", &op->node, err)))
            return st;
        static const char *const placements[] = {"insert", "replace"}, *const fits[] = {"fill",
                                                                                         "derive"};
        if (p && (st = choice(p, "placement", placements, 2, &op->placement, err)))
            return st;
        if (f && (st = choice(f, "fit", fits, 2, &op->fit, err)))
            return st;
        return origin_of(o, origin, err);
    }
    }
    return AG_OK;
}

void ag_edit_op_origin_clear(ag_edit_op_origin *o)
{
    if (!o)
        return;
    free(o->dir);
    memset(o, 0, sizeof *o);
}

static ag_status from(const json_t *obj, ag_edit_op *op, ag_edit_op_origin *origin,
                      ag_error *err)
{
    memset(op, 0, sizeof *op);
    ag_status st = parse(obj, op, origin, err);
    if (st) {
        ag_edit_op_clear(op);
        ag_edit_op_origin_clear(origin);
    }
    return st;
}

ag_status ag_edit_op_json_from(const json_t *obj, ag_edit_op *op, ag_error *err)
{
    return from(obj, op, NULL, err);
}

ag_status ag_edit_op_json_from_ex(const json_t *obj, ag_edit_op *op, ag_edit_op_origin *origin,
                                  ag_error *err)
{
    memset(origin, 0, sizeof *origin);
    return from(obj, op, origin, err);
}

static ag_status parse_text(const char *text, size_t len, ag_edit_op *op,
                            ag_edit_op_origin *origin, ag_error *err)
{
    memset(op, 0, sizeof *op);
    json_error_t je;
    json_t *root = json_loadb(text, len, 0, &je);
    if (!root)
        return ag_error_set(err, AG_ERR_PARSE, je.line > 0 ? je.line : 0, "%s", je.text);
    ag_status st = from(root, op, origin, err);
    json_decref(root);
    return st;
}

ag_status ag_edit_op_json_parse(const char *text, size_t len, ag_edit_op *op, ag_error *err)
{
    return parse_text(text, len, op, NULL, err);
}

ag_status ag_edit_op_json_parse_ex(const char *text, size_t len, ag_edit_op *op,
                                   ag_edit_op_origin *origin, ag_error *err)
{
    memset(origin, 0, sizeof *origin);
    return parse_text(text, len, op, origin, err);
}

static ag_status read_file(const char *path, ag_edit_op *op, ag_edit_op_origin *origin,
                           ag_error *err)
{
    memset(op, 0, sizeof *op);
    FILE *f = fopen(path, "rb");
    if (!f)
        return ag_error_set(err, AG_ERR_IO, 0, "cannot open: %s", strerror(errno));
    size_t cap = 1 << 20, len;
    char *buf = malloc(cap + 1);
    if (!buf) {
        fclose(f);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    len = fread(buf, 1, cap + 1, f);
    int bad = ferror(f);
    fclose(f);
    ag_status st;
    if (bad)
        st = ag_error_set(err, AG_ERR_IO, 0, "read error");
    else if (len > cap)
        st = ag_error_set(err, AG_ERR_TOO_LARGE, 0, "an op file is at most 1 MiB");
    else
        st = parse_text(buf, len, op, origin, err);
    free(buf);
    return st;
}

ag_status ag_edit_op_json_read_file(const char *path, ag_edit_op *op, ag_error *err)
{
    return read_file(path, op, NULL, err);
}

ag_status ag_edit_op_json_read_file_ex(const char *path, ag_edit_op *op,
                                       ag_edit_op_origin *origin, ag_error *err)
{
    memset(origin, 0, sizeof *origin);
    return read_file(path, op, origin, err);
}

static json_t *node_json(int32_t n) { return n == AG_EDIT_ROOT ? json_string("root") : json_integer(n); }

static json_t *nums(const double *v, size_t n)
{
    json_t *a = json_array();
    for (size_t i = 0; a && i < n; i++)
        json_array_append_new(a, json_real(v[i]));
    return a;
}

static json_t *box_json(const ag_box *b)
{
    double v[6] = {b->min[0], b->min[1], b->min[2], b->max[0], b->max[1], b->max[2]};
    return nums(v, 6);
}

json_t *ag_edit_op_json_to(const ag_edit_op *op)
{
    if (op->kind < AG_EDIT_RESIZE || op->kind > AG_EDIT_REMOVE)
        return NULL;
    json_t *o = json_object();
    if (!o)
        return NULL;
    json_object_set_new(o, "kind", json_string(KINDS[op->kind]));
    json_t *list = NULL;
    if (op->nnodes) {
        list = json_array();
        for (size_t i = 0; list && i < op->nnodes; i++)
            json_array_append_new(list, node_json(op->nodes[i]));
    }
    switch (op->kind) {
    case AG_EDIT_RESIZE:
        json_object_set_new(o, "node", node_json(op->node));
        if (op->has_box)
            json_object_set_new(o, "box", box_json(&op->box));
        else
            json_object_set_new(o, "scale", nums(op->scale, 3));
        json_object_set_new(o, "mode", json_string(op->mode == AG_EDIT_LOCAL ? "local" : "global"));
        if (op->has_region)
            json_object_set_new(o, "region", box_json(&op->region));
        break;
    case AG_EDIT_SPLIT:
        json_object_set_new(o, "node", node_json(op->node));
        json_object_set_new(o, "axis", json_string((const char *[]){"x", "y", "z"}[op->axis % 3]));
        json_object_set_new(o, "at", json_real(op->at));
        break;
    case AG_EDIT_JOIN:
    case AG_EDIT_REMOVE:
        json_object_set_new(o, "nodes", list ? list : json_array());
        list = NULL;
        break;
    case AG_EDIT_PASTE:
        json_object_set_new(o, "source", list ? list : json_array());
        list = NULL;
        json_object_set_new(o, "target", node_json(op->node));
        json_object_set_new(o, "placement",
                            json_string(op->placement == AG_EDIT_REPLACE ? "replace" : "insert"));
        json_object_set_new(o, "fit", json_string(op->fit == AG_EDIT_DERIVE ? "derive" : "fill"));
        break;
    }
    json_decref(list);
    return o;
}

json_t *ag_edit_op_json_to_ex(const ag_edit_op *op, const ag_edit_op_origin *origin)
{
    json_t *o = ag_edit_op_json_to(op);
    if (!o || !origin || op->kind != AG_EDIT_PASTE)
        return o;
    if (origin->model > 0)
        json_object_set_new(o, "source_model", json_integer((json_int_t)origin->model));
    else if (origin->dir)
        json_object_set_new(o, "source_dir", json_string(origin->dir));
    return o;
}

json_t *ag_edit_op_json_report(const ag_edit_report *rep)
{
    json_t *o = json_object(), *labels = json_object();
    if (!o || !labels) {
        json_decref(o);
        json_decref(labels);
        return NULL;
    }
    json_object_set_new(o, "equations", json_integer((json_int_t)rep->equations));
    json_object_set_new(o, "unknowns", json_integer((json_int_t)rep->unknowns));
    json_object_set_new(o, "solve_ms", json_real(rep->solve_ms));
    json_object_set_new(o, "max_residual", json_real(rep->max_residual));
    json_object_set_new(o, "max_residual_relative", json_real(rep->max_residual_rel));
    json_object_set_new(o, "splits", json_integer((json_int_t)rep->splits));
    json_object_set_new(o, "joins", json_integer((json_int_t)rep->joins));
    for (size_t i = 0; i < rep->nlabels; i++)
        json_object_set_new(labels, rep->labels[i].name,
                            json_integer((json_int_t)rep->labels[i].count));
    json_object_set_new(o, "instances_per_label", labels);
    json_object_set_new(o, "message", json_string(rep->message));
    return o;
}
