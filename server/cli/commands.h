/* Subcommands of the `archgram` command-line tool, one file each in server/cli/.
 * Each takes the arguments after the subcommand name (argv[0] is the subcommand) and
 * returns the process exit code: 0 success, 1 failure of the work, 2 bad usage. */
#ifndef AG_CLI_COMMANDS_H
#define AG_CLI_COMMANDS_H

int ag_cli_info(int argc, char **argv);
int ag_cli_convert(int argc, char **argv);
int ag_cli_proceduralize(int argc, char **argv);
int ag_cli_derive(int argc, char **argv);
int ag_cli_fmt(int argc, char **argv);
int ag_cli_extrude(int argc, char **argv);
int ag_cli_edit(int argc, char **argv);
int ag_cli_part(int argc, char **argv);

/* Shared by the subcommands (defined in server/cli.c). */
#include "../core/mesh.h"
#include "../core/status.h"
#include "../io/obj.h"

/* Prints `archgram: FILE:LINE: message` (or `archgram: FILE: message`) to stderr. */
void ag_cli_report(const char *file, const ag_error *err);
/* "--up y|z" value → axis; returns 0, or -1 on a bad value. */
int ag_cli_parse_up(const char *value, ag_up_axis *up);
/* A monotonic clock in seconds, for timing stages. */
double ag_cli_seconds(void);
/* Reads a mesh file of any importable format; on failure reports it and returns 1.
 * *bytes receives the file size. */
int ag_cli_load_mesh(const char *path, ag_up_axis up, ag_mesh **out, size_t *bytes);

#endif
