/* Composition of a part into a building (paper §4.2) as graph rewriting of its grammar.
 *
 * The target is a split-tree node of the target model (ids of model->tree); its site in the
 * grammar (trace.h) is the body node its content hangs on. The rewrite:
 * - scope node: the target is separated from the production of every rule above it: each rule
 *   on the path from the axiom that other instances share is cloned (a pattern holding the
 *   path is expanded into its cells, the one on the path applying the clone), so the other
 *   products of those rules continue as before; the change is made in the target's own body.
 * - scope rule: the body of the target's rule is rewritten, so every instance changes (a
 *   terminal target is first wrapped in a rule that replaces its every application). A target
 *   whose content is inlined in a larger rule has no rule of its own: AG_ERR_INVALID.
 * - modes: replace — the target's statements (its own and its descendants') give way to one
 *   application of the part; insert — the target keeps its own applications, and a new rule
 *   made of the part followed by the target's children stands between them (the children hang
 *   below the part); fill — the target keeps its own applications, its children give way to a
 *   grid of the part (a subdivide over the target's box along its two longest axes, counts =
 *   the box over the part's size rounded, at least 1; along the third axis the part keeps its
 *   depth, flush with the face the target faces or centred).
 * - the part's rules and terminals are instantiated: shared with the target's where identical
 *   (same size, same statements, same geometry), kept under their names where free, renamed
 *   name_2, name_3, ... where they clash. Terminals brought in are labelled "<part>_<label>".
 * - the part is turned by quarter turns from the way it faced in its building to the way the
 *   target faces (ag_place_facing), and fitted into the target's box (or a fill cell) by
 *   fit.h: contacts kept, thin members keep their sizes, repeated columns (a facade's
 *   windows) re-counted at their own size and period (fitcount.h).
 * The result is a new resolved grammar (terminals with geometry) that derives, prints and
 * parses like any other; target and part are not changed. Deterministic: a pure function of
 * the target grammar and tree, the part, the node, the mode and the scope. */
#ifndef AG_COMPOSE_H
#define AG_COMPOSE_H

#include <stddef.h>
#include <stdint.h>

#include "../proc/proceduralize.h"
#include "../status.h"
#include "fit.h"
#include "part.h"

typedef enum { AG_COMPOSE_REPLACE = 0, AG_COMPOSE_INSERT = 1, AG_COMPOSE_FILL = 2 } ag_compose_mode;
typedef enum { AG_COMPOSE_NODE = 0, AG_COMPOSE_RULE = 1 } ag_compose_scope;

/* "replace" / "insert" / "fill", "node" / "rule"; -1 for another word. */
int ag_compose_mode_parse(const char *s);
int ag_compose_scope_parse(const char *s);
const char *ag_compose_mode_name(int mode);
const char *ag_compose_scope_name(int scope);

#define AG_COMPOSE_MAX_EXPANDED_CELLS 100000
#define AG_COMPOSE_MAX_FILL_CELLS 1000000

typedef struct {
    int32_t target;   /* node of the target model's tree */
    int mode;         /* ag_compose_mode */
    int scope;        /* ag_compose_scope */
} ag_compose_op;

typedef struct {
    char root[64];          /* the rule the part's fitted root became */
    char target_rule[64];   /* scope rule: the rewritten rule; "" otherwise */
    size_t instances;       /* target instances changed */
    size_t rules_added, rules_shared, terminals_added, terminals_shared, renamed;
    size_t cloned, expanded_cells; /* scope node: rules cloned, pattern cells expanded */
    unsigned counts[3];     /* fill: the grid */
    int turn;               /* quarter turns from the part's facing to the target's */
    double fitted[3];       /* the size the part was fitted to (its own axes) */
    ag_fit_report fit;
    char message[512];
    /* how a service made the new model from the composed grammar (app/usecase_compose.h;
     * ag_compose leaves them 0): 1 when the part was grafted into the model's tree
     * (graft.h), else its derivation was proceduralized, for the reason in fallback */
    int grafted;
    char fallback[160];
} ag_compose_report;

ag_status ag_compose(const ag_proceduralize_result *target, const ag_part *part,
                     const ag_compose_op *op, ag_grammar **out, ag_compose_report *rep,
                     ag_error *err);
/* ag_compose with target->grammar's trace (trace.h) given, NULL: traced here. */
ag_status ag_compose_traced(const ag_proceduralize_result *target, const ag_trace *trace,
                            const ag_part *part, const ag_compose_op *op, ag_grammar **out,
                            ag_compose_report *rep, ag_error *err);

#endif
