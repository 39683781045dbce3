/* Hashing of text for the open-addressing tables and content keys of core: FNV-1a, which
 * needs no table and is plenty for names and short keys (the positions' hashes are in
 * proc/weld.h). */
#ifndef AG_BASE_HASH_H
#define AG_BASE_HASH_H

#include <stdint.h>

/* FNV-1a of a NUL-terminated text; NULL hashes as the empty text. */
static inline uint64_t ag_hash_text(const char *s)
{
    uint64_t h = 1469598103934665603ULL;
    for (; s && *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ULL;
    return h;
}

#endif
