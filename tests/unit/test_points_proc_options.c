/* The options of proceduralizing a point cloud in the service (app/points_proc_options.h) and
 * their trip through a job's params (app/job_params.h): templates and ROIs read as boxes in
 * the cloud's coordinates, auto off, every bad member refused naming it, and the options text
 * a job carries decoded as it was encoded. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include "app/job_params.h"
#include "app/points_proc_options.h"

static void options_are_read(void **state)
{
    (void)state;
    json_t *o = json_loads("{\"templates\":[[85001.4,446000.1,2.4,85002.8,446000.6,4.1],"
                           "[1,2,3,4,5,6]],\"rois\":[[0,0,0,1,1,1]],\"auto\":false}",
                           0, NULL);
    assert_non_null(o);
    ag_usecase_points_proceduralize_params p;
    ag_box *boxes = NULL;
    ag_error e;
    assert_int_equal(ag_points_proc_options_read(o, &p, &boxes, &e), AG_OK);
    assert_int_equal(p.options.ntemplates, 2);
    assert_int_equal(p.options.nrois, 1);
    assert_true(p.options.no_auto);
    assert_true(p.boxes_in_input);
    assert_true(p.options.templates[0].min[0] == 85001.4 && p.options.templates[0].max[2] == 4.1);
    assert_true(p.options.templates[1].min[2] == 3 && p.options.templates[1].max[0] == 4);
    assert_true(p.options.rois[0].max[1] == 1);
    free(boxes);
    json_decref(o);
    /* none at all: the defaults (automatic repetition, no boxes) */
    assert_int_equal(ag_points_proc_options_read(NULL, &p, &boxes, &e), AG_OK);
    assert_null(boxes);
    assert_int_equal(p.options.ntemplates + p.options.nrois, 0);
    assert_false(p.options.no_auto);
}

static void bad_options_name_the_member(void **state)
{
    (void)state;
    const struct {
        const char *json, *says;
    } bad[] = {
        {"{\"templates\":[[1,2,3]]}", "templates[0]: a box"},
        {"{\"templates\":{}}", "templates: an array of at most 64 boxes"},
        {"{\"rois\":[[0,0,0,1,1,\"x\"]]}", "rois[0][5] is not a finite number"},
        {"{\"rois\":[[0,0,2,1,1,1]]}", "rois[0]: its minimum 2 lies above its maximum 1 on axis z"},
        {"{\"auto\":1}", "\"auto\" takes true or false"},
        {"{\"exact\":true}", "\"exact\" is not an option of proceduralize"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        json_t *o = json_loads(bad[i].json, 0, NULL);
        assert_non_null(o);
        ag_usecase_points_proceduralize_params p;
        ag_box *boxes = (ag_box *)1;
        ag_error e;
        ag_error_clear(&e);
        assert_int_equal(ag_points_proc_options_read(o, &p, &boxes, &e), AG_ERR_INVALID);
        assert_null(boxes);
        if (!strstr(e.text, bad[i].says))
            fail_msg("%s: \"%s\" does not say \"%s\"", bad[i].json, e.text, bad[i].says);
        json_decref(o);
    }
    /* 65 boxes are too many */
    json_t *many = json_pack("{s:[]}", "templates");
    for (int k = 0; k < 65; k++)
        json_array_append_new(json_object_get(many, "templates"), json_pack("[i,i,i,i,i,i]", 0, 0, 0, 1, 1, 1));
    ag_usecase_points_proceduralize_params p;
    ag_box *boxes = NULL;
    ag_error e;
    assert_int_equal(ag_points_proc_options_read(many, &p, &boxes, &e), AG_ERR_INVALID);
    assert_non_null(strstr(e.text, "at most 64"));
    json_decref(many);
}

static void a_job_carries_the_options(void **state)
{
    (void)state;
    const char *opts = "{\"templates\":[[1,2,3,4,5,6]],\"auto\":false}";
    ag_job_params q = {.type = AG_JOB_PROCEDURALIZE,
                       .u.proceduralize = {.model = 4, .base = 2, .author = "ana",
                                           .cloud = (char *)opts}};
    char *text = ag_job_params_encode(&q);
    assert_non_null(text);
    ag_job_params back, copy;
    ag_error e;
    assert_int_equal(ag_job_params_decode("proceduralize", text, &back, &e), AG_OK);
    assert_string_equal(back.u.proceduralize.cloud, opts);
    assert_int_equal(ag_job_params_copy(&copy, &back, &e), AG_OK);
    assert_string_equal(copy.u.proceduralize.cloud, opts);
    ag_job_params_clear(&copy);
    ag_job_params_clear(&back);
    free(text);
    /* a mesh's job has none */
    q.u.proceduralize.cloud = NULL;
    text = ag_job_params_encode(&q);
    assert_int_equal(ag_job_params_decode("proceduralize", text, &back, &e), AG_OK);
    assert_null(back.u.proceduralize.cloud);
    ag_job_params_clear(&back);
    free(text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(options_are_read),
        cmocka_unit_test(bad_options_name_the_member),
        cmocka_unit_test(a_job_carries_the_options),
    };
    return cmocka_run_group_tests_name("points_proc_options", tests, NULL, NULL);
}
