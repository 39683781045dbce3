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
int ag_cli_segment(int argc, char **argv);
int ag_cli_cut(int argc, char **argv);

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

/* Point clouds (server/cli/cloud.c). */
#include "../core/points/cloud.h"
/* Whether a file is a point cloud (LAS, LAZ, XYZ, or a PLY without faces). */
int ag_cli_is_cloud_file(const char *path);
/* Whether an output name is a cloud format (.ply, .las, .laz, .xyz, .txt). */
int ag_cli_is_cloud_output(const char *path);
/* Reads a cloud of any format; on failure reports it and returns 1. */
int ag_cli_load_cloud(const char *path, ag_cloud **out);
/* Writes by extension (.ply binary, .las, .xyz); reports and returns 1 (2: bad name). */
int ag_cli_write_cloud(const ag_cloud *c, const char *path, int double_xyz);
/* The cloud branches of `info` and `convert`. */
int ag_cli_cloud_info(const char *file, int as_json);
int ag_cli_cloud_convert(const char *in, const char *out, int double_xyz);

/* Point models (server/cli/points.c): whether a command line is for a point cloud (a cloud to
 * proceduralize, a point grammar to derive), and the point branches of those commands
 * (`archgram edit` of a point model's folder: server/cli/edit.c). */
typedef enum {
    AG_CLI_POINTS_PROCEDURALIZE,
    AG_CLI_POINTS_DERIVE,
} ag_cli_points_command;
int ag_cli_points_wanted(int argc, char **argv, ag_cli_points_command cmd);
int ag_cli_points_proceduralize(int argc, char **argv);
int ag_cli_points_derive(int argc, char **argv);
/* "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX" (min <= max); 0, or -1 for a bad box. */
int ag_cli_parse_cloud_box(const char *s, double box[6]);

#endif
