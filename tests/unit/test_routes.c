/* The route table: matching, 405 Allow lists, and agreement with the OpenAPI document. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <jansson.h>
#include <string.h>
#include <stdio.h>
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

/* Who may call a route is declared by its row: every row declares it, only the health check
 * and the API document are open, a route under a model needs a role on that model (or is an
 * admin's), and nothing that changes state is open to everyone. */
static void every_route_declares_who_may_call_it(void **state)
{
    (void)state;
    int open = 0;
    for (size_t i = 0; i < ag_routes_count; i++) {
        const ag_route *r = &ag_routes[i];
        if (r->need == AG_NEED_UNDECLARED)
            fail_msg("%s %s declares no need", r->method, r->pattern);
        int reads = strcmp(r->method, "GET") == 0;
        if (r->need == AG_NEED_NOTHING) {
            open++;
            if (!reads)
                fail_msg("%s %s changes state without a token", r->method, r->pattern);
        }
        if (strncmp(r->pattern, "/api/v1/models/{id}", 19) == 0 &&
            r->need != AG_NEED_MODEL_VIEWER && r->need != AG_NEED_MODEL_EDITOR &&
            r->need != AG_NEED_MODEL_OWNER && r->need != AG_NEED_ADMIN)
            fail_msg("%s %s is on a model but needs no role on it", r->method, r->pattern);
        if (strncmp(r->pattern, "/api/v1/models/{id}", 19) == 0 && !reads &&
            r->need == AG_NEED_MODEL_VIEWER)
            fail_msg("%s %s lets viewers change the model", r->method, r->pattern);
        if (strncmp(r->pattern, "/api/v1/jobs/{id}", 17) == 0 && r->need != AG_NEED_JOB)
            fail_msg("%s %s is on a job but not its asker's", r->method, r->pattern);
    }
    assert_int_equal(open, 2);
}

static void name_segments_match_account_names_only(void **state)
{
    (void)state;
    const ag_route *route = NULL;
    int64_t ids[2];
    char name[AG_USER_NAME_MAX + 1], allow[64];
    assert_int_equal(ag_routes_find("PUT", "/api/v1/models/7/members/ana.b-c_d", &route, ids,
                                    name, allow, sizeof allow),
                     AG_MATCH_OK);
    assert_string_equal(route->pattern, "/api/v1/models/{id}/members/{name}");
    assert_int_equal(ids[0], 7);
    assert_string_equal(name, "ana.b-c_d");
    assert_int_equal(route->need, AG_NEED_MODEL_OWNER);
    for (const char *const *p = (const char *const[]){"/api/v1/models/7/members/..",
                                                      "/api/v1/models/7/members/",
                                                      "/api/v1/models/7/members/a%20b",
                                                      "/api/v1/models/7/members/a/b", NULL};
         *p; p++)
        assert_int_equal(ag_routes_find("PUT", *p, &route, ids, name, allow, sizeof allow),
                         AG_MATCH_NONE);
    char long_path[200];
    char long_name[AG_USER_NAME_MAX + 2];
    memset(long_name, 'a', sizeof long_name - 1);
    long_name[sizeof long_name - 1] = '\0';
    snprintf(long_path, sizeof long_path, "/api/v1/users/%s/tokens", long_name);
    assert_int_equal(ag_routes_find("POST", long_path, &route, ids, name, allow, sizeof allow),
                     AG_MATCH_NONE);
    long_name[AG_USER_NAME_MAX] = '\0';
    snprintf(long_path, sizeof long_path, "/api/v1/users/%s/tokens", long_name);
    assert_int_equal(ag_routes_find("POST", long_path, &route, ids, name, allow, sizeof allow),
                     AG_MATCH_OK);
    assert_string_equal(name, long_name);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_route_declares_who_may_call_it),
        cmocka_unit_test(name_segments_match_account_names_only),
        cmocka_unit_test(matches_ids_and_rejects_non_ids),
        cmocka_unit_test(wrong_method_lists_the_allowed_ones),
        cmocka_unit_test(openapi_and_route_table_agree),
    };
    return cmocka_run_group_tests_name("routes", tests, NULL, NULL);
}
