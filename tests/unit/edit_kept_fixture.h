/* The model as the store keeps it, for the edit tests (test_edit_ids.c, test_edit_keep_ids.c):
 * its mesh blob and stored tree, reloaded. Header-only because every test file is its own
 * binary; include it after <cmocka.h>. */
#ifndef AG_TEST_EDIT_KEPT_FIXTURE_H
#define AG_TEST_EDIT_KEPT_FIXTURE_H

#include <stdint.h>
#include <stdlib.h>

#include "app/model_kept.h"
#include "app/model_state.h"
#include "app/model_tree.h"
#include "core/edit/edit.h"
#include "io/meshblob.h"

/* em stored (mesh blob and stored tree) and reloaded: the reloaded model's served tree text
 * (malloc'd). */
static inline char *ek_served_after_store(const ag_edit_model *em)
{
    uint8_t *blob = NULL;
    size_t len = 0;
    assert_int_equal(ag_meshblob_encode(em->proc->mesh, &blob, &len), AG_OK);
    char *stored = ag_model_kept_tree_text(em);
    assert_non_null(stored);
    ag_mesh *back = NULL;
    ag_error err = {0};
    assert_int_equal(ag_meshblob_decode(blob, len, &back, &err), AG_OK);
    ag_edit_model *re = NULL;
    if (ag_model_state_reload_kept(back, stored, &re, &err))
        fail_msg("reload: %s", err.text);
    char *text = ag_model_tree_served_text(re);
    ag_edit_model_free(re);
    ag_mesh_free(back);
    free(stored);
    free(blob);
    return text;
}

#endif
