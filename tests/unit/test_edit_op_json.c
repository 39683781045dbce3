/* Edit op JSON: every kind parses, round-trips, and each malformed field gives an error
 * that names it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "io/edit_op_json.h"

static ag_edit_op parse_ok(const char *text)
{
    ag_edit_op op;
    ag_error err = {0};
    ag_status st = ag_edit_op_json_parse(text, strlen(text), &op, &err);
    if (st)
        fail_msg("%s: %s", text, err.text);
    return op;
}

static void test_kinds(void **state)
{
    (void)state;
    ag_edit_op op = parse_ok("{\"kind\":\"resize\",\"node\":\"12\",\"box\":[0,1,2,3,4,5],"
                             "\"mode\":\"local\",\"region\":[0,0,0,9,9,9]}");
    assert_int_equal(op.kind, AG_EDIT_RESIZE);
    assert_int_equal(op.node, 12);
    assert_true(op.has_box && !op.has_scale && op.has_region);
    assert_true(op.box.min[1] == 1 && op.box.max[2] == 5 && op.region.max[0] == 9);
    assert_int_equal(op.mode, AG_EDIT_LOCAL);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"resize\",\"node\":\"root\",\"scale\":[2,1,0.5]}");
    assert_int_equal(op.node, AG_EDIT_ROOT);
    assert_true(op.has_scale && op.scale[2] == 0.5 && op.mode == AG_EDIT_GLOBAL);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"split\",\"node\":7,\"axis\":\"z\",\"at\":3.5}");
    assert_true(op.kind == AG_EDIT_SPLIT && op.node == 7 && op.axis == 2 && op.at == 3.5);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"join\",\"nodes\":[3,\"4\",5]}");
    assert_true(op.kind == AG_EDIT_JOIN && op.nnodes == 3 && op.nodes[1] == 4);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"paste\",\"source\":[3],\"target\":9,\"placement\":\"replace\","
                  "\"fit\":\"derive\"}");
    assert_true(op.kind == AG_EDIT_PASTE && op.nnodes == 1 && op.node == 9);
    assert_true(op.placement == AG_EDIT_REPLACE && op.fit == AG_EDIT_DERIVE);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"paste\",\"source\":[3],\"target\":9}");
    assert_true(op.placement == AG_EDIT_INSERT && op.fit == AG_EDIT_FILL);
    ag_edit_op_clear(&op);

    op = parse_ok("{\"kind\":\"remove\",\"nodes\":[1]}");
    assert_true(op.kind == AG_EDIT_REMOVE && op.nnodes == 1 && op.nodes[0] == 1);
    ag_edit_op_clear(&op);
}

static void test_round_trip(void **state)
{
    (void)state;
    const char *ops[] = {
        "{\"kind\":\"resize\",\"node\":4,\"box\":[0,1,2,3,4,5],\"mode\":\"local\","
        "\"region\":[0,0,0,1,1,1]}",
        "{\"kind\":\"resize\",\"node\":\"root\",\"scale\":[2,1,3]}",
        "{\"kind\":\"split\",\"node\":7,\"axis\":\"y\",\"at\":-1.25}",
        "{\"kind\":\"join\",\"nodes\":[3,4]}",
        "{\"kind\":\"paste\",\"source\":[3,8],\"target\":9,\"placement\":\"replace\"}",
        "{\"kind\":\"remove\",\"nodes\":[2]}",
    };
    for (size_t i = 0; i < sizeof ops / sizeof *ops; i++) {
        ag_edit_op a = parse_ok(ops[i]), b;
        json_t *j = ag_edit_op_json_to(&a);
        assert_non_null(j);
        ag_error err = {0};
        assert_int_equal(ag_edit_op_json_from(j, &b, &err), AG_OK);
        assert_int_equal(a.kind, b.kind);
        assert_int_equal(a.node, b.node);
        assert_int_equal(a.nnodes, b.nnodes);
        for (size_t k = 0; k < a.nnodes; k++)
            assert_int_equal(a.nodes[k], b.nodes[k]);
        assert_memory_equal(&a.box, &b.box, sizeof a.box);
        assert_memory_equal(a.scale, b.scale, sizeof a.scale);
        assert_true(a.mode == b.mode && a.axis == b.axis && a.at == b.at);
        assert_true(a.placement == b.placement && a.fit == b.fit);
        json_decref(j);
        ag_edit_op_clear(&a);
        ag_edit_op_clear(&b);
    }
}

/* Each malformed op fails with a message that starts with the field's name. */
static void test_errors_name_the_field(void **state)
{
    (void)state;
    static const struct {
        const char *json, *field;
    } bad[] = {
        {"[1,2]", "op:"},
        {"{\"node\":1}", "kind:"},
        {"{\"kind\":\"stretch\"}", "kind:"},
        {"{\"kind\":\"resize\",\"scale\":[1,1,1]}", "node:"},
        {"{\"kind\":\"resize\",\"node\":-1,\"scale\":[1,1,1]}", "node:"},
        {"{\"kind\":\"resize\",\"node\":\"top\",\"scale\":[1,1,1]}", "node:"},
        {"{\"kind\":\"resize\",\"node\":1.5,\"scale\":[1,1,1]}", "node:"},
        {"{\"kind\":\"resize\",\"node\":1}", "box:"},
        {"{\"kind\":\"resize\",\"node\":1,\"box\":[0,0,0,1,1]}", "box:"},
        {"{\"kind\":\"resize\",\"node\":1,\"box\":[0,0,0,1,1,\"a\"]}", "box[5]:"},
        {"{\"kind\":\"resize\",\"node\":1,\"box\":[0,2,0,1,1,1]}", "box:"},
        {"{\"kind\":\"resize\",\"node\":1,\"box\":[0,0,0,1,1,1],\"scale\":[1,1,1]}", "scale:"},
        {"{\"kind\":\"resize\",\"node\":1,\"scale\":[1,0,1]}", "scale[1]:"},
        {"{\"kind\":\"resize\",\"node\":1,\"scale\":[1,1,1],\"mode\":\"everywhere\"}", "mode:"},
        {"{\"kind\":\"resize\",\"node\":1,\"scale\":[1,1,1],\"region\":[0,0,0,1,1,1]}", "region:"},
        {"{\"kind\":\"resize\",\"node\":1,\"scale\":[1,1,1],\"mode\":\"local\",\"region\":{}}",
         "region:"},
        {"{\"kind\":\"resize\",\"node\":1,\"scale\":[1,1,1],\"colour\":1}", "colour:"},
        {"{\"kind\":\"split\",\"node\":1,\"at\":1}", "axis:"},
        {"{\"kind\":\"split\",\"node\":1,\"axis\":\"w\",\"at\":1}", "axis:"},
        {"{\"kind\":\"split\",\"node\":1,\"axis\":\"x\"}", "at:"},
        {"{\"kind\":\"split\",\"node\":1,\"axis\":\"x\",\"at\":\"1\"}", "at:"},
        {"{\"kind\":\"join\",\"nodes\":[]}", "nodes:"},
        {"{\"kind\":\"join\",\"nodes\":[1]}", "nodes:"},
        {"{\"kind\":\"join\",\"nodes\":[1,\"x\"]}", "nodes[1]:"},
        {"{\"kind\":\"remove\"}", "nodes:"},
        {"{\"kind\":\"paste\",\"target\":1}", "source:"},
        {"{\"kind\":\"paste\",\"source\":[1]}", "target:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":{}}", "target:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"placement\":\"over\"}", "placement:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"fit\":\"stretch\"}", "fit:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"nodes\":[1]}", "nodes:"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_edit_op op;
        ag_error err = {0};
        ag_status st = ag_edit_op_json_parse(bad[i].json, strlen(bad[i].json), &op, &err);
        if (st == AG_OK)
            fail_msg("accepted: %s", bad[i].json);
        assert_int_equal(st, AG_ERR_INVALID);
        if (strncmp(err.text, bad[i].field, strlen(bad[i].field)))
            fail_msg("%s: expected an error naming %s, got \"%s\"", bad[i].json, bad[i].field,
                     err.text);
        assert_null(op.nodes);
        assert_int_equal(op.nnodes, 0);
    }
}

static void test_syntax_error_has_line(void **state)
{
    (void)state;
    const char *text = "{\n\"kind\": \"resize\",\n\"node\": 1,,\n}";
    ag_edit_op op;
    ag_error err = {0};
    assert_int_equal(ag_edit_op_json_parse(text, strlen(text), &op, &err), AG_ERR_PARSE);
    assert_int_equal(err.element, 3);
}

static void test_read_file(void **state)
{
    (void)state;
    char path[] = "/tmp/archgram_test_op_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("{\"kind\":\"remove\",\"nodes\":[\"root\"]}", f);
    fclose(f);
    ag_edit_op op;
    ag_error err = {0};
    assert_int_equal(ag_edit_op_json_read_file(path, &op, &err), AG_OK);
    assert_true(op.kind == AG_EDIT_REMOVE && op.nnodes == 1 && op.nodes[0] == AG_EDIT_ROOT);
    ag_edit_op_clear(&op);
    remove(path);
    assert_int_equal(ag_edit_op_json_read_file(path, &op, &err), AG_ERR_IO);
}

static void test_report_json(void **state)
{
    (void)state;
    ag_edit_report rep = {.equations = 12, .unknowns = 5, .splits = 2, .max_residual = 1e-9};
    ag_mesh *m = ag_mesh_create();
    size_t g, c;
    ag_mesh_add_group(m, "L2", &g);
    for (int k = 0; k < 3; k++) {
        ag_mesh_add_component(m, (int32_t)g, &c);
        ag_mesh_add_vertex(m, k, 0, 0);
        ag_mesh_add_vertex(m, k + 1, 0, 0);
        ag_mesh_add_vertex(m, k, 1, 0);
        ag_mesh_add_triangle(m, 3 * k, 3 * k + 1, 3 * k + 2, (uint32_t)c);
    }
    ag_error err = {0};
    assert_int_equal(ag_edit_report_count_labels(&rep, m, &err), AG_OK);
    json_t *j = ag_edit_op_json_report(&rep);
    assert_int_equal(json_integer_value(json_object_get(j, "equations")), 12);
    assert_int_equal(json_integer_value(json_object_get(j, "splits")), 2);
    assert_int_equal(
        json_integer_value(json_object_get(json_object_get(j, "instances_per_label"), "L2")), 3);
    json_decref(j);
    ag_edit_report_clear(&rep);
    ag_mesh_free(m);
}

/* A paste from another model: its origin is parsed by the _ex calls, refused by the plain
 * ones, and kept by the canonical JSON. */
static void test_paste_origin(void **state)
{
    (void)state;
    const char *m = "{\"kind\":\"paste\",\"source\":[3],\"target\":7,\"source_model\":42}";
    const char *d = "{\"kind\":\"paste\",\"source\":[\"4\"],\"target\":\"root\","
                    "\"source_dir\":\"../other/p\"}";
    ag_edit_op op;
    ag_edit_op_origin o;
    ag_error err = {0};
    assert_int_equal(ag_edit_op_json_parse_ex(m, strlen(m), &op, &o, &err), AG_OK);
    assert_int_equal(o.model, 42);
    assert_null(o.dir);
    assert_null(op.source);
    assert_true(op.kind == AG_EDIT_PASTE && op.nnodes == 1 && op.nodes[0] == 3 && op.node == 7);
    json_t *j = ag_edit_op_json_to_ex(&op, &o);
    assert_int_equal(json_integer_value(json_object_get(j, "source_model")), 42);
    json_decref(j);
    ag_edit_op_clear(&op);
    ag_edit_op_origin_clear(&o);

    assert_int_equal(ag_edit_op_json_parse_ex(d, strlen(d), &op, &o, &err), AG_OK);
    assert_int_equal(o.model, 0);
    assert_string_equal(o.dir, "../other/p");
    j = ag_edit_op_json_to_ex(&op, &o);
    char *text = json_dumps(j, JSON_COMPACT);
    json_decref(j);
    ag_edit_op back;
    ag_edit_op_origin ob;
    assert_int_equal(ag_edit_op_json_parse_ex(text, strlen(text), &back, &ob, &err), AG_OK);
    assert_string_equal(ob.dir, "../other/p");
    assert_int_equal(back.node, AG_EDIT_ROOT);
    free(text);
    ag_edit_op_clear(&back);
    ag_edit_op_origin_clear(&ob);
    ag_edit_op_clear(&op);
    ag_edit_op_origin_clear(&o);

    /* the plain parser cannot load another model: it refuses, naming the field */
    assert_int_equal(ag_edit_op_json_parse(m, strlen(m), &op, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "source_model:"));
    assert_int_equal(ag_edit_op_json_parse(d, strlen(d), &op, &err), AG_ERR_INVALID);
    assert_non_null(strstr(err.text, "source_dir:"));

    static const struct {
        const char *json, *field;
    } bad[] = {
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_model\":0}", "source_model:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_model\":\"x\"}",
         "source_model:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_model\":[1]}", "source_model:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_dir\":\"\"}", "source_dir:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_dir\":7}", "source_dir:"},
        {"{\"kind\":\"paste\",\"source\":[1],\"target\":2,\"source_dir\":\"a\",\"source_model\":3}",
         "source_dir:"},
        {"{\"kind\":\"remove\",\"nodes\":[1],\"source_model\":3}", "source_model:"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ag_error_clear(&err);
        ag_status st = ag_edit_op_json_parse_ex(bad[i].json, strlen(bad[i].json), &op, &o, &err);
        if (st != AG_ERR_INVALID || strncmp(err.text, bad[i].field, strlen(bad[i].field)))
            fail_msg("%s: %d %s", bad[i].json, st, err.text);
        assert_null(o.dir);
        assert_null(op.nodes);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kinds),
        cmocka_unit_test(test_round_trip),
        cmocka_unit_test(test_errors_name_the_field),
        cmocka_unit_test(test_syntax_error_has_line),
        cmocka_unit_test(test_read_file),
        cmocka_unit_test(test_report_json),
        cmocka_unit_test(test_paste_origin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
