/* The derivation of a grammar as a tree of instances, so that split-tree nodes can be named in
 * grammar terms (the paper's node(p): the command that produced a primitive).
 *
 * An instance is one application of a rule body (the axiom is instance 0): its rule, the
 * instance and statement that applied it (and the pattern cell), the frame that maps its local
 * box to the world and its total quarter turns (frames are per-axis scales after quarter
 * turns, so turns add up along a path). A site is one body node (`p` or a split node) of one
 * instance, with its box in the body's local coordinates and in the world. A split-tree node of
 * a model proceduralized from the grammar is found as the outermost site whose world box is the
 * node's box and under which exactly as many terminals are placed as the node's subtree holds
 * components. */
#ifndef AG_TRACE_H
#define AG_TRACE_H

#include <stddef.h>
#include <stdint.h>

#include "../proc/gframe.h"
#include "../proc/grammar.h"
#include "../proc/proceduralize.h"
#include "../status.h"

typedef struct {
    int32_t rule;        /* grammar rule index, -1 for the axiom */
    int32_t parent;      /* applying instance, -1 for the axiom */
    int32_t stmt;        /* statement of the parent's body that applied it */
    uint32_t cell;       /* pattern cell index of that statement, else 0 */
    int rot;             /* total quarter turns, local to world */
    uint32_t depth;
    ag_gframe frame;     /* local to world */
    size_t site0;        /* its body nodes are sites site0 .. site0 + nnodes - 1 */
    int32_t first_child, next_sibling;
    size_t terminals;    /* terminal placements in the instance, nested ones included */
} ag_trace_instance;

typedef struct {
    size_t ninstances;
    ag_trace_instance *inst;
    size_t nsites;
    ag_box *local, *world;  /* per site */
    size_t nrules;
    size_t *uses;           /* per rule: instances */
} ag_trace;

typedef struct {
    int32_t instance;
    int32_t node;           /* body node index (0 = p) */
} ag_trace_site;

/* Limits of a trace: at most max_instances applications of rules (0 = 5 million). */
ag_status ag_trace_build(const ag_grammar *g, size_t max_instances, ag_trace **out,
                         ag_error *err);
void ag_trace_free(ag_trace *t);

/* The body of an instance. */
const ag_grule *ag_trace_body(const ag_grammar *g, const ag_trace_instance *in);
/* Terminal placements under one site (its own applications and those of nested bodies). */
size_t ag_trace_site_terminals(const ag_trace *t, const ag_grammar *g, ag_trace_site s);

/* The site of split-tree node `node` of r, a model proceduralized from g (r->grammar itself,
 * or a grammar it derives like). AG_ERR_NOT_FOUND names the node when no site matches. */
ag_status ag_trace_find_node(const ag_trace *t, const ag_grammar *g,
                             const ag_proceduralize_result *r, int32_t node, ag_trace_site *out,
                             ag_error *err);

#endif
