/* Split tree: every node is an axis-aligned box obtained from its parent's box by one point
 * split split(parent, vx, vy, vz, q) — the pivot is relative to the parent box's min corner,
 * octant q in 1..8 keeps, per axis a, the upper part when bit a of q-1 is set.
 *
 * Built top-down: components sorted by decreasing box volume (dimensions floored to 1e-3 of
 * the diagonal so that flat walls sort by area) are inserted under the visible node (or the
 * root) whose box encloses theirs most tightly; one or two splits (an invisible intermediate
 * node for the second) cut the component's box out of its parent's. Components only nest
 * under visible nodes, so an intermediate node has exactly one child. Visible nodes keep a
 * component; its geometry is taken relative to the node's box (terminals). */
#ifndef AG_SPLITTREE_H
#define AG_SPLITTREE_H

#include <stddef.h>
#include <stdint.h>

#include "../mesh.h"
#include "../status.h"
#include "label.h"

typedef enum {
    AG_NODE_ROOT = 0,      /* the building box, invisible */
    AG_NODE_SPLIT = 1,     /* intermediate node of a two-split insertion, invisible */
    AG_NODE_COMPONENT = 2, /* visible: holds a component */
    AG_NODE_PATTERN = 3,   /* invisible: a regular pattern of one rule (patterns.c) */
    AG_NODE_DEAD = 4,      /* removed by restructuring */
} ag_node_kind;

typedef struct {
    ag_box box;
    int32_t parent, first_child, last_child, next_sibling;
    int32_t component; /* visible nodes, else -1 */
    int32_t label;     /* label of the component, else -1 */
    int32_t variant;   /* variant (exact class) of the component, else -1 */
    uint8_t rot;       /* quarter turns from the variant's exemplar */
    uint8_t kind;      /* ag_node_kind */
    uint8_t octant;    /* 1..8; 0 for the root and for members of a pattern */
    uint8_t rule_rot;  /* quarter turns from the rule's representative */
    double pivot[3];   /* relative to the parent's box min */
    int32_t rule;      /* repeated-subtree class (rules.c), -1 */
    int32_t pattern;   /* PATTERN nodes: index into patterns */
} ag_tnode;

typedef struct {
    int32_t rule;
    uint8_t rot;
    uint8_t nvec;       /* 0: axis-aligned grid (counts, step per axis); 1..3: a lattice */
    uint32_t counts[3]; /* per axis, or per lattice vector */
    double step[3];     /* axis-aligned grid: the step per axis */
    double vec[3][3];   /* lattice: the translation vectors (need not be axis-aligned) */
    int32_t node;       /* the PATTERN node */
} ag_pattern;

/* A node as the adjacency last saw it: its box, and whether it was visible. */
typedef struct {
    ag_box box;
    uint8_t visible;
} ag_adj_seen;

typedef struct {
    size_t nnodes, cap;
    ag_tnode *nodes;
    size_t ncomponents;
    int32_t *comp_node; /* per component: its visible node, -1 for components without triangles */
    size_t nadj;
    uint32_t *adj;      /* nadj pairs of visible nodes whose boxes meet (adjacency.h) */
    size_t adj_nseen;
    ag_adj_seen *adj_seen; /* what adj was found for (adjacency.h); NULL: unknown */
    double adj_tol;        /* the tolerance it was found with */
    size_t nrules;
    uint32_t *rule_count; /* per rule: visible nodes in the class */
    int32_t *rule_rep;    /* per rule: its representative node */
    size_t npatterns, cap_patterns;
    ag_pattern *patterns;
    double tol; /* absolute matching tolerance (the labels' exact tolerance) */
    double eps; /* absolute coincidence tolerance for faces */
} ag_splittree;

typedef struct {
    size_t nodes, visible, invisible, depth;
} ag_splittree_stats;

/* Components nest at most this deep (deeper ones are inserted under the root). */
#define AG_SPLITTREE_MAX_NESTING 256

/* The labels must come from the same mesh. */
ag_status ag_splittree_build(const ag_mesh *m, const ag_labels *labels, ag_splittree **out,
                             ag_error *err);
void ag_splittree_free(ag_splittree *t);

/* Box of the child of `parent` cut by (pivot, octant). */
ag_box ag_splittree_child_box(const ag_box *parent, const double pivot[3], int octant);
/* The node that a child slot leads to: follows intermediate split nodes. */
int32_t ag_splittree_chain_end(const ag_splittree *t, int32_t n);
/* The first visible node of the rule with the most instances (at least two): a window of a
 * facade, what a part is typically saved from; -1 when no rule repeats. */
int32_t ag_splittree_most_repeated(const ag_splittree *t);
/* Adds one or two split nodes under `parent` ending in a node with box `box`; returns the last
 * node's index (with kind `kind`) or -1 when out of memory. */
int32_t ag_splittree_insert(ag_splittree *t, int32_t parent, const ag_box *box, int kind);
/* Appends child to parent's list. */
void ag_splittree_attach(ag_splittree *t, int32_t parent, int32_t child);
/* Inserts child into parent's list right after sibling `after` (-1: at the end). */
void ag_splittree_attach_after(ag_splittree *t, int32_t parent, int32_t after, int32_t child);
/* Takes child out of its parent's list (parent = -1 afterwards). */
void ag_splittree_detach(ag_splittree *t, int32_t child);
/* A new node of the given kind, linked to nothing (-1 when out of memory). */
int32_t ag_splittree_add_node(ag_splittree *t, int kind);
/* Hangs an existing node (its box set, linked to nothing) under parent by the split chain
 * insertion would give it: its pivot and octant, and an intermediate split node when it needs
 * two splits. */
ag_status ag_splittree_hang(ag_splittree *t, int32_t parent, int32_t node);
/* Recomputes the split chain from a chain end's parent (through its intermediate node, if any)
 * to the end from their current boxes: pivots, octants and the intermediate box, adding an
 * intermediate node when one split no longer cuts the end's box (a chain of two whose first
 * split suffices keeps its second as a split that keeps everything). Pattern cells have no
 * chain. */
ag_status ag_splittree_rechain(ag_splittree *t, int32_t end);
/* A deep copy (NULL when out of memory). */
ag_splittree *ag_splittree_copy(const ag_splittree *t);
ag_splittree_stats ag_splittree_stats_of(const ag_splittree *t);

#endif
