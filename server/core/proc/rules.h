/* Rule labeling: visible nodes whose whole subtrees are the same up to translation and a
 * quarter turn about z get one rule (class), with the turn stored in node.rule_rot.
 *
 * Top-down, the comparison of two same-label nodes walks their children level by level;
 * intermediate split nodes are "don't care" paths (a child is compared by the node it leads
 * to, its box relative to the parent's centre, its rule and its turn). Running the comparison
 * from the leaves up (every child's rule is known before its parent is compared) makes each
 * comparison one level deep. Bottom-up, a rule is carried to the parents of its instances
 * when those parents are similar: the exporter then applies the parent's rule and the child
 * rule appears once, inside it (see grammar.c). */
#ifndef AG_RULES_H
#define AG_RULES_H

#include "../status.h"
#include "splittree.h"

ag_status ag_rules_label(ag_splittree *t, ag_error *err);

/* Largest number of visible nodes of one rule. */
size_t ag_rules_max_count(const ag_splittree *t);

#endif
