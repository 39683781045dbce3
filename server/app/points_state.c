#include "points_state.h"

#include <stdlib.h>
#include <string.h>

#include "../core/points/pointedit.h"
#include "../io/grammar_text.h"
#include "../io/point_terminals.h"
#include "model_kept.h"

void ag_points_state_clear(ag_points_state *s)
{
    if (!s)
        return;
    free(s->text);
    ag_terminals_set_clear(&s->terms);
    ag_pointmodel_free(s->pm);
    memset(s, 0, sizeof *s);
}

ag_status ag_points_state_text(ag_pointmodel *pm, char **text, size_t *len, ag_error *err)
{
    ag_grammar *g = pm->em->proc->grammar;
    ag_box keep = g->axiom.box;
    for (int a = 0; a < 3; a++) {
        g->axiom.box.min[a] += pm->offset[a];
        g->axiom.box.max[a] += pm->offset[a];
    }
    ag_status st = ag_grammar_text_print(g, text, len, err);
    g->axiom.box = keep;
    return st;
}

ag_status ag_points_state_read(const char *text, size_t len, ag_terminal_lookup lookup,
                               void *user, ag_pointmodel **out, ag_error *err, long *col)
{
    *out = NULL;
    if (col)
        *col = 0;
    ag_grammar *g = NULL;
    ag_status st = ag_grammar_text_parse(text, len, &g, err, col);
    if (st != AG_OK)
        return st;
    ag_cloud **clouds = calloc(g->nterminals + 1, sizeof *clouds);
    if (!clouds) {
        ag_grammar_free(g);
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    }
    int kind = ag_point_terminals_is_point_grammar(g, err);
    if (kind < 0) {
        st = AG_ERR_PARSE;
        goto done;
    }
    if (!kind) {
        st = ag_error_set(err, AG_ERR_PARSE, 0,
                          g->nterminals ? "the grammar's terminals are meshes, not point sets"
                                        : "the grammar has no terminals");
        goto done;
    }
    for (size_t i = 0; i < g->nterminals && st == AG_OK; i++) {
        const ag_gterminal *t = &g->terminals[i];
        char *bytes = NULL;
        size_t n = 0;
        if ((st = lookup(user, t->path ? t->path : "", &bytes, &n, err)) != AG_OK) {
            if (st == AG_ERR_NOT_FOUND)
                st = ag_error_set(err, AG_ERR_PARSE, 0,
                                  "terminal '%s' names %s, which the model does not keep",
                                  t->name, t->path ? t->path : "no file");
            break;
        }
        st = ag_point_terminals_decode(t, (const uint8_t *)bytes, n, &clouds[i], err);
        free(bytes);
    }
    if (st != AG_OK)
        goto done;
    /* the axiom in the input's coordinates: back to a local origin */
    double origin[3];
    ag_cloud_choose_origin(g->axiom.box.min, g->axiom.box.max, origin);
    for (int a = 0; a < 3; a++) {
        g->axiom.box.min[a] -= origin[a];
        g->axiom.box.max[a] -= origin[a];
    }
    st = ag_pointmodel_from_grammar(g, clouds, origin, out, err);
done:
    for (size_t i = 0; i < g->nterminals; i++)
        ag_cloud_free(clouds[i]);
    free(clouds);
    ag_grammar_free(g);
    return st;
}

ag_status ag_points_state_make(ag_pointmodel *made, ag_points_state *out, ag_error *err)
{
    memset(out, 0, sizeof *out);
    if (!made->em)
        return ag_error_set(err, AG_ERR_INVALID, 0, "the model is not built");
    ag_grammar *g = made->em->proc->grammar;
    int32_t *term = NULL;
    ag_cloud **clouds = calloc(g->nterminals + 1, sizeof *clouds);
    ag_status st = clouds ? ag_pointmodel_grammar_terminals(made, &term, err)
                          : ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory");
    if (st == AG_OK) {
        for (size_t i = 0; i < g->nterminals; i++)
            clouds[i] = made->terminals[term[i]].points;
        st = ag_point_terminals_collect(g, clouds, &out->terms, err);
    }
    free(term);
    free(clouds);
    if (st == AG_OK)
        st = ag_points_state_text(made, &out->text, &out->text_len, err);
    if (st == AG_OK) {
        long col = 0;
        st = ag_points_state_read(out->text, out->text_len, ag_terminals_set_lookup, &out->terms,
                                  &out->pm, err, &col);
        if (st != AG_OK && err) {
            char text[sizeof err->text];
            memcpy(text, err->text, sizeof text);
            st = ag_error_set(err, AG_ERR_INTERNAL, err->element,
                              "the point grammar does not read back: %s", text);
        }
    }
    if (st != AG_OK)
        ag_points_state_clear(out);
    return st;
}

ag_status ag_points_state_reload_kept(ag_pointmodel *pm, const char *tree_text, ag_error *err)
{
    if (!tree_text || !pm->em)
        return AG_OK;
    /* read once over the proxy the text gives, to learn the kept order of the placements,
     * then over the proxy in that order */
    ag_edit_model *em = NULL;
    ag_mesh *ordered = NULL;
    ag_status st = ag_model_kept_reload(pm->em->proc->mesh, tree_text, &em, err);
    if (st == AG_ERR_NOT_FOUND)
        return AG_OK;
    if (st == AG_OK)
        st = ag_pointedit_kept_order(pm, em, &ordered, err);
    ag_edit_model_free(em);
    em = NULL;
    if (st == AG_OK)
        st = ag_model_kept_reload(ordered, tree_text, &em, err);
    ag_mesh_free(ordered);
    if (st != AG_OK)
        return st;
    em->opt = pm->em->opt; /* a point model's options, as its build set them */
    ag_edit_model_free(pm->em);
    pm->em = em;
    return ag_pointedit_name_groups(pm, err);
}
