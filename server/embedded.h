/* Files compiled into the binaries by server/embed.sh (see the Makefile). */
#ifndef AG_EMBEDDED_H
#define AG_EMBEDDED_H

#include <stddef.h>

struct ag_migration {
    const char *name; /* "0001_models", from migrations/0001_models.sql */
    const char *sql;
};
extern const struct ag_migration ag_migrations[];
extern const size_t ag_migrations_count;

extern const char ag_openapi_json[];

#endif
