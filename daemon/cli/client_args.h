/* client_args.h — the options of the client commands (submit, jobs, cancel,
 * fetch): one table (client_args.c) drives their parsing, defaults
 * (flag, then environment variable, then built-in) and --help. */
#ifndef PK_CLIENT_ARGS_H
#define PK_CLIENT_ARGS_H

#include <stdio.h>

typedef struct pk_client_args {
    const char *server; /* --server, $PACKD_SERVER, http://127.0.0.1:8080 */
    const char *token;  /* --token, $PACKD_TOKEN */
    const char *output; /* -o FILE */
    const char *status; /* jobs --status */
    const char *limit;  /* jobs --limit */
    int wait;           /* submit --wait (implied by -o) */
    int json;           /* jobs --json */
    int quiet;          /* submit/fetch --quiet: no progress line */
    const char *arg;    /* the positional argument (JOB.json or ID), NULL for jobs */
} pk_client_args;

/* Parse argv (argv[0] is the command name).  Returns 0, or 64 after printing
 * a usage error to stderr. */
int pk_client_parse(int argc, char **argv, pk_client_args *a);

/* The usage and option list of a client command. */
void pk_client_help(const char *cmd, FILE *f);

#endif
