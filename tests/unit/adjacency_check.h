/* The brute-force check of a split tree's adjacency for the adjacency tests: every pair of
 * visible boxes that meet within the tree's tolerance, listed once, by the smaller node index
 * then the larger, found by comparing every pair and never through the adjacency code.
 *
 * Header-only (static functions); include it after cmocka.h. */
#ifndef AG_TEST_ADJACENCY_CHECK_H
#define AG_TEST_ADJACENCY_CHECK_H

#include <stddef.h>

#include "core/base/box.h"
#include "core/proc/splittree.h"

static int adjacency_check_meets(const ag_box *a, const ag_box *b, double tol)
{
    for (int k = 0; k < 3; k++)
        if (a->min[k] > b->max[k] + tol || b->min[k] > a->max[k] + tol)
            return 0;
    return 1;
}

/* fails the test, naming `what` and the first pair out of place, unless t's listed pairs are
 * exactly the meeting pairs of its visible boxes in order */
static void adjacency_check_brute_force(const ag_splittree *t, const char *what)
{
    size_t k = 0;
    for (size_t i = 0; i < t->nnodes; i++) {
        if (t->nodes[i].kind != AG_NODE_COMPONENT)
            continue;
        for (size_t j = i + 1; j < t->nnodes; j++) {
            if (t->nodes[j].kind != AG_NODE_COMPONENT ||
                !adjacency_check_meets(&t->nodes[i].box, &t->nodes[j].box, t->tol))
                continue;
            if (k >= t->nadj)
                fail_msg("%s: pair %zu %zu missing (only %zu listed)", what, i, j, t->nadj);
            if (t->adj[2 * k] != i || t->adj[2 * k + 1] != j)
                fail_msg("%s: pair %zu: %u %u listed, %zu %zu expected", what, k,
                         (unsigned)t->adj[2 * k], (unsigned)t->adj[2 * k + 1], i, j);
            k++;
        }
    }
    if (k != t->nadj)
        fail_msg("%s: %zu pairs listed, %zu meet", what, t->nadj, k);
}

#endif
