#include "tokens.h"

#include <sodium.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HASH_BYTES 32
#define SECRET_BYTES 32
#define MIN_CHOSEN 32

/* sodium_init is thread-safe and cheap after the first call (it returns 1 then). */
static ag_status need_sodium(ag_error *err)
{
    return sodium_init() >= 0
               ? AG_OK
               : ag_error_set(err, AG_ERR_INTERNAL, 0, "libsodium did not initialise");
}

static void hash_text(const char *text, unsigned char hash[HASH_BYTES], int64_t *lookup)
{
    crypto_generichash(hash, HASH_BYTES, (const unsigned char *)text, strlen(text), NULL, 0);
    uint64_t l;
    memcpy(&l, hash, sizeof l);
    *lookup = (int64_t)l;
}

static int token_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
           c == '.' || c == '_' || c == '~' || c == '+' || c == '-';
}

/* Only well-formed text is hashed and looked up. */
static int well_formed(const char *text, size_t min)
{
    size_t n = text ? strlen(text) : 0;
    if (n < min || n > AG_TOKEN_TEXT_MAX)
        return 0;
    for (size_t i = 0; i < n; i++)
        if (!token_char(text[i]))
            return 0;
    return 1;
}

ag_status ag_tokens_check_text(const char *text, ag_error *err)
{
    if (!well_formed(text, MIN_CHOSEN))
        return ag_error_set(err, AG_ERR_INVALID, 0,
                            "a token is %d to %d characters of A-Z a-z 0-9 . _ ~ + -", MIN_CHOSEN,
                            AG_TOKEN_TEXT_MAX);
    return AG_OK;
}

static ag_status check_label(const char *label, ag_error *err)
{
    size_t n = label ? strlen(label) : 0;
    if (n > AG_TOKEN_LABEL_MAX)
        return ag_error_set(err, AG_ERR_INVALID, 0, "a token's label has at most %d bytes",
                            AG_TOKEN_LABEL_MAX);
    for (size_t i = 0; i < n; i++)
        if ((unsigned char)label[i] < 0x20 || label[i] == 0x7f)
            return ag_error_set(err, AG_ERR_INVALID, 0, "a token's label holds no control "
                                                        "characters");
    return AG_OK;
}

static ag_status insert(ag_db *db, int64_t user, const char *text, const char *label,
                        int64_t *id, ag_error *err)
{
    unsigned char hash[HASH_BYTES];
    int64_t lookup;
    hash_text(text, hash, &lookup);
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st, "SELECT 1 FROM tokens WHERE lookup = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, lookup);
    int taken = sqlite3_step(st) == SQLITE_ROW;
    sqlite3_reset(st);
    if (taken)
        return ag_error_set(err, AG_ERR_CONFLICT, 0, "this token is stored already");
    if ((s = ag_db_prepared(db, &st,
                            "INSERT INTO tokens (user_id, lookup, hash, label) VALUES (?, ?, ?, ?)",
                            err)) != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, user);
    sqlite3_bind_int64(st, 2, lookup);
    sqlite3_bind_blob(st, 3, hash, HASH_BYTES, SQLITE_TRANSIENT);
    sqlite3_bind_text(st, 4, label ? label : "", -1, SQLITE_STATIC);
    sodium_memzero(hash, sizeof hash);
    if ((s = ag_db_step_done(db, st, "storing a token", err)) != AG_OK)
        return s;
    *id = sqlite3_last_insert_rowid(ag_db_handle(db));
    return AG_OK;
}

ag_status ag_tokens_create(ag_db *db, int64_t user, const char *label, char *text, int64_t *id,
                           ag_error *err)
{
    text[0] = '\0';
    ag_status s = need_sodium(err);
    if (s == AG_OK)
        s = check_label(label, err);
    if (s != AG_OK)
        return s;
    unsigned char secret[SECRET_BYTES];
    randombytes_buf(secret, sizeof secret);
    memcpy(text, "agt_", 4);
    sodium_bin2base64(text + 4, AG_TOKEN_TEXT_MAX + 1 - 4, secret, sizeof secret,
                      sodium_base64_VARIANT_URLSAFE_NO_PADDING);
    sodium_memzero(secret, sizeof secret);
    s = insert(db, user, text, label, id, err);
    if (s != AG_OK)
        sodium_memzero(text, strlen(text));
    return s;
}

ag_status ag_tokens_add(ag_db *db, int64_t user, const char *text, const char *label,
                        int64_t *id, ag_error *err)
{
    ag_status s = need_sodium(err);
    if (s == AG_OK)
        s = ag_tokens_check_text(text, err);
    if (s == AG_OK)
        s = check_label(label, err);
    return s != AG_OK ? s : insert(db, user, text, label, id, err);
}

int ag_tokens_hash(const char *text, unsigned char hash[32])
{
    int64_t lookup;
    if (need_sodium(NULL) != AG_OK || !well_formed(text, 1))
        return 0;
    hash_text(text, hash, &lookup);
    return 1;
}

ag_status ag_tokens_verify(ag_db *db, const char *text, int64_t *user, int64_t *token,
                           ag_user_row *account, ag_error *err)
{
    *user = *token = 0;
    ag_status s = need_sodium(err);
    if (s != AG_OK)
        return s;
    if (!well_formed(text, 1))
        return ag_error_set(err, AG_ERR_UNAUTHORIZED, 0, "the token is not one this server gave out");
    unsigned char hash[HASH_BYTES];
    int64_t lookup;
    hash_text(text, hash, &lookup);
    sqlite3_stmt *st;
    if ((s = ag_db_prepared(db, &st,
                            "SELECT t.id, t.user_id, t.hash, u.name, u.role, u.created_at "
                            "FROM tokens t JOIN users u ON u.id = t.user_id WHERE t.lookup = ?",
                            err)) != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, lookup);
    int rc = sqlite3_step(st);
    if (rc == SQLITE_ROW) {
        const void *stored = sqlite3_column_blob(st, 2);
        int match = stored && sqlite3_column_bytes(st, 2) == HASH_BYTES &&
                    sodium_memcmp(stored, hash, HASH_BYTES) == 0;
        if (match) {
            *token = sqlite3_column_int64(st, 0);
            *user = sqlite3_column_int64(st, 1);
        }
        if (match && account) {
            memset(account, 0, sizeof *account);
            account->id = *user;
            ag_db_column_copy(st, 3, account->name, sizeof account->name);
            if (ag_users_role_parse((const char *)sqlite3_column_text(st, 4), &account->role,
                                    NULL) != AG_OK)
                account->role = AG_ACCOUNT_VIEWER;
            ag_db_column_copy(st, 5, account->created_at, sizeof account->created_at);
        }
        s = match ? AG_OK
                  : ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                                 "the token is not one this server gave out");
    } else if (rc == SQLITE_DONE) {
        s = ag_error_set(err, AG_ERR_UNAUTHORIZED, 0,
                         "the token is not one this server gave out (or it was revoked)");
    } else {
        s = ag_db_fail(db, err, "checking a token");
    }
    sqlite3_reset(st);
    sodium_memzero(hash, sizeof hash);
    return s;
}

ag_status ag_tokens_list(ag_db *db, int64_t user, size_t limit, ag_token_row **rows,
                         size_t *count, ag_error *err)
{
    *rows = NULL;
    *count = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(db, &st,
                                 "SELECT id, user_id, label, created_at FROM tokens "
                                 "WHERE user_id = ? ORDER BY id LIMIT ?",
                                 err);
    if (s != AG_OK)
        return s;
    ag_token_row *out = calloc(limit ? limit : 1, sizeof *out);
    if (!out)
        return ag_error_set(err, AG_ERR_NOMEM, 0, "out of memory listing tokens");
    sqlite3_bind_int64(st, 1, user);
    sqlite3_bind_int64(st, 2, (sqlite3_int64)limit);
    size_t n = 0;
    int rc = SQLITE_DONE;
    while (n < limit && (rc = sqlite3_step(st)) == SQLITE_ROW) {
        ag_token_row *t = &out[n++];
        t->id = sqlite3_column_int64(st, 0);
        t->user = sqlite3_column_int64(st, 1);
        ag_db_column_copy(st, 2, t->label, sizeof t->label);
        ag_db_column_copy(st, 3, t->created_at, sizeof t->created_at);
    }
    if (n < limit && rc != SQLITE_DONE)
        s = ag_db_fail(db, err, "listing tokens");
    sqlite3_reset(st);
    if (s != AG_OK) {
        free(out);
        return s;
    }
    *rows = out;
    *count = n;
    return AG_OK;
}

ag_status ag_tokens_delete(ag_db *db, int64_t user, int64_t id, ag_error *err)
{
    sqlite3_stmt *st;
    ag_status s =
        ag_db_prepared(db, &st, "DELETE FROM tokens WHERE id = ? AND user_id = ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, id);
    sqlite3_bind_int64(st, 2, user);
    if ((s = ag_db_step_done(db, st, "revoking a token", err)) != AG_OK)
        return s;
    if (sqlite3_changes(ag_db_handle(db)) == 0)
        return ag_error_set(err, AG_ERR_NOT_FOUND, 0, "there is no token %lld of this account",
                            (long long)id);
    return AG_OK;
}

ag_status ag_tokens_delete_label(ag_db *db, int64_t user, const char *label, int64_t keep,
                                 int *removed, ag_error *err)
{
    *removed = 0;
    sqlite3_stmt *st;
    ag_status s = ag_db_prepared(
        db, &st, "DELETE FROM tokens WHERE user_id = ? AND label = ? AND id != ?", err);
    if (s != AG_OK)
        return s;
    sqlite3_bind_int64(st, 1, user);
    sqlite3_bind_text(st, 2, label, -1, SQLITE_STATIC);
    sqlite3_bind_int64(st, 3, keep);
    if ((s = ag_db_step_done(db, st, "revoking tokens", err)) == AG_OK)
        *removed = sqlite3_changes(ag_db_handle(db));
    return s;
}
