/* A reusable procedural part (paper §4.1, "store"): the subtree of one split-tree node of a
 * proceduralized building as a grammar of its own, with its proportions and metadata.
 *
 * The part's grammar holds the rules and terminals reachable from the node, a root rule whose
 * body is the node's content (the statements of the body that produced the node, restricted
 * to the node and its descendants, in that body's local coordinates) and an axiom placing the
 * root rule on the node's world box in the source building, turned as it was there. So the
 * grammar derives exactly the part as it stood in its building, and parses, prints and
 * derives like any grammar. Proportions: the node's box and each node of its subtree (split
 * nodes left out) with its box relative to it, per axis (min - box.min) / size, 0 on flat
 * axes. Pure functions of the model and the node: a service calls it on a proceduralize
 * result in memory. */
#ifndef AG_PART_H
#define AG_PART_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../proc/proceduralize.h"
#include "trace.h"
#include "../status.h"

#define AG_PART_NAME_MAX 200
#define AG_PART_TAGS_MAX 64
#define AG_PART_TEXT_MAX 4000

typedef struct {
    int32_t parent;    /* index into the part's nodes, -1 for its root */
    int kind;          /* ag_node_kind: ROOT for the part's root when it is invisible */
    int32_t label;     /* the source label, -1 */
    char rule[64];     /* the grammar rule of its class, "" when it has none */
    double box[6];     /* relative: min xyz, max xyz in [0, 1] of the part's box */
} ag_part_node;

typedef struct {
    char *key, *value;
} ag_part_attr;

typedef struct {
    /* metadata */
    char *name;
    char *description;      /* may be NULL */
    size_t ntags;
    char **tags;
    unsigned version;       /* 1 for a new part; an update of a part makes version + 1 */
    char *source;           /* provenance: the source model (a name or folder), may be NULL */
    long source_version;    /* its version, 0 when unknown */
    int32_t source_node;    /* the split-tree node it was saved from */
    size_t nattrs;
    ag_part_attr *attrs;    /* labels, counts: what the part is */
    /* content */
    ag_grammar *grammar;    /* resolved; terminals carry geometry */
    char *root;             /* the root rule's name */
    ag_box box;             /* the node's world box in the source building */
    int facing;             /* ag_place_facing of box in the source building (0..3) */
    size_t nnodes;
    ag_part_node *nodes;
} ag_part;

typedef struct {
    const char *name;          /* required, 1..AG_PART_NAME_MAX bytes */
    const char *description;   /* optional */
    const char *const *tags;   /* optional */
    size_t ntags;
    const char *source;        /* optional provenance */
    long source_version;
} ag_part_meta;

/* Saves node `node` of r (node ids of r->tree; r->grammar is r's exported grammar) as a part. */
ag_status ag_part_extract(const ag_proceduralize_result *r, int32_t node, const ag_part_meta *meta,
                          ag_part **out, ag_error *err);
/* ag_part_extract with r->grammar's trace (trace.h) given, NULL: traced here. A caller that
 * keeps a model traces it once for every save and composition of that version. */
ag_status ag_part_extract_traced(const ag_proceduralize_result *r, const ag_trace *trace,
                                 int32_t node, const ag_part_meta *meta, ag_part **out,
                                 ag_error *err);
void ag_part_free(ag_part *p);
/* A deep copy (its grammar resolved again). */
ag_status ag_part_copy(const ag_part *p, ag_part **out, ag_error *err);

/* Checks the metadata limits (name length, tags, text); element = 0. */
ag_status ag_part_check_meta(const ag_part_meta *meta, ag_error *err);
/* Copies strings into a new part without content (the bundle reader fills it). */
ag_status ag_part_set_meta(ag_part *p, const ag_part_meta *meta);
ag_status ag_part_add_attr(ag_part *p, const char *key, const char *value);

/* Index of the root rule in p->grammar, -1 when missing. */
int32_t ag_part_root_rule(const ag_part *p);
/* Quarter turns the part's axiom applies its root rule with (0..3). */
int ag_part_root_rot(const ag_part *p);
/* The largest |coordinate| of a part's box, in metres: beyond every projected CRS in use
 * (web-mercator reaches 2e7 m), so a part saved from a georeferenced model keeps its place.
 * Saving checks it (ag_part_validate) and the bundle reader refuses more, so whatever is
 * written reads back. */
#define AG_PART_MAX_COORD 1e8

/* Checks a part's own consistency: the grammar is resolved, the axiom is exactly one
 * application of the root rule, every terminal has geometry, the box is finite and within
 * AG_PART_MAX_COORD, nodes are in range. Names the offending element. */
ag_status ag_part_validate(const ag_part *p, ag_error *err);

#endif
