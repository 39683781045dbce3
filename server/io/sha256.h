/* SHA-256 of a buffer as 64 lowercase hex digits (OpenSSL's libcrypto), for content-addressed
 * files such as the terminals of part bundles. */
#ifndef AG_SHA256_H
#define AG_SHA256_H

#include <stddef.h>

#include "../core/status.h"

#define AG_SHA256_HEX 65 /* 64 digits and the NUL */

ag_status ag_sha256_hex(const void *data, size_t len, char out[AG_SHA256_HEX], ag_error *err);
/* Non-zero when s is exactly 64 lowercase hex digits. */
int ag_sha256_is_hex(const char *s);

#endif
