/* cli.h — the packd subcommands.  main.c only dispatches; each command lives
 * in its own file (cmd_<name>.c) and returns the process exit status:
 *   0 success, 1 invalid input (errors printed), 2 runtime failure, 64 usage. */
#ifndef PK_CLI_H
#define PK_CLI_H

int cmd_run(int argc, char **argv);
int cmd_validate(int argc, char **argv);
int cmd_inspect(int argc, char **argv);
int cmd_serve(int argc, char **argv);
int cmd_picture(int argc, char **argv);
int cmd_token(int argc, char **argv);

/* Load a JSON file ("-" = stdin); NULL with a message on stderr. */
#include <jansson.h>
json_t *cli_load_json(const char *path);

/* Print {"valid":false,"errors":[...]} style output to stdout. */
#include "json_schema.h"
void cli_print_errors(const char *path, const pk_schema_errors *errs);

#endif
