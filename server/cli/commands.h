/* Subcommands of the `archgram` command-line tool, one file each in server/cli/.
 * Each takes the arguments after the subcommand name (argv[0] is the subcommand) and
 * returns the process exit code: 0 success, 1 failure of the work, 2 bad usage. */
#ifndef AG_CLI_COMMANDS_H
#define AG_CLI_COMMANDS_H

int ag_cli_info(int argc, char **argv);
int ag_cli_convert(int argc, char **argv);

#endif
