/* Saving a part (paper section 4.1, "store"), over any workspace (app/workspace.h): the
 * workspace's model → the node named, or the common ancestor of a selection at the tree level
 * (core/parts/select.h) → the part (core/parts/part.h) → stored where the workspace keeps
 * parts (a bundle file for a folder, the parts library for the store), with the provenance the
 * workspace knows. Node ids are ids of the workspace's tree (app/model_tree.h). `archgram part
 * save` runs it on a folder, POST /api/v1/parts on the store. */
#ifndef AG_USECASE_SAVE_PART_H
#define AG_USECASE_SAVE_PART_H

#include "workspace.h"

#define AG_USECASE_SAVE_PART_MAX_NODES 100000

typedef struct {
    const int32_t *nodes;      /* one node, or a selection (1..AG_USECASE_SAVE_PART_MAX_NODES) */
    size_t nnodes;
    const ag_part_meta *meta;  /* name, description, tags; source is the workspace's */
} ag_usecase_save_part_params;

typedef struct {
    int32_t node;              /* the node saved */
    size_t nodes, visible, rules, terminals;
    double size[3];
    double load_ms, save_ms;   /* reading the model; extracting the part */
} ag_usecase_save_part_result;

/* Problems naming the selection are AG_ERR_INVALID or AG_ERR_NOT_FOUND ("nodes[2]: ..."),
 * the metadata's AG_ERR_INVALID; the rest are the model's or the workspace's. */
ag_status ag_usecase_save_part_run(ag_workspace *ws, const ag_usecase_save_part_params *p,
                                   ag_usecase_save_part_result *out, ag_error *err);

#endif
