#include "extrude.h"

#include <string.h>

#include "verify.h"

/* The budget's verdict as the extrusion's error. */
static ag_status over_budget(const ag_budget *b, const char *stage, ag_error *err)
{
    return ag_error_set(err, b->st, 0, "the extrusion was %s, %s", b->why, stage);
}

ag_status ag_extrude_plan_with(ag_plan *plan, const ag_extrude_options *opt, ag_mesh *m,
                               int32_t group, ag_extrude_result *res, ag_shell **keep_shell,
                               ag_error *err)
{
    ag_extrude_result local;
    if (!res)
        res = &local;
    memset(res, 0, sizeof *res);
    if (keep_shell)
        *keep_shell = NULL;
    size_t corners = 0;
    for (size_t L = 0; L < plan->nloops; L++)
        corners += plan->loops[L].n;
    ag_budget budget;
    ag_budget_start(&budget, opt ? &opt->budget : NULL, corners);
    if (ag_budget_poll(&budget, 0) != AG_OK)
        return over_budget(&budget, "before it started", err);
    ag_plan_fixes fixes = {0};
    double extent = 0;
    ag_status st = ag_plan_validate(plan, &fixes, &extent, err);
    res->nfixes = fixes.n;
    if (opt && opt->fixes)
        *opt->fixes = fixes;
    else
        ag_plan_fixes_free(&fixes);
    if (st != AG_OK)
        return st;
    if (ag_budget_poll(&budget, 0) != AG_OK)
        return over_budget(&budget, "after validating the plan", err);
    ag_shell *sh = NULL;
    ag_skeleton_options so = {&budget, plan->anchors, opt && opt->no_winding_repair};
    st = ag_skeleton_build(plan, extent, &so, &sh, &res->stats, err);
    if (st != AG_OK)
        return st;
    res->failing_faces = ag_shell_check(sh, res->problems, AG_EXTRUDE_MAX_PROBLEMS);
    for (size_t f = 0; f < sh->nfaces; f++)
        if (sh->faces[f].nloops & 0x7fffffffu)
            res->faces++;
    res->top = res->stats.top;
    res->volume = ag_shell_volume(sh);
    size_t comp = 0, t0 = m->ntris;
    st = ag_budget_poll(&budget, 0);
    if (st != AG_OK) {
        ag_shell_free(sh);
        return over_budget(&budget, "before triangulating the shell", err);
    }
    st = ag_mesh_add_component(m, group, &comp);
    if (st == AG_OK)
        st = ag_shell_to_mesh(sh, m, (uint32_t)comp, &res->triangles);
    if (st != AG_OK)
        ag_error_set(err, st, 0, "out of memory");
    if (st == AG_OK)
        ag_verify_building(m, t0, m->ntris, plan, res->defect, sizeof res->defect);
    if (keep_shell && st == AG_OK)
        *keep_shell = sh;
    else
        ag_shell_free(sh);
    res->seconds = ag_budget_elapsed(&budget);
    return st;
}

int ag_extrude_result_ok(const ag_extrude_result *res)
{
    return res->failing_faces == 0 && !res->defect[0];
}

ag_status ag_extrude_plan(ag_plan *plan, ag_mesh *m, int32_t group, ag_extrude_result *res,
                          ag_shell **keep_shell, ag_error *err)
{
    return ag_extrude_plan_with(plan, NULL, m, group, res, keep_shell, err);
}

ag_status ag_extrude_place_meshes(const ag_plan *plan, ag_mesh *m, int32_t group, size_t *placed,
                                  ag_error *err)
{
    if (placed)
        *placed = 0;
    for (size_t i = 0; i < plan->nanchors; i++) {
        const ag_anchor *a = &plan->anchors[i];
        if (!a->found || a->mesh <= 0 || (size_t)a->mesh > plan->nmeshes)
            continue;
        const ag_mesh *src = plan->meshes[a->mesh - 1].mesh;
        const double *t = a->tangent, *n = a->normal;
        /* up = n x t: in the face's plane, perpendicular to the edge, rising */
        double up[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2],
                        n[0] * t[1] - n[1] * t[0]};
        size_t comp = 0;
        uint32_t v0 = (uint32_t)m->nverts;
        ag_status st = ag_mesh_add_component(m, group, &comp);
        if (st == AG_OK)
            st = ag_mesh_reserve(m, m->nverts + src->nverts, m->ntris + src->ntris);
        for (size_t v = 0; v < src->nverts && st == AG_OK; v++) {
            const double *p = &src->pos[3 * v];
            double q[3];
            for (int k = 0; k < 3; k++)
                q[k] = a->pos[k] + p[0] * t[k] - p[1] * n[k] + p[2] * up[k];
            st = ag_mesh_add_vertex(m, q[0], q[1], q[2]);
        }
        for (size_t f = 0; f < src->ntris && st == AG_OK; f++)
            st = ag_mesh_add_triangle(m, v0 + src->tri[3 * f], v0 + src->tri[3 * f + 1],
                                      v0 + src->tri[3 * f + 2], (uint32_t)comp);
        if (st != AG_OK)
            return ag_error_set(err, st, 0, "out of memory");
        if (placed)
            (*placed)++;
    }
    return AG_OK;
}
