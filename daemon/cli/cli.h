/* cli.h — the packd subcommands.  main.c only dispatches; each command lives
 * in its own file (cmd_<name>.c) and returns the process exit status:
 *   0 success, 1 invalid input (errors printed; also a job or input file that
 *   cannot be opened), 2 runtime failure, 64 usage. */
#ifndef PK_CLI_H
#define PK_CLI_H

int cmd_run(int argc, char **argv);
int cmd_validate(int argc, char **argv);
int cmd_inspect(int argc, char **argv);
int cmd_serve(int argc, char **argv);
int cmd_picture(int argc, char **argv);
int cmd_token(int argc, char **argv);
/* the client of a packd service (client_args.c: options; exit statuses
 * 0 done, 1 rejected, 2 transport or integrity error, 3 job failed) */
int cmd_submit(int argc, char **argv);
int cmd_jobs(int argc, char **argv);
int cmd_cancel(int argc, char **argv);
int cmd_fetch(int argc, char **argv);
int cmd_backup(int argc, char **argv);

#include <stdio.h>
void cmd_serve_help(const char *name, FILE *f);
void cmd_backup_help(const char *name, FILE *f);

/* 1 when argv[1..] asks for help (-h or --help before a "--"). */
int cli_help_requested(int argc, char **argv);

/* Load a JSON file ("-" = stdin); NULL with the errors printed (stdout:
 * JSON, stderr: "packd: cannot open FILE: No such file or directory" or the
 * JSON's line, column and reason). */
#include <jansson.h>
json_t *cli_load_json(const char *path);

/* Print {"valid":false,"errors":[...]} style output to stdout. */
#include "api/schemas/json_schema.h"
void cli_print_errors(const char *path, const pk_schema_errors *errs);

#endif
