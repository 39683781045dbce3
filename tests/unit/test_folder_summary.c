/* `archgram proceduralize`'s summary.json prints its components list directly and splices it
 * into jansson's dump of the rest: the file must be what jansson prints for the same
 * document (read back and dumped again with the summary's flags, character for character),
 * with one entry per component and group names escaped as jansson escapes them. On generated
 * facades with and without groups, with names that need escaping, one not UTF-8, and at
 * UTM-sized coordinates. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/folder_ws.h"
#include "app/usecase_proceduralize.h"
#include "core/gen_facade.h"
#include "io/obj.h"

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    char *b = malloc((size_t)n + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    b[n] = '\0';
    fclose(f);
    return b;
}

static void check_summary(ag_mesh *g, const char *name)
{
    char dir[] = "/tmp/archgram_test_summary_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char obj[4200], out[4200], sum[4200];
    snprintf(obj, sizeof obj, "%s/in.obj", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    snprintf(sum, sizeof sum, "%s/out/summary.json", dir);
    ag_error err = {0};
    assert_int_equal(ag_obj_write_file(g, AG_UP_Z, obj, &err), AG_OK);

    ag_folder_ws w;
    ag_folder_ws_init(&w, &(ag_folder_ws_options){.mesh_path = obj, .up = AG_UP_Z, .out_dir = out});
    ag_usecase_proceduralize_params p = {0};
    ag_usecase_proceduralize_result r;
    ag_status s = ag_usecase_proceduralize_run(&w.ws, &p, &r, &err);
    ag_workspace_close(&w.ws);
    if (s)
        fail_msg("%s: %s", name, err.text);

    char *text = slurp(sum);
    json_error_t je;
    json_t *j = json_loads(text, 0, &je);
    if (!j)
        fail_msg("%s: summary.json does not parse: %s (line %d)", name, je.text, je.line);
    char *again = json_dumps(j, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(10));
    assert_non_null(again);
    if (strcmp(text, again)) {
        size_t i = 0;
        while (text[i] && text[i] == again[i])
            i++;
        fail_msg("%s: differs from jansson's print at byte %zu: ...%.50s... instead of ...%.50s...",
                 name, i, text + i, again + i);
    }
    json_t *comps = json_object_get(j, "components");
    assert_int_equal(json_array_size(comps), r.components);
    for (size_t c = 0; c < json_array_size(comps); c++)
        assert_int_equal(json_integer_value(json_object_get(json_array_get(comps, c), "index")), c);
    free(again);
    json_decref(j);
    free(text);
    char cmd[4300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

static void test_summary_is_what_jansson_prints(void **state)
{
    (void)state;
    const ag_gen_facade_options opts[] = {
        {.cols = 5, .rows = 3, .side_cols = 3, .back = 1, .annex = 1},
        {.cols = 4, .rows = 2, .side_cols = 2, .annex = 1, .no_groups = 1},
        {.cols = 3, .rows = 2},
    };
    for (size_t i = 0; i < sizeof opts / sizeof *opts; i++) {
        ag_mesh *g;
        ag_error err = {0};
        assert_int_equal(ag_gen_facade(&opts[i], &g, &err), AG_OK);
        if (i == 0) { /* names that need escaping, a non-ASCII one, one that is not UTF-8 */
            const char *names[] = {"Fenster_\"Süd\"", "back\\slash", "bad_\xff\xfe"};
            for (size_t k = 0; k < g->ngroups && k < 3; k++) {
                free(g->group_names[k]);
                g->group_names[k] = strdup(names[k]);
            }
        }
        if (i == 2) /* UTM-sized coordinates */
            for (size_t v = 0; v < g->nverts; v++) {
                g->pos[3 * v] += 512345.25;
                g->pos[3 * v + 1] += 5812345.5;
            }
        char name[32];
        snprintf(name, sizeof name, "facade %zu", i);
        check_summary(g, name);
        ag_mesh_free(g);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_summary_is_what_jansson_prints),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
