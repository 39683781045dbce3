/* API tokens: random secrets (libsodium's randombytes_buf) shown once when they are made and
 * stored only as a BLAKE2b-256 hash (crypto_generichash). A token is found by the first 8
 * bytes of its hash and accepted when the whole hash matches, compared in constant time
 * (sodium_memcmp). Tokens this server makes are "agt_" and 43 base64url characters (256 random
 * bits); a token chosen elsewhere (a docker secret) may be any 32..256 characters of
 * A-Z a-z 0-9 . _ ~ + - (characters a websocket subprotocol may carry). */
#ifndef AG_TOKENS_H
#define AG_TOKENS_H

#include <stddef.h>
#include <stdint.h>

#include "db.h"
#include "users.h"

#define AG_TOKEN_TEXT_MAX 256
#define AG_TOKEN_LABEL_MAX 100

typedef struct {
    int64_t id;
    int64_t user;
    char label[AG_TOKEN_LABEL_MAX + 1];
    char created_at[32];
} ag_token_row;

/* A new random token for user, inside the caller's transaction: text (at least
 * AG_TOKEN_TEXT_MAX + 1 bytes) gets the token, which is kept nowhere; *id its row. */
ag_status ag_tokens_create(ag_db *db, int64_t user, const char *label, char *text, int64_t *id,
                           ag_error *err);
/* Stores a token chosen elsewhere (AG_ERR_INVALID when it is too short or holds other
 * characters; AG_ERR_CONFLICT when it is stored already). */
ag_status ag_tokens_add(ag_db *db, int64_t user, const char *text, const char *label,
                        int64_t *id, ag_error *err);
/* Whose token text is: *user and *token (its row), and in *account (may be NULL) the account
 * itself, read in the same query. AG_ERR_UNAUTHORIZED when no stored token has this text. */
ag_status ag_tokens_verify(ag_db *db, const char *text, int64_t *user, int64_t *token,
                           ag_user_row *account, ag_error *err);
/* The hash a token is kept as (32 bytes); 0 when text is not a well-formed token. */
int ag_tokens_hash(const char *text, unsigned char hash[32]);
/* A user's tokens, oldest first, at most limit; *rows is malloc'd. */
ag_status ag_tokens_list(ag_db *db, int64_t user, size_t limit, ag_token_row **rows,
                         size_t *count, ag_error *err);
/* Revokes one of user's tokens; AG_ERR_NOT_FOUND when user has no token id. */
ag_status ag_tokens_delete(ag_db *db, int64_t user, int64_t id, ag_error *err);
/* Revokes every token of user with this label but keep (0: none); *removed counts them. */
ag_status ag_tokens_delete_label(ag_db *db, int64_t user, const char *label, int64_t keep,
                                 int *removed, ag_error *err);
/* The checks ag_tokens_add makes on a token chosen elsewhere. */
ag_status ag_tokens_check_text(const char *text, ag_error *err);

#endif
