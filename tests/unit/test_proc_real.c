/* Proceduralization of the real meshes in ../shared/data (skipped when absent). */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <cmocka.h>

#include "core/proc/proceduralize.h"
#include "io/grammar_text.h"
#include "io/obj.h"
#include "io/terminals.h"

#define SHARED AG_REPO_DIR "/../shared/data"

/* Bytes of the grammar text plus the distinct terminal files, computed in memory. */
static size_t output_bytes(ag_grammar *g)
{
    size_t total = 0;
    char *text;
    size_t len;
    /* the paths the files would get: terminals/<16 hex digits>.obj */
    for (size_t i = 0; i < g->nterminals; i++)
        if (!g->terminals[i].path)
            g->terminals[i].path = strdup("terminals/0123456789abcdef.obj");
    assert_int_equal(ag_grammar_text_print(g, &text, &len, NULL), AG_OK);
    total += len;
    free(text);
    for (size_t i = 0; i < g->nterminals; i++) {
        assert_int_equal(ag_terminals_format(&g->terminals[i], &text, &len, NULL), AG_OK);
        total += len;
        free(text);
    }
    return total;
}

/* exact: terminals shared by exact copies only (--exact), so derivation gives the input back */
static ag_proceduralize_result *proc_file(const char *path, ag_up_axis up, int exact,
                                          ag_mesh **mesh)
{
    ag_obj_read_options ro = {.up = up};
    ag_error err = {0};
    if (ag_obj_read_file(path, &ro, mesh, &err))
        fail_msg("%s: %s", path, err.text);
    ag_proceduralize_options po = {.verify = 1};
    po.label.exact_copies = exact;
    ag_proceduralize_result *r;
    if (ag_proceduralize_run(*mesh, &po, &r, &err))
        fail_msg("%s: %s", path, err.text);
    if (r->fidelity.unmatched)
        fail_msg("%s: %zu triangles not reproduced", path, r->fidelity.unmatched);
    return r;
}

static void test_ingolstadt_windows(void **state)
{
    (void)state;
    FILE *csv = fopen(SHARED "/lod3_ingolstadt/ground_truth_counts.csv", "r");
    if (!csv) {
        print_message("skipping: %s is absent\n", SHARED "/lod3_ingolstadt");
        skip();
    }
    char line[512];
    size_t buildings = 0, windows_total = 0, window_labels_total = 0, repeating = 0;
    assert_non_null(fgets(line, sizeof line, csv)); /* header */
    while (fgets(line, sizeof line, csv)) {
        char id[64];
        unsigned vtx, tris, windows, doors;
        if (sscanf(line, "%63[^,],%u,%u,%u,%u", id, &vtx, &tris, &windows, &doors) != 5)
            continue;
        char path[512];
        snprintf(path, sizeof path, SHARED "/lod3_ingolstadt/obj/%s.obj", id);
        struct stat sb;
        if (stat(path, &sb))
            continue;
        ag_mesh *m;
        /* exact copies: the input comes back within rounding */
        ag_proceduralize_result *r = proc_file(path, AG_UP_Z, 1, &m);
        assert_true(r->fidelity.relative <= 1e-6);
        ag_proceduralize_result_free(r);
        ag_mesh_free(m);
        /* by default: shared terminals move no surface by more than a centimetre */
        r = proc_file(path, AG_UP_Z, 0, &m);
        if (!(r->fidelity.max_error <= 0.01))
            fail_msg("%s: fidelity %g m", id, r->fidelity.max_error);
        assert_int_equal(m->ntris, tris);
        /* every Window_n group stays one component; compare with the ground truth */
        const ag_labels *L = r->labels;
        size_t nwin = 0, ndoor = 0;
        uint8_t *seen = calloc(L->nlabels + 1, 1);
        size_t wl = 0;
        for (size_t c = 0; c < r->mesh->ncomponents; c++) {
            int32_t g = r->mesh->component_group[c];
            if (g >= 0 && !strncmp(r->mesh->group_names[g], "Door_", 5))
                ndoor++;
            if (g < 0 || strncmp(r->mesh->group_names[g], "Window_", 7))
                continue;
            nwin++;
            if (!seen[L->label[c]]) {
                seen[L->label[c]] = 1;
                wl++;
            }
        }
        free(seen);
        assert_int_equal(nwin, windows);
        assert_int_equal(ndoor, doors);
        /* identical windows share a label: windows of one label are exact copies, so
         * the grammar stores one terminal per window label */
        assert_true(wl <= nwin);
        windows_total += nwin;
        window_labels_total += wl;
        /* wherever parts repeat exactly, grammar + terminals are smaller than the OBJ */
        if (2 * r->grammar->nterminals <= r->mesh->ncomponents) {
            repeating++;
            size_t ob = output_bytes(r->grammar);
            if (ob >= (size_t)sb.st_size)
                fail_msg("%s: output %zu bytes, input %zu", id, ob, (size_t)sb.st_size);
        }
        buildings++;
        ag_proceduralize_result_free(r);
        ag_mesh_free(m);
    }
    fclose(csv);
    print_message("ingolstadt: %zu buildings, %zu windows in %zu window labels, %zu repeating\n",
                  buildings, windows_total, window_labels_total, repeating);
    assert_true(buildings >= 30);
    assert_int_equal(windows_total, 718);
    assert_true(window_labels_total * 2 < windows_total); /* repetition was found */
}

static void test_0ad_loose_parts(void **state)
{
    (void)state;
    DIR *d = opendir(SHARED "/meshes_0ad");
    if (!d) {
        print_message("skipping: %s is absent\n", SHARED "/meshes_0ad");
        skip();
    }
    struct dirent *e;
    size_t n = 0;
    while ((e = readdir(d))) {
        size_t l = strlen(e->d_name);
        if (l < 5 || strcmp(e->d_name + l - 4, ".obj"))
            continue;
        char path[512];
        snprintf(path, sizeof path, SHARED "/meshes_0ad/%s", e->d_name);
        struct stat sb;
        assert_int_equal(stat(path, &sb), 0);
        ag_mesh *m;
        ag_proceduralize_result *r = proc_file(path, AG_UP_Y, 1, &m);
        assert_true(r->fidelity.relative <= 1e-6);
        ag_proceduralize_result_free(r);
        ag_mesh_free(m);
        r = proc_file(path, AG_UP_Y, 0, &m);
        if (!(r->fidelity.max_error <= 0.01))
            fail_msg("%s: fidelity %g m", e->d_name, r->fidelity.max_error);
        /* the file is one object of loose parts: it is split into them */
        assert_true(r->mesh->ncomponents > 10);
        assert_true(r->labels->nlabels < r->mesh->ncomponents);
        size_t ob = output_bytes(r->grammar);
        print_message("%s: %zu -> %zu bytes, %zu components, %zu labels, %zu terminals\n",
                      e->d_name, (size_t)sb.st_size, ob, r->mesh->ncomponents, r->labels->nlabels,
                      r->grammar->nterminals);
        /* where parts repeat exactly, the procedural model is smaller */
        if (2 * r->grammar->nterminals <= r->mesh->ncomponents)
            assert_true(ob < (size_t)sb.st_size);
        n++;
        ag_proceduralize_result_free(r);
        ag_mesh_free(m);
    }
    closedir(d);
    assert_true(n > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ingolstadt_windows),
        cmocka_unit_test(test_0ad_loose_parts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
