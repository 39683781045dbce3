#include "plan_write.h"

#include <string.h>

static json_t *pair(double a, double b)
{
    return json_pack("[f,f]", a, b);
}

/* The members an anchor and a step share: name, loop, edge, relative|absolute, height. */
static void put_anchor(json_t *o, const char *name, const ag_anchor *a)
{
    if (name && *name)
        json_object_set_new(o, "name", json_string(name));
    json_object_set_new(o, "loop", json_integer(a->loop));
    json_object_set_new(o, "edge", json_integer(a->edge));
    json_object_set_new(o, a->absolute ? "absolute" : "relative", json_real(a->along));
    json_object_set_new(o, "height", json_real(a->z));
}

ag_status ag_plan_write_json(const ag_plan *p, json_t **out, ag_error *err)
{
    *out = NULL;
    json_t *root = json_object(), *profiles = json_object(), *loops = json_array();
    if (!root || !profiles || !loops) {
        json_decref(root);
        json_decref(profiles);
        json_decref(loops);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    json_object_set_new(root, "profiles", profiles);
    json_object_set_new(root, "loops", loops);
    ag_status st = AG_OK;
    for (size_t i = 0; i < p->nprofiles && st == AG_OK; i++) {
        const ag_profile *pr = &p->profiles[i];
        if (json_object_get(profiles, pr->name)) {
            st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                              "plan: two profiles are named \"%s\"", pr->name);
            break;
        }
        json_t *pts = json_array();
        for (size_t k = 0; k < pr->npoints; k++)
            json_array_append_new(pts, pair(pr->points[k].w, pr->points[k].z));
        json_t *o = json_pack("{s:o}", "points", pts);
        if (pr->tag)
            json_object_set_new(o, "tag", json_string(pr->tag));
        if (pr->priority)
            json_object_set_new(o, "priority", json_integer(pr->priority));
        json_object_set_new(profiles, pr->name, o);
    }
    for (size_t L = 0; L < p->nloops && st == AG_OK; L++) {
        const ag_plan_loop *l = &p->loops[L];
        json_t *pts = json_array(), *names = json_array();
        for (size_t i = 0; i < l->n; i++) {
            json_array_append_new(pts, pair(l->xy[2 * i], l->xy[2 * i + 1]));
            int32_t k = l->profile ? l->profile[i] : 0;
            if (k < 0 || (size_t)k >= p->nprofiles) {
                st = ag_error_set(err, AG_ERR_INVALID, (long)L + 1,
                                  "plan: loop %zu edge %zu names no profile", L, i);
                break;
            }
            json_array_append_new(names, json_string(p->profiles[k].name));
        }
        json_array_append_new(loops, json_pack("{s:o,s:o}", "points", pts, "profiles", names));
    }
    if (st == AG_OK && p->nanchors) {
        json_t *a = json_array();
        for (size_t i = 0; i < p->nanchors; i++) {
            json_t *o = json_object();
            put_anchor(o, p->anchors[i].name, &p->anchors[i]);
            json_array_append_new(a, o);
        }
        json_object_set_new(root, "anchors", a);
    }
    if (st == AG_OK && p->nsteps) {
        json_t *a = json_array();
        for (size_t i = 0; i < p->nsteps && st == AG_OK; i++) {
            const ag_plan_step *s = &p->steps[i];
            if (s->profile < 0 || (size_t)s->profile >= p->nprofiles) {
                st = ag_error_set(err, AG_ERR_INVALID, (long)i + 1,
                                  "plan: step %zu names no profile", i);
                break;
            }
            json_t *o = json_object();
            put_anchor(o, s->name, &s->at);
            json_object_set_new(o, "width", json_real(s->width));
            json_object_set_new(o, "depth", json_real(s->depth));
            json_object_set_new(o, "profile", json_string(p->profiles[s->profile].name));
            json_array_append_new(a, o);
        }
        json_object_set_new(root, "steps", a);
    }
    if (p->cap_height > 0)
        json_object_set_new(root, "cap_height", json_real(p->cap_height));
    json_object_set_new(root, "priority", json_string(p->priority == AG_PRIORITY_MIN_VOLUME
                                                          ? "min_volume"
                                                          : "max_volume"));
    if (st != AG_OK) {
        json_decref(root);
        return st;
    }
    *out = root;
    return AG_OK;
}
