#include "plan_json.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../core/base/array.h"
#include "obj.h"

static ag_status read_points(json_t *arr, const char *what, ag_profile_point **out, size_t *n,
                             ag_error *err)
{
    *out = NULL;
    *n = 0;
    if (!json_is_array(arr) || json_array_size(arr) == 0)
        return ag_error_set(err, AG_ERR_PARSE, 0, "%s: expected a non-empty array of [x, y] pairs",
                            what);
    size_t k = json_array_size(arr);
    ag_profile_point *p = malloc(k * sizeof *p);
    if (!p)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    for (size_t i = 0; i < k; i++) {
        json_t *pt = json_array_get(arr, i);
        if (!json_is_array(pt) || json_array_size(pt) != 2 ||
            !json_is_number(json_array_get(pt, 0)) || !json_is_number(json_array_get(pt, 1))) {
            free(p);
            return ag_error_set(err, AG_ERR_PARSE, (long)i + 1,
                                "%s: point %zu is not a pair of numbers", what, i);
        }
        p[i].w = json_number_value(json_array_get(pt, 0));
        p[i].z = json_number_value(json_array_get(pt, 1));
    }
    *out = p;
    *n = k;
    return AG_OK;
}

static ag_status read_anchor_mesh(json_t *av, const char *what, size_t ai, ag_anchor *a,
                                  const ag_plan *p, ag_error *err)
{
    memset(a, 0, sizeof *a);
    json_t *rel = json_object_get(av, "relative"), *abs_ = json_object_get(av, "absolute");
    json_t *lo = json_object_get(av, "loop"), *ed = json_object_get(av, "edge");
    json_t *h = json_object_get(av, "height");
    if (!json_is_object(av) || !json_is_integer(ed) || (lo && !json_is_integer(lo)) ||
        !json_is_number(h) || (!rel == !abs_) || (rel && !json_is_number(rel)) ||
        (abs_ && !json_is_number(abs_)))
        return ag_error_set(err, AG_ERR_PARSE, (long)ai + 1,
                            "plan: %s[%zu] needs \"edge\", \"height\" and one of \"relative\" "
                            "or \"absolute\" (numbers)", what, ai);
    const char *nm = json_string_value(json_object_get(av, "name"));
    snprintf(a->name, sizeof a->name, "%s", nm ? nm : "");
    a->loop = lo ? (int32_t)json_integer_value(lo) : 0;
    a->edge = (int32_t)json_integer_value(ed);
    a->absolute = abs_ != NULL;
    a->along = json_number_value(abs_ ? abs_ : rel);
    a->z = json_number_value(h);
    json_t *mesh = json_object_get(av, "mesh");
    if (mesh) {
        int32_t k = p && json_is_string(mesh) ? ag_plan_find_mesh(p, json_string_value(mesh)) : -1;
        if (k < 0)
            return ag_error_set(err, AG_ERR_PARSE, (long)ai + 1,
                                "plan: %s[%zu].mesh must name one of \"meshes\"", what, ai);
        a->mesh = k + 1;
    }
    return AG_OK;
}

static ag_status read_anchor(json_t *av, const char *what, size_t ai, ag_anchor *a, ag_error *err)
{
    return read_anchor_mesh(av, what, ai, a, NULL, err);
}

/* "meshes": {name: "file.obj" | {"path": "file.obj", "up": "y" | "z"}}, paths relative
 * to base (the plan file's folder; NULL: as given). */
static ag_status read_meshes(json_t *root, const char *base, ag_plan *p, ag_error *err)
{
    json_t *ms = json_object_get(root, "meshes");
    if (!ms)
        return AG_OK;
    if (!json_is_object(ms))
        return ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"meshes\" must map names to OBJ files");
    const char *name;
    json_t *mv;
    json_object_foreach(ms, name, mv)
    {
        json_t *pv = json_is_object(mv) ? json_object_get(mv, "path") : mv;
        json_t *up = json_is_object(mv) ? json_object_get(mv, "up") : NULL;
        const char *path = json_string_value(pv), *ups = up ? json_string_value(up) : "y";
        if (!path || !ups || (strcmp(ups, "y") != 0 && strcmp(ups, "z") != 0))
            return ag_error_set(err, AG_ERR_PARSE, 0,
                                "plan: meshes.%s must be a file name or {\"path\", \"up\": "
                                "\"y\"|\"z\"}", name);
        if (strlen(name) >= sizeof p->meshes[0].name)
            return ag_error_set(err, AG_ERR_PARSE, 0, "plan: mesh name %s is too long (max %zu)",
                                name, sizeof p->meshes[0].name - 1);
        /* a description from the network or from memory has no folder of its own: naming
         * files there would let a client make the server read any OBJ on its disk */
        if (!base)
            return ag_error_set(err, AG_ERR_INVALID, 0,
                                "plan: meshes.%s: mesh files can only be named in a plan read "
                                "from a file (archgram extrude --plan)", name);
        char full[4096];
        if (path[0] != '/')
            snprintf(full, sizeof full, "%s/%s", base, path);
        else
            snprintf(full, sizeof full, "%s", path);
        ag_obj_read_options o = {0};
        o.up = ups[0] == 'z' ? AG_UP_Z : AG_UP_Y;
        ag_mesh *m = NULL;
        ag_error e2 = {0};
        if (ag_obj_read_file(full, &o, &m, &e2) != AG_OK)
            return ag_error_set(err, e2.code ? e2.code : AG_ERR_IO, 0, "plan: meshes.%s: %s", name,
                                e2.text);
        ag_status st = ag_plan_add_mesh(p, name, m, NULL, err);
        if (st != AG_OK)
            return st;
    }
    return AG_OK;
}

/* "offsets": [{"height", "outside", "profile", "side", "inside": {"gap", "profile",
 * "inner"}, "edges": [{"loop", "edge", "disabled", "outside", "profile", "inside"}]}] */
static int32_t opt_profile(json_t *v, const ag_plan *p, int *bad)
{
    if (!v || json_is_null(v))
        return -1;
    int32_t k = json_is_string(v) ? ag_plan_find_profile(p, json_string_value(v)) : -1;
    if (k < 0)
        *bad = 1;
    return k;
}

/* "inside": {"gap": [from, to], "profile": NAME, "inner": NAME}; every member optional
 * here (the event's are checked when it is added). Returns 0 when malformed. */
static int read_inside(json_t *v, const ag_plan *p, int *has_gap, double *from, double *to,
                       int32_t *inside, int32_t *inner)
{
    if (!json_is_object(v))
        return 0;
    json_t *g = json_object_get(v, "gap");
    int bad = 0;
    *inside = opt_profile(json_object_get(v, "profile"), p, &bad);
    *inner = opt_profile(json_object_get(v, "inner"), p, &bad);
    if (g && (!json_is_array(g) || json_array_size(g) != 2 ||
              !json_is_number(json_array_get(g, 0)) || !json_is_number(json_array_get(g, 1))))
        bad = 1;
    const char *key;
    json_t *x;
    json_object_foreach(v, key, x)
        if (strcmp(key, "gap") && strcmp(key, "profile") && strcmp(key, "inner"))
            bad = 1;
    if (bad)
        return 0;
    *has_gap = g != NULL;
    *from = g ? json_number_value(json_array_get(g, 0)) : 0;
    *to = g ? json_number_value(json_array_get(g, 1)) : 0;
    return 1;
}

static ag_status read_offsets(json_t *root, ag_plan *p, ag_error *err)
{
    json_t *offs = json_object_get(root, "offsets");
    if (!offs)
        return AG_OK;
    if (!json_is_array(offs))
        return ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"offsets\" must be an array");
    size_t oi;
    json_t *ov;
    json_array_foreach(offs, oi, ov)
    {
        json_t *h = json_object_get(ov, "height"), *w = json_object_get(ov, "outside");
        json_t *edges = json_object_get(ov, "edges");
        int bad = 0;
        ag_plan_offset o;
        memset(&o, 0, sizeof o);
        o.profile = opt_profile(json_object_get(ov, "profile"), p, &bad);
        o.side = opt_profile(json_object_get(ov, "side"), p, &bad);
        json_t *ins = json_object_get(ov, "inside");
        o.inner = -1;
        o.inside = -1;
        if (ins && (!read_inside(ins, p, &o.has_gap, &o.gap_from, &o.gap_to, &o.inside, &o.inner) ||
                    !o.has_gap))
            return ag_error_set(err, AG_ERR_PARSE, (long)oi + 1,
                                "plan: offsets[%zu].inside needs \"gap\": [from, to] (metres "
                                "inwards) and may have \"profile\" and \"inner\" (profile "
                                "names)", oi);
        if (!json_is_object(ov) || !json_is_number(h) || (!json_is_number(w) && (w || !ins)) ||
            bad || (edges && !json_is_array(edges)))
            return ag_error_set(err, AG_ERR_PARSE, (long)oi + 1,
                                "plan: offsets[%zu] needs \"height\" and \"outside\" (numbers; "
                                "\"outside\" may be left out with \"inside\"); \"profile\" "
                                "and \"side\" must name profiles, \"edges\" be an array", oi);
        o.z = json_number_value(h);
        o.outside = w ? json_number_value(w) : 0;
        o.nedges = edges ? json_array_size(edges) : 0;
        o.edges = calloc(o.nedges ? o.nedges : 1, sizeof *o.edges);
        if (!o.edges)
            return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
        size_t ei;
        json_t *ev;
        json_array_foreach(edges, ei, ev)
        {
            ag_offset_edge *x = &o.edges[ei];
            json_t *lo = json_object_get(ev, "loop"), *ed = json_object_get(ev, "edge");
            json_t *dis = json_object_get(ev, "disabled"), *xw = json_object_get(ev, "outside");
            x->profile = opt_profile(json_object_get(ev, "profile"), p, &bad);
            json_t *xin = json_object_get(ev, "inside");
            int32_t xi = -1, xn = -1;
            if (xin && !read_inside(xin, p, &x->has_gap, &x->gap_from, &x->gap_to, &xi, &xn))
                bad = 1;
            x->inside = xi + 1;
            x->inner = xn + 1;
            if (!json_is_object(ev) || !json_is_integer(ed) || (lo && !json_is_integer(lo)) ||
                (dis && !json_is_boolean(dis)) || (xw && !json_is_number(xw)) || bad) {
                free(o.edges);
                return ag_error_set(err, AG_ERR_PARSE, (long)oi + 1,
                                    "plan: offsets[%zu].edges[%zu] needs \"edge\" (and may have "
                                    "\"loop\", \"disabled\", \"outside\", \"profile\", "
                                    "\"inside\")", oi, ei);
            }
            x->loop = lo ? (int32_t)json_integer_value(lo) : 0;
            x->edge = (int32_t)json_integer_value(ed);
            x->disabled = json_is_true(dis);
            x->has_outside = xw != NULL;
            x->outside = xw ? json_number_value(xw) : 0;
        }
        ag_status st = ag_plan_add_offset(p, &o, err);
        free(o.edges);
        if (st != AG_OK)
            return st;
    }
    return AG_OK;
}

static ag_status parse_plan(json_t *root, const char *base, ag_plan **out, ag_error *err)
{
    if (!json_is_object(root))
        return ag_error_set(err, AG_ERR_PARSE, 0, "plan: the document must be a JSON object");
    ag_plan *p = ag_plan_create();
    if (!p)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = AG_OK;
    json_t *profiles = json_object_get(root, "profiles");
    if (!json_is_object(profiles) || json_object_size(profiles) == 0) {
        st = ag_error_set(err, AG_ERR_PARSE, 0,
                          "plan: \"profiles\" must be an object of named profiles");
        goto fail;
    }
    const char *name;
    json_t *pv;
    json_object_foreach(profiles, name, pv)
    {
        json_t *pts = json_is_object(pv) ? json_object_get(pv, "points") : pv;
        json_t *tag = json_is_object(pv) ? json_object_get(pv, "tag") : NULL;
        if (tag && !json_is_string(tag)) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: profiles.%s.tag must be a string", name);
            goto fail;
        }
        char what[96];
        snprintf(what, sizeof what, "plan: profiles.%s.points", name);
        ag_profile_point *pp = NULL;
        size_t n = 0;
        st = read_points(pts, what, &pp, &n, err);
        if (st != AG_OK)
            goto fail;
        size_t idx = 0;
        st = ag_plan_add_profile(p, name, pp, n, tag ? json_string_value(tag) : NULL, &idx, err);
        free(pp);
        if (st != AG_OK)
            goto fail;
        json_t *prio = json_is_object(pv) ? json_object_get(pv, "priority") : NULL;
        if (prio && !json_is_integer(prio)) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: profiles.%s.priority must be an integer",
                              name);
            goto fail;
        }
        if (prio)
            p->profiles[idx].priority = (int32_t)json_integer_value(prio);
        json_t *sp = json_is_object(pv) ? json_object_get(pv, "segment_priority") : NULL;
        if (sp && (!json_is_array(sp) || json_array_size(sp) != n - 1)) {
            st = ag_error_set(err, AG_ERR_PARSE, 0,
                              "plan: profiles.%s.segment_priority must hold one integer per "
                              "segment (%zu)", name, n - 1);
            goto fail;
        }
        for (size_t k = 0; sp && k + 1 < n; k++) {
            json_t *v = json_array_get(sp, k);
            if (!json_is_integer(v) && !json_is_null(v)) {
                st = ag_error_set(err, AG_ERR_PARSE, 0,
                                  "plan: profiles.%s.segment_priority[%zu] must be an integer "
                                  "(or null for the profile's priority)", name, k);
                goto fail;
            }
            st = ag_plan_set_segment_priority(
                p, idx, k, json_is_null(v) ? p->profiles[idx].priority : (int32_t)json_integer_value(v),
                err);
            if (st != AG_OK)
                goto fail;
        }
    }
    int32_t def = 0;
    json_t *dp = json_object_get(root, "default_profile");
    if (dp) {
        if (!json_is_string(dp) || (def = ag_plan_find_profile(p, json_string_value(dp))) < 0) {
            st = ag_error_set(err, AG_ERR_PARSE, 0,
                              "plan: \"default_profile\" must name one of the profiles");
            goto fail;
        }
    }
    json_t *loops = json_object_get(root, "loops");
    if (!json_is_array(loops) || json_array_size(loops) == 0) {
        st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"loops\" must be a non-empty array");
        goto fail;
    }
    size_t li;
    json_t *lv;
    json_array_foreach(loops, li, lv)
    {
        json_t *pts = json_is_object(lv) ? json_object_get(lv, "points") : lv;
        char what[64];
        snprintf(what, sizeof what, "plan: loops[%zu].points", li);
        ag_profile_point *pp = NULL;
        size_t n = 0;
        st = read_points(pts, what, &pp, &n, err);
        if (st != AG_OK)
            goto fail;
        int32_t *prof = malloc(n * sizeof *prof);
        double *xy = malloc(2 * n * sizeof *xy);
        if (!prof || !xy) {
            free(pp);
            free(prof);
            free(xy);
            st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            goto fail;
        }
        for (size_t i = 0; i < n; i++) {
            xy[2 * i] = pp[i].w;
            xy[2 * i + 1] = pp[i].z;
            prof[i] = def;
        }
        free(pp);
        json_t *lp = json_is_object(lv) ? json_object_get(lv, "profiles") : NULL;
        if (lp && (!json_is_array(lp) || json_array_size(lp) != n)) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)li + 1,
                              "plan: loops[%zu].profiles must hold one profile name per edge (%zu)",
                              li, n);
        } else if (lp) {
            for (size_t i = 0; i < n && st == AG_OK; i++) {
                json_t *nm = json_array_get(lp, i);
                int32_t k = json_is_string(nm) ? ag_plan_find_profile(p, json_string_value(nm)) : -1;
                if (json_is_null(nm))
                    k = def;
                if (k < 0)
                    st = ag_error_set(err, AG_ERR_PARSE, (long)li + 1,
                                      "plan: loops[%zu].profiles[%zu] names no profile", li, i);
                else
                    prof[i] = k;
            }
        }
        if (st == AG_OK)
            st = ag_plan_add_loop(p, xy, n, prof, err);
        free(prof);
        free(xy);
        if (st != AG_OK)
            goto fail;
    }
    st = read_meshes(root, base, p, err);
    if (st != AG_OK)
        goto fail;
    json_t *anchors = json_object_get(root, "anchors");
    if (anchors && !json_is_array(anchors)) {
        st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"anchors\" must be an array");
        goto fail;
    }
    size_t ai;
    json_t *av;
    json_array_foreach(anchors, ai, av)
    {
        ag_anchor a;
        st = read_anchor_mesh(av, "anchors", ai, &a, p, err);
        if (st == AG_OK)
            st = ag_plan_add_anchor(p, &a, err);
        if (st != AG_OK)
            goto fail;
    }
    json_t *steps = json_object_get(root, "steps");
    if (steps && !json_is_array(steps)) {
        st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"steps\" must be an array");
        goto fail;
    }
    json_array_foreach(steps, ai, av)
    {
        ag_plan_step sp;
        memset(&sp, 0, sizeof sp);
        json_t *fpts = json_object_get(av, "points");
        json_t *pn = json_object_get(av, "profile");
        sp.profile = json_is_string(pn) ? ag_plan_find_profile(p, json_string_value(pn)) : -1;
        if (fpts) {
            /* a forced step: a polygon in the anchor's frame, or in plan coordinates
             * when no edge is given */
            char what[64];
            snprintf(what, sizeof what, "plan: steps[%zu].points", ai);
            ag_profile_point *pp = NULL;
            size_t n = 0;
            json_t *h = json_object_get(av, "height");
            if (json_object_get(av, "edge")) {
                st = read_anchor(av, "steps", ai, &sp.at, err);
            } else if (!json_is_number(h)) {
                st = ag_error_set(err, AG_ERR_PARSE, (long)ai + 1,
                                  "plan: steps[%zu] needs \"height\" (a number)", ai);
            } else {
                const char *nm = json_string_value(json_object_get(av, "name"));
                snprintf(sp.at.name, sizeof sp.at.name, "%s", nm ? nm : "");
                sp.at.edge = -1;
                sp.at.z = json_number_value(h);
                sp.plan_frame = 1;
            }
            if (st == AG_OK && sp.profile < 0)
                st = ag_error_set(err, AG_ERR_PARSE, (long)ai + 1,
                                  "plan: steps[%zu] needs \"profile\" (a profile name)", ai);
            if (st == AG_OK)
                st = read_points(fpts, what, &pp, &n, err);
            if (st != AG_OK)
                goto fail;
            memcpy(sp.name, sp.at.name, sizeof sp.name);
            double *xy = malloc(2 * n * sizeof *xy);
            if (!xy) {
                free(pp);
                st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
                goto fail;
            }
            for (size_t i = 0; i < n; i++) {
                xy[2 * i] = pp[i].w;
                xy[2 * i + 1] = pp[i].z;
            }
            free(pp);
            sp.npoints = n;
            sp.points = xy;
            st = ag_plan_add_step(p, &sp, err);
            free(xy);
            if (st != AG_OK)
                goto fail;
            continue;
        }
        st = read_anchor(av, "steps", ai, &sp.at, err);
        if (st != AG_OK)
            goto fail;
        memcpy(sp.name, sp.at.name, sizeof sp.name);
        json_t *w = json_object_get(av, "width"), *d = json_object_get(av, "depth");
        if (!json_is_number(w) || !json_is_number(d) || sp.profile < 0) {
            st = ag_error_set(err, AG_ERR_PARSE, (long)ai + 1,
                              "plan: steps[%zu] needs \"width\", \"depth\" (numbers) and "
                              "\"profile\" (a profile name)", ai);
            goto fail;
        }
        sp.width = json_number_value(w);
        sp.depth = json_number_value(d);
        st = ag_plan_add_step(p, &sp, err);
        if (st != AG_OK)
            goto fail;
    }
    st = read_offsets(root, p, err);
    if (st != AG_OK)
        goto fail;
    json_t *cap = json_object_get(root, "cap_height");
    if (cap) {
        if (!json_is_number(cap) || !(json_number_value(cap) >= 0)) {
            st = ag_error_set(err, AG_ERR_PARSE, 0, "plan: \"cap_height\" must be a number >= 0");
            goto fail;
        }
        p->cap_height = json_number_value(cap);
    }
    json_t *pr = json_object_get(root, "priority");
    if (pr) {
        const char *s = json_string_value(pr);
        if (s && strcmp(s, "max_volume") == 0)
            p->priority = AG_PRIORITY_MAX_VOLUME;
        else if (s && strcmp(s, "min_volume") == 0)
            p->priority = AG_PRIORITY_MIN_VOLUME;
        else {
            st = ag_error_set(err, AG_ERR_PARSE, 0,
                              "plan: \"priority\" must be \"max_volume\" or \"min_volume\"");
            goto fail;
        }
    }
    *out = p;
    return AG_OK;
fail:
    ag_plan_free(p);
    return st;
}

static char *slurp(const char *path, size_t *len, ag_error *err, ag_status *st)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        *st = ag_error_set(err, AG_ERR_IO, 0, "cannot open %s", path);
        return NULL;
    }
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (AG_ARRAY_RESERVE_MORE(buf, cap, n, 4096)) { /* room for a read of 4 KiB */
            free(buf);
            fclose(f);
            *st = ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
            return NULL;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (!r)
            break;
    }
    fclose(f);
    *len = n;
    *st = AG_OK;
    return buf;
}

static ag_status read_buffer(const char *data, size_t len, const char *base, ag_plan **out,
                             ag_error *err)
{
    *out = NULL;
    json_error_t je;
    json_t *root = json_loadb(data, len, 0, &je);
    if (!root)
        return ag_error_set(err, AG_ERR_PARSE, je.line, "plan: %s (line %d, column %d)", je.text,
                            je.line, je.column);
    ag_status st = parse_plan(root, base, out, err);
    json_decref(root);
    return st;
}

ag_status ag_plan_json_read_buffer(const char *data, size_t len, ag_plan **out, ag_error *err)
{
    return read_buffer(data, len, NULL, out, err);
}

ag_status ag_plan_json_read_buffer_in(const char *data, size_t len, const char *dir, ag_plan **out,
                                      ag_error *err)
{
    return read_buffer(data, len, dir ? dir : ".", out, err);
}

ag_status ag_plan_json_read_file(const char *path, ag_plan **out, ag_error *err)
{
    *out = NULL;
    size_t len = 0;
    ag_status st;
    char *buf = slurp(path, &len, err, &st);
    if (!buf)
        return st;
    /* mesh files are found next to the plan */
    char base[4096];
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(base, sizeof base, "%.*s", (int)(slash - path), path);
    st = read_buffer(buf, len, slash ? (slash == path ? "/" : base) : ".", out, err);
    free(buf);
    return st;
}

/* --- styles ------------------------------------------------------------------------------ */

static int label_bits(json_t *v, const char *const *names, const uint32_t *bits, uint32_t any,
                      uint32_t *out)
{
    if (!v) {
        *out = any;
        return 1;
    }
    json_t *one = NULL;
    if (json_is_string(v)) {
        one = json_array();
        json_array_append(one, v);
        v = one;
    }
    if (!json_is_array(v)) {
        return 0;
    }
    uint32_t b = 0;
    size_t i;
    json_t *s;
    int ok = 1;
    json_array_foreach(v, i, s)
    {
        const char *t = json_string_value(s);
        int found = 0;
        if (t && strcmp(t, "any") == 0) {
            b |= any;
            found = 1;
        }
        for (int k = 0; t && names[k]; k++)
            if (strcmp(t, names[k]) == 0) {
                b |= bits[k];
                found = 1;
            }
        if (!found)
            ok = 0;
    }
    if (one)
        json_decref(one);
    *out = b;
    return ok;
}

static ag_status parse_style(json_t *root, ag_style *s, ag_error *err)
{
    if (!json_is_object(root))
        return ag_error_set(err, AG_ERR_PARSE, 0, "style: the document must be a JSON object");
    ag_style_builtin("hip", s, NULL); /* defaults */
    s->nprofiles = 0;
    s->nrules = 0;
    const char *nm = json_string_value(json_object_get(root, "name"));
    snprintf(s->name, sizeof s->name, "%s", nm ? nm : "custom");
    json_t *v;
    if ((v = json_object_get(root, "height"))) {
        if (!json_is_number(v) || !(json_number_value(v) > 0))
            return ag_error_set(err, AG_ERR_PARSE, 0, "style: \"height\" must be a number > 0");
        s->height = json_number_value(v);
    }
    if ((v = json_object_get(root, "cap")))
        s->cap = json_is_true(v);
    if ((v = json_object_get(root, "seed")))
        s->seed = (uint64_t)json_integer_value(v);
    if ((v = json_object_get(root, "short_below")) && json_is_number(v))
        s->short_below = json_number_value(v);
    if ((v = json_object_get(root, "long_above")) && json_is_number(v))
        s->long_above = json_number_value(v);
    if ((v = json_object_get(root, "street"))) {
        if (!json_is_array(v) || json_array_size(v) != 2)
            return ag_error_set(err, AG_ERR_PARSE, 0, "style: \"street\" must be [dx, dy]");
        double dx = json_number_value(json_array_get(v, 0)), dy = json_number_value(json_array_get(v, 1));
        double l = hypot(dx, dy);
        if (!(l > 0))
            return ag_error_set(err, AG_ERR_PARSE, 0, "style: \"street\" must not be zero");
        s->has_street = 1;
        s->street_dir[0] = dx / l;
        s->street_dir[1] = dy / l;
    }
    json_t *profiles = json_object_get(root, "profiles");
    if (!json_is_object(profiles) || !json_object_size(profiles))
        return ag_error_set(err, AG_ERR_PARSE, 0, "style: \"profiles\" must be a non-empty object");
    const char *name;
    json_object_foreach(profiles, name, v)
    {
        if (s->nprofiles == AG_STYLE_MAX_PROFILES)
            return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "style: at most %d profiles",
                                AG_STYLE_MAX_PROFILES);
        char what[96];
        snprintf(what, sizeof what, "style: profiles.%s", name);
        ag_profile_point *pp = NULL;
        size_t n = 0;
        ag_status st = read_points(v, what, &pp, &n, err);
        if (st != AG_OK)
            return st;
        if (n > AG_STYLE_MAX_POINTS) {
            free(pp);
            return ag_error_set(err, AG_ERR_TOO_LARGE, 0, "%s: at most %d points", what,
                                AG_STYLE_MAX_POINTS);
        }
        ag_style_profile *sp = &s->profiles[s->nprofiles++];
        snprintf(sp->name, sizeof sp->name, "%s", name);
        sp->npoints = n;
        memcpy(sp->points, pp, n * sizeof *pp);
        free(pp);
    }
    json_t *rules = json_object_get(root, "rules");
    if (!json_is_array(rules) || !json_array_size(rules))
        return ag_error_set(err, AG_ERR_PARSE, 0, "style: \"rules\" must be a non-empty array");
    static const char *const ln[] = {"short", "medium", "long", NULL};
    static const uint32_t lb[] = {AG_LABEL_SHORT, AG_LABEL_MEDIUM, AG_LABEL_LONG};
    static const char *const on[] = {"north", "east", "south", "west", "street", "side", "back", NULL};
    static const uint32_t ob[] = {AG_LABEL_NORTH, AG_LABEL_EAST, AG_LABEL_SOUTH, AG_LABEL_WEST,
                                  AG_LABEL_STREET, AG_LABEL_SIDE, AG_LABEL_BACK};
    static const char *const an[] = {"along", "across", NULL};
    static const uint32_t ab[] = {AG_LABEL_ALONG, AG_LABEL_ACROSS};
    size_t ri;
    json_t *r;
    json_array_foreach(rules, ri, r)
    {
        if (s->nrules == AG_STYLE_MAX_RULES)
            return ag_error_set(err, AG_ERR_TOO_LARGE, (long)ri + 1, "style: at most %d rules",
                                AG_STYLE_MAX_RULES);
        ag_style_rule *ru = &s->rules[s->nrules];
        memset(ru, 0, sizeof *ru);
        uint32_t a, b, c;
        if (!json_is_object(r) ||
            !label_bits(json_object_get(r, "length"), ln, lb, AG_LABEL_ANY_LENGTH, &a) ||
            !label_bits(json_object_get(r, "orientation"), on, ob, AG_LABEL_ANY_ORIENTATION, &b) ||
            !label_bits(json_object_get(r, "axis"), an, ab, AG_LABEL_ANY_AXIS, &c))
            return ag_error_set(err, AG_ERR_PARSE, (long)ri + 1,
                                "style: rules[%zu] has an unknown label (length: short/medium/"
                                "long, orientation: north/east/south/west/street/side/back, "
                                "axis: along/across, or any)", ri);
        ru->labels = a | b | c;
        json_t *choice = json_object_get(r, "profiles");
        if (json_is_string(choice)) {
            json_t *o = json_object();
            json_object_set_new(o, json_string_value(choice), json_real(1));
            choice = o;
        } else {
            json_incref(choice);
        }
        if (!json_is_object(choice) || !json_object_size(choice)) {
            json_decref(choice);
            return ag_error_set(err, AG_ERR_PARSE, (long)ri + 1,
                                "style: rules[%zu].profiles must map profile names to weights", ri);
        }
        const char *pn;
        json_t *w;
        ag_status st = AG_OK;
        json_object_foreach(choice, pn, w)
        {
            size_t k = 0;
            while (k < s->nprofiles && strcmp(s->profiles[k].name, pn) != 0)
                k++;
            if (k == s->nprofiles || !json_is_number(w) || json_number_value(w) < 0 ||
                ru->nchoices == AG_STYLE_MAX_PROFILES) {
                st = ag_error_set(err, AG_ERR_PARSE, (long)ri + 1,
                                  "style: rules[%zu].profiles.%s: unknown profile or bad weight",
                                  ri, pn);
                break;
            }
            ru->profile[ru->nchoices] = (uint32_t)k;
            ru->weight[ru->nchoices] = json_number_value(w);
            ru->nchoices++;
        }
        json_decref(choice);
        if (st != AG_OK)
            return st;
        s->nrules++;
    }
    return AG_OK;
}

ag_status ag_plan_json_read_style_buffer(const char *data, size_t len, ag_style *out,
                                         ag_error *err)
{
    json_error_t je;
    json_t *root = json_loadb(data, len, 0, &je);
    if (!root)
        return ag_error_set(err, AG_ERR_PARSE, je.line, "style: %s (line %d, column %d)", je.text,
                            je.line, je.column);
    ag_status st = parse_style(root, out, err);
    json_decref(root);
    return st;
}

ag_status ag_plan_json_read_style_file(const char *path, ag_style *out, ag_error *err)
{
    size_t len = 0;
    ag_status st;
    char *buf = slurp(path, &len, err, &st);
    if (!buf)
        return st;
    st = ag_plan_json_read_style_buffer(buf, len, out, err);
    free(buf);
    return st;
}
