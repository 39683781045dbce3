#include "plan_write.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* The first failure wins; later builders see it and do nothing, so the code below can
 * build the whole document without checking every call. */
typedef struct {
    ag_status st;
    ag_error *err;
} writer;

static void fail(writer *w, ag_status code, long element, const char *fmt, ...)
{
    if (w->st != AG_OK)
        return;
    char text[sizeof w->err->text];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    w->st = ag_error_set(w->err, code, element, "%s", text);
}

static void nomem(writer *w)
{
    fail(w, AG_ERR_NOMEM, 0, "out of memory");
}

/* jansson refuses NaN/inf; say which value it was rather than drop it. */
static json_t *num(writer *w, double v, const char *what)
{
    if (!isfinite(v)) {
        fail(w, AG_ERR_INVALID, 0, "plan: %s is not a finite number", what);
        return NULL;
    }
    json_t *j = json_real(v);
    if (!j)
        nomem(w);
    return j;
}

static json_t *str(writer *w, const char *s, const char *what)
{
    json_t *j = json_string(s);
    if (!j) {
        /* json_string fails for bad UTF-8 or no memory: tell them apart */
        json_t *probe = json_string_nocheck(s);
        if (probe)
            fail(w, AG_ERR_INVALID, 0, "plan: %s is not valid UTF-8", what);
        else
            nomem(w);
        json_decref(probe);
    }
    return j;
}

static json_t *integer(writer *w, json_int_t v)
{
    json_t *j = json_integer(v);
    if (!j)
        nomem(w);
    return j;
}

static json_t *container(writer *w, json_t *j)
{
    if (!j)
        nomem(w);
    return j;
}

/* Takes v (also on failure); NULL v means its builder already failed. */
static void set(writer *w, json_t *o, const char *key, json_t *v)
{
    if (!v || !o) {
        json_decref(v);
        if (w->st == AG_OK)
            nomem(w);
        return;
    }
    if (json_object_set_new(o, key, v) != 0)
        nomem(w);
}

static void append(writer *w, json_t *a, json_t *v)
{
    if (!v || !a) {
        json_decref(v);
        if (w->st == AG_OK)
            nomem(w);
        return;
    }
    if (json_array_append_new(a, v) != 0)
        nomem(w);
}

static json_t *pair(writer *w, double a, double b, const char *what)
{
    json_t *arr = container(w, json_array());
    append(w, arr, num(w, a, what));
    append(w, arr, num(w, b, what));
    return arr;
}

static json_t *profile_name(writer *w, const ag_plan *p, int32_t k, const char *what)
{
    if (k < 0 || (size_t)k >= p->nprofiles) {
        fail(w, AG_ERR_INVALID, 0, "plan: %s names no profile (%d)", what, (int)k);
        return NULL;
    }
    return str(w, p->profiles[k].name, what);
}

/* The members an anchor and a step share: name, loop, edge, relative|absolute, height. */
static void put_anchor(writer *w, json_t *o, const char *name, const ag_anchor *a,
                       const char *what)
{
    if (name && *name)
        set(w, o, "name", str(w, name, what));
    set(w, o, "loop", integer(w, a->loop));
    set(w, o, "edge", integer(w, a->edge));
    set(w, o, a->absolute ? "absolute" : "relative", num(w, a->along, what));
    set(w, o, "height", num(w, a->z, what));
}

static void put_profiles(writer *w, const ag_plan *p, json_t *root)
{
    json_t *profiles = container(w, json_object());
    set(w, root, "profiles", profiles);
    for (size_t i = 0; i < p->nprofiles && w->st == AG_OK; i++) {
        const ag_profile *pr = &p->profiles[i];
        char what[96];
        snprintf(what, sizeof what, "profile %zu", i);
        if (!pr->name) {
            fail(w, AG_ERR_INVALID, (long)i + 1, "plan: %s has no name", what);
            break;
        }
        if (json_object_get(profiles, pr->name)) {
            fail(w, AG_ERR_INVALID, (long)i + 1, "plan: two profiles are named \"%s\"", pr->name);
            break;
        }
        json_t *o = container(w, json_object()), *pts = container(w, json_array());
        set(w, o, "points", pts);
        for (size_t k = 0; k < pr->npoints; k++)
            append(w, pts, pair(w, pr->points[k].w, pr->points[k].z, what));
        if (pr->tag)
            set(w, o, "tag", str(w, pr->tag, what));
        if (pr->priority)
            set(w, o, "priority", integer(w, pr->priority));
        if (pr->seg_priority && pr->npoints > 1) {
            json_t *sp = container(w, json_array());
            set(w, o, "segment_priority", sp);
            for (size_t k = 0; k + 1 < pr->npoints; k++)
                append(w, sp, integer(w, pr->seg_priority[k]));
        }
        /* object keys must be UTF-8 too: str() tells that from a lack of memory */
        json_t *key = str(w, pr->name, what);
        json_decref(key);
        if (w->st != AG_OK) {
            json_decref(o);
            break;
        }
        set(w, profiles, pr->name, o);
    }
}

static void put_loops(writer *w, const ag_plan *p, json_t *root)
{
    json_t *loops = container(w, json_array());
    set(w, root, "loops", loops);
    for (size_t L = 0; L < p->nloops && w->st == AG_OK; L++) {
        const ag_plan_loop *l = &p->loops[L];
        char what[64], ewhat[64];
        snprintf(what, sizeof what, "loop %zu", L);
        json_t *o = container(w, json_object());
        json_t *pts = container(w, json_array()), *names = container(w, json_array());
        set(w, o, "points", pts);
        set(w, o, "profiles", names);
        append(w, loops, o);
        for (size_t i = 0; i < l->n && w->st == AG_OK; i++) {
            append(w, pts, pair(w, l->xy[2 * i], l->xy[2 * i + 1], what));
            snprintf(ewhat, sizeof ewhat, "loop %zu edge %zu", L, i);
            append(w, names, profile_name(w, p, l->profile ? l->profile[i] : 0, ewhat));
        }
    }
}

static void put_meshes(writer *w, const ag_plan *p, const ag_plan_write_options *opt,
                       json_t *root)
{
    if (!p->nmeshes || w->st != AG_OK)
        return;
    if (!opt || !opt->mesh_files) {
        fail(w, AG_ERR_INVALID, 1, "plan: mesh %s has no file to name (give mesh_files)",
             p->meshes[0].name);
        return;
    }
    json_t *ms = container(w, json_object());
    set(w, root, "meshes", ms);
    for (size_t i = 0; i < p->nmeshes && w->st == AG_OK; i++) {
        const ag_plan_mesh *m = &p->meshes[i];
        const ag_plan_mesh_file *f = &opt->mesh_files[i];
        if (!f->path || !*f->path) {
            fail(w, AG_ERR_INVALID, (long)i + 1, "plan: mesh %s has no file to name", m->name);
            break;
        }
        if (json_object_get(ms, m->name)) {
            fail(w, AG_ERR_INVALID, (long)i + 1, "plan: two meshes are named \"%s\"", m->name);
            break;
        }
        char what[64];
        snprintf(what, sizeof what, "mesh %zu", i);
        json_t *v;
        if (f->up == AG_UP_Z) {
            v = container(w, json_object());
            set(w, v, "path", str(w, f->path, what));
            set(w, v, "up", str(w, "z", what));
        } else {
            v = str(w, f->path, what); /* y up: the reader's default */
        }
        json_t *key = str(w, m->name, what);
        json_decref(key);
        if (w->st != AG_OK) {
            json_decref(v);
            break;
        }
        set(w, ms, m->name, v);
    }
}

static void put_anchors(writer *w, const ag_plan *p, json_t *root)
{
    if (!p->nanchors || w->st != AG_OK)
        return;
    json_t *arr = container(w, json_array());
    set(w, root, "anchors", arr);
    for (size_t i = 0; i < p->nanchors && w->st == AG_OK; i++) {
        const ag_anchor *a = &p->anchors[i];
        char what[64];
        snprintf(what, sizeof what, "anchor %zu", i);
        json_t *o = container(w, json_object());
        append(w, arr, o);
        put_anchor(w, o, a->name, a, what);
        if (a->mesh < 0 || (size_t)a->mesh > p->nmeshes)
            fail(w, AG_ERR_INVALID, (long)i + 1, "plan: anchor %zu names no mesh (%d)", i,
                 (int)a->mesh);
        else if (a->mesh > 0)
            set(w, o, "mesh", str(w, p->meshes[a->mesh - 1].name, what));
    }
}

static void put_steps(writer *w, const ag_plan *p, json_t *root)
{
    if (!p->nsteps || w->st != AG_OK)
        return;
    json_t *arr = container(w, json_array());
    set(w, root, "steps", arr);
    for (size_t i = 0; i < p->nsteps && w->st == AG_OK; i++) {
        const ag_plan_step *s = &p->steps[i];
        char what[64];
        snprintf(what, sizeof what, "step %zu", i);
        json_t *o = container(w, json_object());
        append(w, arr, o);
        if (s->npoints && s->plan_frame) {
            /* plan coordinates: no edge, only the height of the anchor counts */
            if (*s->name)
                set(w, o, "name", str(w, s->name, what));
            set(w, o, "height", num(w, s->at.z, what));
        } else {
            put_anchor(w, o, s->name, &s->at, what);
        }
        if (s->npoints) {
            json_t *pts = container(w, json_array());
            set(w, o, "points", pts);
            for (size_t k = 0; k < s->npoints; k++)
                append(w, pts, pair(w, s->points[2 * k], s->points[2 * k + 1], what));
        } else {
            set(w, o, "width", num(w, s->width, what));
            set(w, o, "depth", num(w, s->depth, what));
        }
        set(w, o, "profile", profile_name(w, p, s->profile, what));
    }
}

/* -1 means "the event's" (or "none" for side): the member is left out. */
static void put_opt_profile(writer *w, const ag_plan *p, json_t *o, const char *key, int32_t k,
                            const char *what)
{
    if (k >= 0)
        set(w, o, key, profile_name(w, p, k, what));
    else if (k != -1)
        fail(w, AG_ERR_INVALID, 0, "plan: %s names no profile (%d)", what, (int)k);
}

/* "inside": {"gap": [from, to], "profile", "inner"} of an event or an edge (-1: unset) */
static void put_inside(writer *w, const ag_plan *p, json_t *o, int has_gap, double from,
                       double to, int32_t inside, int32_t inner, const char *what)
{
    json_t *in = container(w, json_object());
    set(w, o, "inside", in);
    if (has_gap) {
        json_t *gap = container(w, json_array());
        set(w, in, "gap", gap);
        append(w, gap, num(w, from, what));
        append(w, gap, num(w, to, what));
    }
    put_opt_profile(w, p, in, "profile", inside, what);
    put_opt_profile(w, p, in, "inner", inner, what);
}

static void put_offsets(writer *w, const ag_plan *p, json_t *root)
{
    if (!p->noffsets || w->st != AG_OK)
        return;
    json_t *arr = container(w, json_array());
    set(w, root, "offsets", arr);
    for (size_t i = 0; i < p->noffsets && w->st == AG_OK; i++) {
        const ag_plan_offset *of = &p->offsets[i];
        char what[64];
        snprintf(what, sizeof what, "offset %zu", i);
        json_t *o = container(w, json_object());
        append(w, arr, o);
        set(w, o, "height", num(w, of->z, what));
        set(w, o, "outside", num(w, of->outside, what));
        put_opt_profile(w, p, o, "profile", of->profile, what);
        put_opt_profile(w, p, o, "side", of->side, what);
        if (of->has_gap)
            put_inside(w, p, o, 1, of->gap_from, of->gap_to, of->inside, of->inner, what);
        if (!of->nedges)
            continue;
        json_t *edges = container(w, json_array());
        set(w, o, "edges", edges);
        for (size_t k = 0; k < of->nedges && w->st == AG_OK; k++) {
            const ag_offset_edge *e = &of->edges[k];
            snprintf(what, sizeof what, "offset %zu edge %zu", i, k);
            json_t *eo = container(w, json_object());
            append(w, edges, eo);
            set(w, eo, "loop", integer(w, e->loop));
            set(w, eo, "edge", integer(w, e->edge));
            if (e->disabled)
                set(w, eo, "disabled", container(w, json_true()));
            if (e->has_outside)
                set(w, eo, "outside", num(w, e->outside, what));
            put_opt_profile(w, p, eo, "profile", e->profile, what);
            /* an edge's inside profiles are stored as 1 + index, 0 meaning the event's */
            if (e->has_gap || e->inside || e->inner)
                put_inside(w, p, eo, e->has_gap, e->gap_from, e->gap_to, e->inside - 1,
                           e->inner - 1, what);
        }
    }
}

ag_status ag_plan_write_json_opts(const ag_plan *p, const ag_plan_write_options *opt,
                                  json_t **out, ag_error *err)
{
    *out = NULL;
    writer w = {AG_OK, err};
    /* members in the order the reader needs them: meshes before the anchors naming them */
    json_t *root = container(&w, json_object());
    put_profiles(&w, p, root);
    put_loops(&w, p, root);
    put_meshes(&w, p, opt, root);
    put_anchors(&w, p, root);
    put_steps(&w, p, root);
    put_offsets(&w, p, root);
    if (p->cap_height > 0 || !isfinite(p->cap_height))
        set(&w, root, "cap_height", num(&w, p->cap_height, "cap_height"));
    set(&w, root, "priority",
        str(&w, p->priority == AG_PRIORITY_MIN_VOLUME ? "min_volume" : "max_volume", "priority"));
    if (w.st != AG_OK) {
        json_decref(root);
        return w.st;
    }
    *out = root;
    return AG_OK;
}

ag_status ag_plan_write_json(const ag_plan *p, json_t **out, ag_error *err)
{
    return ag_plan_write_json_opts(p, NULL, out, err);
}
