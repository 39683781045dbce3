/* The nodes the edit benchmarks edit on a generated building: two windows of one label on
 * one facade (small visible boxes, thin across the facade) and the largest wall. Shared by
 * bench/edit and bench/adjacency so that both time the same ops. Header-only. */
#ifndef AG_BENCH_EDIT_TARGETS_H
#define AG_BENCH_EDIT_TARGETS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "core/proc/splittree.h"

/* w[0], w[1]: two windows (-1 when missing); *wall: the largest thin box (-1 when none) */
static void bench_pick_windows_and_wall(const ag_splittree *t, int32_t w[2], int32_t *wall)
{
    double wall_area = 0;
    w[0] = w[1] = *wall = -1;
    for (size_t n = 0; n < t->nnodes; n++) {
        const ag_box *b = &t->nodes[n].box;
        if (t->nodes[n].kind != AG_NODE_COMPONENT)
            continue;
        double dx = b->max[0] - b->min[0], dz = b->max[2] - b->min[2];
        if (dx < 2 && dz < 3 && dx > 0.5 && b->max[1] - b->min[1] < 1) {
            if (w[0] < 0)
                w[0] = (int32_t)n;
            else if (w[1] < 0 && t->nodes[n].label == t->nodes[w[0]].label &&
                     fabs(b->min[1] - t->nodes[w[0]].box.min[1]) < 1e-6)
                w[1] = (int32_t)n;
        }
        if (dx * dz > wall_area && b->max[1] - b->min[1] < 1) {
            wall_area = dx * dz;
            *wall = (int32_t)n;
        }
    }
}

#endif
