/* API tokens and accounts in the store: tokens are random, shown once, kept only as a 32-byte
 * hash, found again by their text alone, revoked at once; a token chosen elsewhere must be
 * long enough; account names and roles are checked. The checks read the table directly, not
 * only through the functions under test. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "store/tokens.h"
#include "store/users.h"
#include "store_fixture.h"

typedef struct {
    char *path;
    ag_db *db;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->db = open_temp_db(&f->path);
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

static void new_token(ag_db *db, int64_t owner, const char *label, char *text, int64_t *id)
{
    ag_error err;
    assert_int_equal(ag_db_begin(db, &err), AG_OK);
    assert_int_equal(ag_tokens_create(db, owner, label, text, id, &err), AG_OK);
    assert_int_equal(ag_db_commit(db, &err), AG_OK);
}

/* Does any text or blob cell of the tokens table hold needle? */
static int stored_anywhere(ag_db *db, const void *needle, size_t n)
{
    sqlite3_stmt *st;
    assert_int_equal(sqlite3_prepare_v2(ag_db_handle(db),
                                        "SELECT id, user_id, lookup, hash, label, created_at "
                                        "FROM tokens",
                                        -1, &st, NULL),
                     SQLITE_OK);
    int found = 0;
    while (sqlite3_step(st) == SQLITE_ROW)
        for (int c = 0; c < 6; c++) {
            const void *p = sqlite3_column_blob(st, c);
            size_t len = (size_t)sqlite3_column_bytes(st, c);
            if (p && len >= n && memmem(p, len, needle, n))
                found = 1;
        }
    sqlite3_finalize(st);
    return found;
}

static void tokens_are_random_and_kept_as_hashes(void **state)
{
    fixture *f = *state;
    int64_t ana = insert_user(f->db, "ana", AG_ACCOUNT_EDITOR);
    char a[AG_TOKEN_TEXT_MAX + 1], b[AG_TOKEN_TEXT_MAX + 1];
    int64_t ida, idb;
    new_token(f->db, ana, "laptop", a, &ida);
    new_token(f->db, ana, "ci", b, &idb);
    assert_int_equal(strncmp(a, "agt_", 4), 0);
    assert_int_equal(strlen(a), 4 + 43);
    assert_string_not_equal(a, b);
    assert_int_equal(count(f->db, "SELECT count(*) FROM tokens WHERE length(hash) = 32"), 2);
    /* neither the text nor its secret part is stored */
    assert_false(stored_anywhere(f->db, a, strlen(a)));
    assert_false(stored_anywhere(f->db, a + 4, strlen(a) - 4));
    assert_false(stored_anywhere(f->db, b + 4, 20));
    /* and each text finds its own row */
    int64_t who, which;
    ag_error err;
    assert_int_equal(ag_tokens_verify(f->db, a, &who, &which, NULL, &err), AG_OK);
    assert_int_equal(who, ana);
    assert_int_equal(which, ida);
    assert_int_equal(ag_tokens_verify(f->db, b, &who, &which, NULL, &err), AG_OK);
    assert_int_equal(which, idb);
}

static void a_changed_token_is_refused(void **state)
{
    fixture *f = *state;
    int64_t bo = insert_user(f->db, "bo", AG_ACCOUNT_VIEWER);
    char t[AG_TOKEN_TEXT_MAX + 1];
    int64_t id, who, which;
    new_token(f->db, bo, NULL, t, &id);
    ag_error err;
    /* every single character changed, one at a time, and cut short or made longer */
    size_t n = strlen(t);
    for (size_t i = 0; i < n; i++) {
        char c[AG_TOKEN_TEXT_MAX + 1];
        memcpy(c, t, n + 1);
        c[i] = c[i] == 'A' ? 'B' : 'A';
        assert_int_equal(ag_tokens_verify(f->db, c, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
        assert_int_equal(who, 0);
    }
    char shorter[AG_TOKEN_TEXT_MAX + 1];
    memcpy(shorter, t, n - 1);
    shorter[n - 1] = '\0';
    assert_int_equal(ag_tokens_verify(f->db, shorter, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    char longer[AG_TOKEN_TEXT_MAX + 2];
    snprintf(longer, sizeof longer, "%sx", t);
    assert_int_equal(ag_tokens_verify(f->db, longer, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, "", &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, "agt_\n", &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, NULL, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, t, &who, &which, NULL, &err), AG_OK);
}

static void revoking_takes_effect_at_once(void **state)
{
    fixture *f = *state;
    int64_t cy = insert_user(f->db, "cy", AG_ACCOUNT_EDITOR);
    int64_t dee = insert_user(f->db, "dee", AG_ACCOUNT_EDITOR);
    char t1[AG_TOKEN_TEXT_MAX + 1], t2[AG_TOKEN_TEXT_MAX + 1];
    int64_t id1, id2, who, which;
    new_token(f->db, cy, "one", t1, &id1);
    new_token(f->db, cy, "two", t2, &id2);
    ag_error err;
    /* another account cannot revoke it */
    assert_int_equal(ag_tokens_delete(f->db, dee, id1, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_tokens_verify(f->db, t1, &who, &which, NULL, &err), AG_OK);
    assert_int_equal(ag_tokens_delete(f->db, cy, id1, &err), AG_OK);
    assert_int_equal(ag_tokens_verify(f->db, t1, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, t2, &who, &which, NULL, &err), AG_OK);
    ag_token_row *rows;
    size_t n;
    assert_int_equal(ag_tokens_list(f->db, cy, 10, &rows, &n, &err), AG_OK);
    assert_int_equal(n, 1);
    assert_string_equal(rows[0].label, "two");
    free(rows);
    /* an account's tokens go with it */
    assert_int_equal(sqlite3_exec(ag_db_handle(f->db), "DELETE FROM users WHERE name = 'cy'", NULL,
                                  NULL, NULL),
                     SQLITE_OK);
    assert_int_equal(ag_tokens_verify(f->db, t2, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
}

static void chosen_tokens_must_be_long_and_plain(void **state)
{
    fixture *f = *state;
    int64_t admin = insert_user(f->db, "admin", AG_ACCOUNT_ADMIN);
    ag_error err;
    int64_t id, who, which;
    const char *good = "0123456789abcdef0123456789abcdef-from-a-secret";
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_tokens_add(f->db, admin, "short", "f", &id, &err), AG_ERR_INVALID);
    assert_int_equal(ag_tokens_add(f->db, admin, "0123456789abcdef0123456789abcdef with space",
                                   "f", &id, &err),
                     AG_ERR_INVALID);
    assert_int_equal(ag_tokens_add(f->db, admin, good, "file", &id, &err), AG_OK);
    assert_int_equal(ag_tokens_add(f->db, admin, good, "file", &id, &err), AG_ERR_CONFLICT);
    assert_int_equal(ag_db_commit(f->db, &err), AG_OK);
    assert_false(stored_anywhere(f->db, good, strlen(good)));
    assert_int_equal(ag_tokens_verify(f->db, good, &who, &which, NULL, &err), AG_OK);
    assert_int_equal(who, admin);
    /* rotation: tokens of a label but the one kept are revoked */
    char other[AG_TOKEN_TEXT_MAX + 1];
    int64_t kept;
    new_token(f->db, admin, "file", other, &kept);
    int removed = 0;
    assert_int_equal(ag_tokens_delete_label(f->db, admin, "file", kept, &removed, &err), AG_OK);
    assert_int_equal(removed, 1);
    assert_int_equal(ag_tokens_verify(f->db, good, &who, &which, NULL, &err), AG_ERR_UNAUTHORIZED);
    assert_int_equal(ag_tokens_verify(f->db, other, &who, &which, NULL, &err), AG_OK);
}

static void account_names_and_roles(void **state)
{
    fixture *f = *state;
    ag_error err;
    for (const char *const *n = (const char *const[]){"ana", "Bo.2", "rest-user", "x_y", NULL}; *n;
         n++)
        assert_int_equal(ag_users_check_name(*n, &err), AG_OK);
    for (const char *const *n = (const char *const[]){"", ".x", "-x", "a b", "a/b", "é", "..", NULL};
         *n; n++)
        assert_int_equal(ag_users_check_name(*n, &err), AG_ERR_INVALID);
    char long_name[80];
    memset(long_name, 'a', 65);
    long_name[65] = '\0';
    assert_int_equal(ag_users_check_name(long_name, &err), AG_ERR_INVALID);
    long_name[64] = '\0';
    assert_int_equal(ag_users_check_name(long_name, &err), AG_OK);
    ag_account_role r;
    assert_int_equal(ag_users_role_parse("admin", &r, &err), AG_OK);
    assert_int_equal(r, AG_ACCOUNT_ADMIN);
    assert_int_equal(ag_users_role_parse("root", &r, &err), AG_ERR_INVALID);
    int64_t id = insert_user(f->db, "eve", AG_ACCOUNT_VIEWER);
    assert_int_equal(ag_db_begin(f->db, &err), AG_OK);
    assert_int_equal(ag_users_insert(f->db, "eve", AG_ACCOUNT_EDITOR, &id, &err), AG_ERR_CONFLICT);
    ag_db_rollback(f->db);
    ag_user_row row;
    assert_int_equal(ag_users_find(f->db, "eve", &row, &err), AG_OK);
    assert_int_equal(row.role, AG_ACCOUNT_VIEWER);
    assert_int_equal(ag_users_find(f->db, "nobody", &row, &err), AG_ERR_NOT_FOUND);
    assert_int_equal(ag_users_count(f->db), 1);
    /* the schema itself refuses what the checks refuse */
    assert_int_not_equal(sqlite3_exec(ag_db_handle(f->db),
                                      "INSERT INTO users (name, role) VALUES ('z', 'root')", NULL,
                                      NULL, NULL),
                         SQLITE_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(tokens_are_random_and_kept_as_hashes, setup, teardown),
        cmocka_unit_test_setup_teardown(a_changed_token_is_refused, setup, teardown),
        cmocka_unit_test_setup_teardown(revoking_takes_effect_at_once, setup, teardown),
        cmocka_unit_test_setup_teardown(chosen_tokens_must_be_long_and_plain, setup, teardown),
        cmocka_unit_test_setup_teardown(account_names_and_roles, setup, teardown),
    };
    return cmocka_run_group_tests_name("tokens", tests, NULL, NULL);
}
