#include "extrude.h"

#include <string.h>

ag_status ag_extrude_plan(ag_plan *plan, ag_mesh *m, int32_t group, ag_extrude_result *res,
                          ag_shell **keep_shell, ag_error *err)
{
    ag_extrude_result local;
    if (!res)
        res = &local;
    memset(res, 0, sizeof *res);
    if (keep_shell)
        *keep_shell = NULL;
    ag_plan_fixes fixes = {0};
    double extent = 0;
    ag_status st = ag_plan_validate(plan, &fixes, &extent, err);
    res->nfixes = fixes.n;
    ag_plan_fixes_free(&fixes);
    if (st != AG_OK)
        return st;
    ag_shell *sh = NULL;
    ag_skeleton_options so = {0, plan->anchors};
    st = ag_skeleton_build(plan, extent, &so, &sh, &res->stats, err);
    if (st != AG_OK)
        return st;
    res->failing_faces = ag_shell_check(sh, res->problems, AG_EXTRUDE_MAX_PROBLEMS);
    for (size_t f = 0; f < sh->nfaces; f++)
        if (sh->faces[f].nloops & 0x7fffffffu)
            res->faces++;
    res->top = res->stats.top;
    res->volume = ag_shell_volume(sh);
    size_t comp = 0;
    st = ag_mesh_add_component(m, group, &comp);
    if (st == AG_OK)
        st = ag_shell_to_mesh(sh, m, (uint32_t)comp, &res->triangles);
    if (st != AG_OK)
        ag_error_set(err, st, 0, "out of memory");
    if (keep_shell && st == AG_OK)
        *keep_shell = sh;
    else
        ag_shell_free(sh);
    return st;
}
