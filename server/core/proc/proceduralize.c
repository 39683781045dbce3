#include "proceduralize.h"

#include <stdlib.h>

#include "../base/clock.h"
#include "../base/tolerance.h"

const char *ag_proceduralize_stage_name(ag_stage s)
{
    static const char *names[] = {"segment", "label", "tree", "rules",
                                  "patterns", "export", "verify"};
    return s < AG_STAGE_COUNT ? names[s] : "?";
}

void ag_proceduralize_result_free(ag_proceduralize_result *r)
{
    if (!r)
        return;
    ag_mesh_free(r->mesh);
    ag_labels_free(r->labels);
    ag_splittree_free(r->tree);
    ag_grammar_free(r->grammar);
    ag_grammar_export_info_free(&r->info);
    free(r);
}

ag_status ag_proceduralize_run(const ag_mesh *in, const ag_proceduralize_options *opt,
                               ag_proceduralize_result **out, ag_error *err)
{
    ag_proceduralize_options o = opt ? *opt : (ag_proceduralize_options){0};
    *out = NULL;
    ag_proceduralize_result *r = calloc(1, sizeof *r);
    if (!r)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    ag_status st = AG_OK;
    double t0;
#define STAGE(s, call)                                                                 \
    do {                                                                               \
        if (o.progress && o.progress(o.user, s)) {                                     \
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled before %s",        \
                              ag_proceduralize_stage_name(s));                         \
            goto fail;                                                                 \
        }                                                                              \
        t0 = ag_clock_seconds();                                                       \
        st = (call);                                                                   \
        r->seconds[s] = ag_clock_seconds() - t0;                                       \
        if (st)                                                                        \
            goto fail;                                                                 \
    } while (0)

    STAGE(AG_STAGE_SEGMENT, ag_segment_run(in, &o.segment, &r->mesh, &r->segment, err));
    STAGE(AG_STAGE_LABEL, ag_label_components(r->mesh, &o.label, &r->labels, err));
    STAGE(AG_STAGE_TREE, ag_splittree_build(r->mesh, r->labels, &r->tree, err));
    STAGE(AG_STAGE_RULES, ag_rules_label(r->tree, err));
    STAGE(AG_STAGE_PATTERNS, ag_patterns_find(r->tree, &o.patterns, err));
    STAGE(AG_STAGE_EXPORT,
          ag_grammar_export(r->mesh, r->labels, r->tree, &r->grammar, &r->info, err));
    if (o.verify) {
        ag_mesh *d = NULL;
        if (o.progress && o.progress(o.user, AG_STAGE_VERIFY)) {
            st = ag_error_set(err, AG_ERR_CANCELLED, 0, "cancelled before verify");
            goto fail;
        }
        t0 = ag_clock_seconds();
        st = ag_grammar_derive(r->grammar, NULL, &d, err);
        if (!st)
            st = ag_grammar_fidelity(r->mesh, d, AG_PROC_VERIFY_FACTOR * r->labels->tol,
                                     &r->fidelity, err);
        ag_mesh_free(d);
        r->seconds[AG_STAGE_VERIFY] = ag_clock_seconds() - t0;
        if (st)
            goto fail;
    }
#undef STAGE
    *out = r;
    return AG_OK;
fail:
    ag_proceduralize_result_free(r);
    return st;
}
