/* Roles on models in the store: members and their roles, the public-read flag, who a list of
 * models shows to whom, the owner a job's model gets, the role rule of the access checks, and
 * a database from before accounts brought up to date. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/auth.h"
#include "store/jobs.h"
#include "store/members.h"
#include "store/users.h"
#include "store_fixture.h"

typedef struct {
    char *path;
    ag_db *db;
    int64_t ana, bo, cy, m1, m2, m3;
} fixture;

static int64_t model(ag_db *db, const char *name)
{
    ag_model_new m = {.name = name, .mesh = "m", .mesh_len = 1};
    return insert_model(db, &m);
}

static void put(ag_db *db, int64_t m, int64_t u, ag_model_role role)
{
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_members_put(db, m, u, role, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->db = open_temp_db(&f->path);
    f->ana = insert_user(f->db, "ana", AG_ACCOUNT_EDITOR);
    f->bo = insert_user(f->db, "bo", AG_ACCOUNT_EDITOR);
    f->cy = insert_user(f->db, "cy", AG_ACCOUNT_VIEWER);
    f->m1 = model(f->db, "one");
    f->m2 = model(f->db, "two");
    f->m3 = model(f->db, "three");
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    close_temp_db(f->db, f->path);
    free(f);
    return 0;
}

static ag_model_role role_of(ag_db *db, int64_t m, int64_t u, int *pub)
{
    ag_model_role r;
    ag_error err;
    assert_int_equal(ag_members_access(db, m, u, &r, pub, &err), AG_OK);
    return r;
}

static void members_have_one_role_each(void **state)
{
    fixture *f = *state;
    int pub = -1;
    assert_int_equal(role_of(f->db, f->m1, f->ana, &pub), AG_ROLE_NONE);
    assert_int_equal(pub, 0);
    put(f->db, f->m1, f->ana, AG_ROLE_OWNER);
    put(f->db, f->m1, f->bo, AG_ROLE_VIEWER);
    put(f->db, f->m1, f->bo, AG_ROLE_EDITOR); /* replaces */
    assert_int_equal(role_of(f->db, f->m1, f->ana, &pub), AG_ROLE_OWNER);
    assert_int_equal(role_of(f->db, f->m1, f->bo, &pub), AG_ROLE_EDITOR);
    assert_int_equal(role_of(f->db, f->m2, f->bo, &pub), AG_ROLE_NONE);
    assert_int_equal(role_of(f->db, f->m1, 0, &pub), AG_ROLE_NONE);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_members"), 2);
    assert_int_equal(ag_members_owners(f->db, f->m1), 1);
    ag_member_row *rows;
    size_t n;
    ag_error err;
    assert_int_equal(ag_members_list(f->db, f->m1, 10, &rows, &n, &err), AG_OK);
    assert_int_equal(n, 2);
    assert_string_equal(rows[0].name, "ana");
    assert_int_equal(rows[0].role, AG_ROLE_OWNER);
    assert_string_equal(rows[1].name, "bo");
    free(rows);
    int removed = 0;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_members_remove(f->db, f->m1, f->bo, &removed, &err), AG_OK);
    assert_int_equal(removed, 1);
    assert_int_equal(ag_members_remove(f->db, f->m1, f->bo, &removed, &err), AG_OK);
    assert_int_equal(removed, 0);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    ag_model_role r;
    assert_int_equal(ag_members_access(f->db, 999, f->ana, &r, &pub, &err), AG_ERR_NOT_FOUND);
    ag_model_role parsed;
    assert_int_equal(ag_members_role_parse("admin", &parsed, &err), AG_ERR_INVALID);
    /* the schema refuses other roles too */
    assert_int_not_equal(sqlite3_exec(ag_db_handle(f->db),
                                      "INSERT INTO model_members VALUES (1, 1, 'boss')", NULL,
                                      NULL, NULL),
                         SQLITE_OK);
    /* members go with their model and with their account */
    put(f->db, f->m2, f->cy, AG_ROLE_VIEWER);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_delete(f->db, f->m1, 1, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_members"), 1);
    assert_int_equal(sqlite3_exec(ag_db_handle(f->db), "DELETE FROM users WHERE name = 'cy'", NULL,
                                  NULL, NULL),
                     SQLITE_OK);
    assert_int_equal(count(f->db, "SELECT count(*) FROM model_members"), 0);
}

static size_t listed(ag_db *db, int64_t visible_to, int64_t *ids, char roles[][8])
{
    ag_model_row *rows;
    size_t n;
    ag_error err;
    assert_int_equal(ag_models_list(db, visible_to, 0, 100, &rows, &n, &err), AG_OK);
    for (size_t i = 0; i < n; i++) {
        ids[i] = rows[i].id;
        if (roles)
            snprintf(roles[i], 8, "%s", rows[i].member_role);
        ag_models_row_clear(&rows[i]);
    }
    free(rows);
    return n;
}

static void lists_show_what_an_account_may_see(void **state)
{
    fixture *f = *state;
    put(f->db, f->m1, f->ana, AG_ROLE_OWNER);
    put(f->db, f->m3, f->ana, AG_ROLE_VIEWER);
    put(f->db, f->m2, f->bo, AG_ROLE_OWNER);
    ag_error err;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_models_set_public_read(f->db, f->m2, 1, &err), AG_OK);
    assert_int_equal(ag_models_set_public_read(f->db, 999, 1, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    int64_t ids[8];
    char roles[8][8];
    assert_int_equal(listed(f->db, f->ana, ids, roles), 3);
    assert_int_equal(ids[0], f->m1);
    assert_string_equal(roles[0], "owner");
    assert_int_equal(ids[1], f->m2);
    assert_string_equal(roles[1], ""); /* public: no role of ana's */
    assert_int_equal(ids[2], f->m3);
    assert_string_equal(roles[2], "viewer");
    assert_int_equal(listed(f->db, f->cy, ids, roles), 1);
    assert_int_equal(ids[0], f->m2);
    assert_int_equal(listed(f->db, 0, ids, NULL), 3); /* everything, for admins */
    /* paging goes on past what is hidden */
    ag_model_row *rows;
    size_t n;
    assert_int_equal(ag_models_list(f->db, f->cy, f->m1, 1, &rows, &n, &err), AG_OK);
    assert_int_equal(n, 1);
    assert_int_equal(rows[0].id, f->m2);
    assert_int_equal(rows[0].public_read, 1);
    ag_models_row_clear(&rows[0]);
    free(rows);
    assert_int_equal(ag_models_list(f->db, f->cy, f->m2, 5, &rows, &n, &err), AG_OK);
    assert_int_equal(n, 0);
    free(rows);
}

static void a_jobs_model_is_its_askers(void **state)
{
    fixture *f = *state;
    ag_error err;
    int64_t asked = 0, server = 0;
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_jobs_insert(f->db, "import", "{}", f->bo, &asked, &err), AG_OK);
    assert_int_equal(ag_jobs_insert(f->db, "import", "{}", 0, &server, &err), AG_OK);
    assert_int_equal(ag_members_own_from_job(f->db, f->m1, asked, &err), AG_OK);
    assert_int_equal(ag_members_own_from_job(f->db, f->m2, server, &err), AG_OK);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    int pub;
    assert_int_equal(role_of(f->db, f->m1, f->bo, &pub), AG_ROLE_OWNER);
    assert_int_equal(pub, 0);
    assert_int_equal(role_of(f->db, f->m2, f->bo, &pub), AG_ROLE_NONE);
    assert_int_equal(pub, 1); /* the server's own content is readable by every account */
    ag_job_row row;
    assert_int_equal(ag_jobs_get(f->db, asked, &row, &err), AG_OK);
    assert_int_equal(row.user, f->bo);
    ag_jobs_row_clear(&row);
    assert_int_equal(ag_jobs_get(f->db, server, &row, &err), AG_OK);
    assert_int_equal(row.user, 0);
    ag_jobs_row_clear(&row);
}

static void the_role_rule(void **state)
{
    (void)state;
    ag_identity admin = {.user = 1, .role = AG_ACCOUNT_ADMIN};
    ag_identity editor = {.user = 2, .role = AG_ACCOUNT_EDITOR};
    ag_identity viewer = {.user = 3, .role = AG_ACCOUNT_VIEWER};
    /* admins own everything, seen or not */
    assert_int_equal(ag_auth_role(&admin, AG_ROLE_NONE, 0), AG_ROLE_OWNER);
    assert_int_equal(ag_auth_role(&admin, AG_ROLE_VIEWER, 1), AG_ROLE_OWNER);
    /* a member has the role given, whatever its account role and the public flag */
    assert_int_equal(ag_auth_role(&editor, AG_ROLE_VIEWER, 1), AG_ROLE_VIEWER);
    assert_int_equal(ag_auth_role(&viewer, AG_ROLE_EDITOR, 0), AG_ROLE_EDITOR);
    assert_int_equal(ag_auth_role(&viewer, AG_ROLE_OWNER, 0), AG_ROLE_OWNER);
    /* everyone else: viewer of public models, nothing otherwise */
    assert_int_equal(ag_auth_role(&editor, AG_ROLE_NONE, 1), AG_ROLE_VIEWER);
    assert_int_equal(ag_auth_role(&editor, AG_ROLE_NONE, 0), AG_ROLE_NONE);
    ag_identity local;
    ag_auth_local(&local);
    assert_string_equal(local.name, "local");
    assert_int_equal(local.user, 0);
    assert_int_equal(ag_auth_role(&local, AG_ROLE_NONE, 0), AG_ROLE_OWNER);
}

static void a_database_from_before_accounts(void **state)
{
    (void)state;
    char *path = old_database(ag_migrations_count - 1);
    ag_db *db = open_old_database(path);
    /* its models have no members: only admins (who see everything) reach them */
    int64_t ids[4];
    assert_int_equal(listed(db, 0, ids, NULL), 1);
    assert_int_equal(ids[0], 5);
    assert_int_equal(count(db, "SELECT count(*) FROM users"), 0);
    assert_int_equal(count(db, "SELECT public_read FROM models WHERE id = 5"), 0);
    assert_int_equal(count(db, "SELECT count(*) FROM jobs WHERE user_id IS NOT NULL"), 0);
    int64_t ana = insert_user(db, "ana", AG_ACCOUNT_EDITOR);
    assert_int_equal(listed(db, ana, ids, NULL), 0);
    ag_db_close(db);
    remove_db(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(members_have_one_role_each, setup, teardown),
        cmocka_unit_test_setup_teardown(lists_show_what_an_account_may_see, setup, teardown),
        cmocka_unit_test_setup_teardown(a_jobs_model_is_its_askers, setup, teardown),
        cmocka_unit_test(the_role_rule),
        cmocka_unit_test(a_database_from_before_accounts),
    };
    return cmocka_run_group_tests_name("members", tests, NULL, NULL);
}
