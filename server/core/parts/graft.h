/* A composition's new model without proceduralizing again (paper §4.2): the target model's
 * split tree with the part's components grafted in.
 *
 * The composed grammar (compose.h) derives `derived`; `in` is the model it was composed into.
 * The sites changed are the target (scope node) or every visible node of the target's rule
 * class (scope rule); replace removes a site with its subtree, fill removes what lies below a
 * site, insert removes nothing. Every other visible node of in's tree stays with its id and
 * its component of in's mesh; the derivation's components are paired with those by box, and
 * the ones left over are what the part brought: nested among themselves as the split tree
 * nests components (ag_splittree_build on them alone), hung under their site (replace: under
 * the site's nearest visible ancestor that holds them), their geometry taken from the
 * derivation. A new component in a group "L<k>" naming one of in's labels keeps that label;
 * the others get one new label per group; variants are exact shapes (the geometry relative to
 * its box, turned by quarter turns or not: a part composed onto facades facing other ways
 * keeps one terminal), one of in's variants of the label where shape and size are its. A kept
 * component's pair must cover the same surface (area and centroid, within the variant's
 * certified deviation). The tree is then rebuilt (rebuild.h: chains, mesh, rules, patterns, grammar), so
 * the result is the model the derivation proceduralized would be, with in's node ids kept.
 *
 * When the derivation does not pair that way (a kept component missing or moved, a new one
 * outside every site, a site without a rule class for scope rule) the graft does not apply:
 * AG_ERR_NOT_AVAILABLE naming the reason; the caller proceduralizes the derivation instead. */
#ifndef AG_GRAFT_H
#define AG_GRAFT_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../proc/proceduralize.h"
#include "../status.h"
#include "compose.h"

typedef struct {
    size_t sites;   /* nodes of in's tree the composition changed */
    size_t kept;    /* visible nodes kept (their ids unchanged) */
    size_t removed; /* visible nodes removed */
    size_t added;   /* components the part brought (new nodes) */
    /* where the graft spent its time (ms): the derivation's components measured, the tree
     * copied with the sites removed, the components paired, the new ones classified (sites,
     * labels, variants), inserted, the rebuild's input made, the rebuild */
    double components_ms, removal_ms, pair_ms, classify_ms, insert_ms, input_ms, rebuild_ms;
} ag_graft_report;

ag_status ag_graft_compose(const ag_proceduralize_result *in, const ag_compose_op *op,
                           const ag_mesh *derived, const ag_patterns_options *popt,
                           ag_proceduralize_result **out, ag_graft_report *rep,
                           ag_error *err);

#endif
