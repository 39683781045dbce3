/* Styles for footprint batches: which profile each plan edge gets, from edge labels.
 *
 * Every edge is labelled by length (short / medium / long, with the style's
 * thresholds), by compass orientation of its outward normal (north / east / south /
 * west; street / side / back when a street direction is given: the edge facing it is
 * street, the opposite back, the rest side) and by axis (along / across the
 * footprint's longest edge). The first rule whose labels match picks one of its
 * profiles at random with the given weights; the choice is a hash of the seed, the
 * footprint index and the edge index, so a batch is reproducible. Style profiles are
 * given above the eave as (w, dz), dz >= 0 (0: a horizontal segment): each starts with a
 * vertical wall to the building height. */
#ifndef AG_EXTRUDE_STYLE_H
#define AG_EXTRUDE_STYLE_H

#include <stddef.h>
#include <stdint.h>

#include "../status.h"
#include "plan.h"

#define AG_STYLE_MAX_PROFILES 8
#define AG_STYLE_MAX_POINTS 8
#define AG_STYLE_MAX_RULES 8

enum {
    AG_LABEL_SHORT = 1 << 0,
    AG_LABEL_MEDIUM = 1 << 1,
    AG_LABEL_LONG = 1 << 2,
    AG_LABEL_ANY_LENGTH = 7,
    AG_LABEL_NORTH = 1 << 3,
    AG_LABEL_EAST = 1 << 4,
    AG_LABEL_SOUTH = 1 << 5,
    AG_LABEL_WEST = 1 << 6,
    AG_LABEL_STREET = 1 << 7,
    AG_LABEL_SIDE = 1 << 8,
    AG_LABEL_BACK = 1 << 9,
    AG_LABEL_ANY_ORIENTATION = 0x3f8,
    AG_LABEL_ALONG = 1 << 10,
    AG_LABEL_ACROSS = 1 << 11,
    AG_LABEL_ANY_AXIS = 3 << 10,
};

typedef struct {
    char name[32];
    size_t npoints; /* points above the eave: (w, dz), dz never decreasing */
    ag_profile_point points[AG_STYLE_MAX_POINTS];
} ag_style_profile;

typedef struct {
    uint32_t labels; /* all label groups must match: length, orientation, axis bits */
    size_t nchoices;
    uint32_t profile[AG_STYLE_MAX_PROFILES];
    double weight[AG_STYLE_MAX_PROFILES];
} ag_style_rule;

typedef struct {
    char name[32];
    double height;          /* default wall height when a footprint has none */
    int cap;                /* close flat at the wall height (flat roofs) */
    double short_below;     /* edges shorter are short (m) */
    double long_above;      /* edges longer are long (m) */
    int has_street;
    double street_dir[2];   /* unit direction towards the street (outward normal of street edges) */
    uint64_t seed;
    size_t nprofiles;
    ag_style_profile profiles[AG_STYLE_MAX_PROFILES];
    size_t nrules;
    ag_style_rule rules[AG_STYLE_MAX_RULES];
} ag_style;

/* Fills s with a built-in style: flat, hip, gable, mansard, overhang. */
ag_status ag_style_builtin(const char *name, ag_style *s, ag_error *err);
/* Labels of edge i of a loop (xy pairs, n corners) with the style's thresholds;
 * `axis` is the footprint's main direction (unit vector). */
uint32_t ag_style_edge_labels(const ag_style *s, const double *xy, size_t n, size_t i,
                              const double axis[2]);
/* Builds a plan for one footprint: loops (xy pairs, nloops with sizes), wall height
 * (<= 0: the style's default), footprint index for the random choices. */
ag_status ag_style_apply(const ag_style *s, const double *const *loops, const size_t *sizes,
                         size_t nloops, double height, size_t footprint, ag_plan **out,
                         ag_error *err);

#endif
