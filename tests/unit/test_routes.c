/* The route table: matching, 405 Allow lists, and agreement with the OpenAPI document. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <string.h>
#include <strings.h>

#include "embedded.h"
#include "net/routes.h"

static void matches_ids_and_rejects_non_ids(void **state)
{
    (void)state;
    const ag_route *route = NULL;
    int64_t ids[2] = {0, 0};
    char allow[64];
    assert_int_equal(ag_routes_match("GET", "/api/v1/models/42/mesh.glb", &route, ids, allow,
                                     sizeof allow),
                     AG_MATCH_OK);
    assert_string_equal(route->pattern, "/api/v1/models/{id}/mesh.glb");
    assert_int_equal(ids[0], 42);
    assert_int_equal(ag_routes_match("GET", "/api/v1/models/abc", &route, ids, allow, sizeof allow),
                     AG_MATCH_NONE);
    assert_int_equal(ag_routes_match("GET", "/api/v1/models/007", &route, ids, allow, sizeof allow),
                     AG_MATCH_NONE);
    assert_int_equal(ag_routes_match("GET", "/api/v1/models/1/", &route, ids, allow, sizeof allow),
                     AG_MATCH_NONE);
    assert_int_equal(ag_routes_match("GET", "/api/v1/nothing", &route, ids, allow, sizeof allow),
                     AG_MATCH_NONE);
}

static void wrong_method_lists_the_allowed_ones(void **state)
{
    (void)state;
    const ag_route *route = NULL;
    int64_t ids[2];
    char allow[64];
    assert_int_equal(ag_routes_match("PUT", "/api/v1/models/3", &route, ids, allow, sizeof allow),
                     AG_MATCH_PATH_ONLY);
    assert_non_null(strstr(allow, "GET"));
    assert_non_null(strstr(allow, "PATCH"));
    assert_non_null(strstr(allow, "DELETE"));
    assert_null(strstr(allow, "POST"));
}

/* "/api/v1/models/{id}" + "get" must be in the document for every route, and every
 * operation in the document must be a route. */
static void openapi_and_route_table_agree(void **state)
{
    (void)state;
    json_error_t je;
    json_t *doc = json_loads(ag_openapi_json, 0, &je);
    assert_non_null(doc);
    assert_string_equal(json_string_value(json_object_get(doc, "openapi")), "3.1.0");
    json_t *paths = json_object_get(doc, "paths");
    assert_true(json_is_object(paths));
    for (size_t i = 0; i < ag_routes_count; i++) {
        json_t *item = json_object_get(paths, ag_routes[i].pattern);
        if (!item)
            fail_msg("route %s is not in openapi.json", ag_routes[i].pattern);
        char method[16];
        size_t n = strlen(ag_routes[i].method);
        for (size_t k = 0; k <= n; k++)
            method[k] = (char)(ag_routes[i].method[k] | (k < n ? 0x20 : 0));
        if (!json_object_get(item, method))
            fail_msg("%s %s is not in openapi.json", ag_routes[i].method, ag_routes[i].pattern);
    }
    const char *path;
    json_t *item;
    static const char *const verbs[] = {"get", "put", "post", "delete", "patch", "head", "options"};
    json_object_foreach(paths, path, item) {
        for (size_t v = 0; v < sizeof verbs / sizeof verbs[0]; v++) {
            if (!json_object_get(item, verbs[v]))
                continue;
            int found = 0;
            for (size_t i = 0; i < ag_routes_count; i++)
                found |= strcmp(ag_routes[i].pattern, path) == 0 &&
                         strcasecmp(ag_routes[i].method, verbs[v]) == 0;
            if (!found)
                fail_msg("openapi.json describes %s %s, which no route serves", verbs[v], path);
        }
    }
    json_decref(doc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(matches_ids_and_rejects_non_ids),
        cmocka_unit_test(wrong_method_lists_the_allowed_ones),
        cmocka_unit_test(openapi_and_route_table_agree),
    };
    return cmocka_run_group_tests_name("routes", tests, NULL, NULL);
}
