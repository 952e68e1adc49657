/* client_args.c — the one option table of the client commands (flag, env, default).
 * Contract: daemon/cli/client_args.h. */
#include "client_args.h"

#include <stddef.h>
#include <stdlib.h>
#include <string.h>

enum { SUBMIT = 1, JOBS = 2, CANCEL = 4, FETCH = 8, ALL = 15 };

static const struct command {
    const char *name;
    unsigned bit;
    const char *positional; /* NULL: none */
    const char *what;
} commands[] = {
    {"submit", SUBMIT, "JOB.json",
     "submit a job file to a packd service; with --wait follow it and download its result"},
    {"jobs", JOBS, NULL, "list the service's jobs, newest first"},
    {"cancel", CANCEL, "ID", "dismiss a job (a running one is stopped)"},
    {"fetch", FETCH, "ID", "download a job's result and verify its SHA-256"},
};

typedef enum { STR, FLAG } kind;

static const struct option {
    const char *name;  /* long form, without "--" */
    const char *alias; /* short form or NULL */
    kind kind;
    const char *metavar;
    const char *env; /* fallback environment variable or NULL */
    const char *def; /* built-in default or NULL */
    unsigned cmds;
    size_t off;
    const char *help;
} options[] = {
    {"server", NULL, STR, "URL", "PACKD_SERVER", "http://127.0.0.1:8080", ALL,
     offsetof(pk_client_args, server), "base URL of the service"},
    {"token", NULL, STR, "T", "PACKD_TOKEN", NULL, ALL, offsetof(pk_client_args, token),
     "bearer token sent as `Authorization: Bearer T`"},
    {"wait", NULL, FLAG, NULL, NULL, NULL, SUBMIT, offsetof(pk_client_args, wait),
     "follow the job (progress on stderr) until it ends"},
    {"output", "-o", STR, "OUT.h5", NULL, NULL, SUBMIT | FETCH, offsetof(pk_client_args, output),
     "download the result here and verify its SHA-256 (submit: implies --wait)"},
    {"quiet", "-q", FLAG, NULL, NULL, NULL, SUBMIT | FETCH, offsetof(pk_client_args, quiet),
     "no progress line"},
    {"status", NULL, STR, "S", NULL, NULL, JOBS, offsetof(pk_client_args, status),
     "only jobs in status S (accepted, running, successful, failed, dismissed)"},
    {"limit", NULL, STR, "N", NULL, "20", JOBS, offsetof(pk_client_args, limit), "at most N jobs"},
    {"json", NULL, FLAG, NULL, NULL, NULL, JOBS, offsetof(pk_client_args, json),
     "print the service's job list document instead of a table"},
};
#define NOPT (sizeof options / sizeof *options)

static const struct command *find_command(const char *name)
{
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(commands[i].name, name))
            return &commands[i];
    return NULL;
}

static const struct option *find_option(const char *arg, unsigned bit)
{
    for (size_t i = 0; i < NOPT; i++) {
        const struct option *o = &options[i];
        if (!(o->cmds & bit))
            continue;
        if ((arg[0] == '-' && arg[1] == '-' && !strcmp(arg + 2, o->name)) ||
            (o->alias && !strcmp(arg, o->alias)))
            return o;
    }
    return NULL;
}

void pk_client_help(const char *cmd, FILE *f)
{
    const struct command *c = find_command(cmd);
    if (!c)
        return;
    fprintf(f, "usage: packd %s%s%s [options]\n%s\n\noptions:\n", c->name, c->positional ? " " : "",
            c->positional ? c->positional : "", c->what);
    for (size_t i = 0; i < NOPT; i++) {
        const struct option *o = &options[i];
        if (!(o->cmds & c->bit))
            continue;
        char head[64];
        snprintf(head, sizeof head, "%s%s--%s%s%s", o->alias ? o->alias : "", o->alias ? ", " : "",
                 o->name, o->metavar ? " " : "", o->metavar ? o->metavar : "");
        fprintf(f, "  %-22s %s", head, o->help);
        if (o->env)
            fprintf(f, "; default $%s", o->env);
        if (o->def)
            fprintf(f, "%s%s", o->env ? ", else " : "; default ", o->def);
        fputc('\n', f);
    }
    if (c->bit & (SUBMIT | FETCH))
        fprintf(f,
                "\nexit status: 0 done, 1 rejected (the problem's errors on stderr), 2 transport\n"
                "or integrity error (no answer, 5xx, SHA-256 mismatch), 3 the job failed or was\n"
                "dismissed (with -o OUT, a failed job's partial result is downloaded to\n"
                "OUT.partial: OUT is written only for a successful job), 64 usage.\n");
}

int pk_client_parse(int argc, char **argv, pk_client_args *a)
{
    memset(a, 0, sizeof *a);
    const struct command *c = find_command(argv[0]);
    if (!c)
        return 64;
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        const struct option *o = arg[0] == '-' && arg[1] ? find_option(arg, c->bit) : NULL;
        if (o && o->kind == FLAG) {
            *(int *)((char *)a + o->off) = 1;
        } else if (o) {
            if (i + 1 >= argc) {
                fprintf(stderr, "packd %s: %s needs a value (%s)\n", c->name, arg, o->metavar);
                return 64;
            }
            *(const char **)((char *)a + o->off) = argv[++i];
        } else if (arg[0] == '-' && arg[1]) {
            fprintf(stderr, "packd %s: unknown option '%s' (packd %s --help)\n", c->name, arg,
                    c->name);
            return 64;
        } else if (c->positional && !a->arg) {
            a->arg = arg;
        } else {
            fprintf(stderr, "packd %s: unexpected argument '%s' (packd %s --help)\n", c->name, arg,
                    c->name);
            return 64;
        }
    }
    if (c->positional && !a->arg) {
        fprintf(stderr, "packd %s: missing %s (packd %s --help)\n", c->name, c->positional,
                c->name);
        return 64;
    }
    if ((c->bit & FETCH) && !a->output) {
        fprintf(stderr, "packd fetch: missing -o OUT.h5\n");
        return 64;
    }
    for (size_t i = 0; i < NOPT; i++) { /* fallbacks: environment, then built-in */
        const struct option *o = &options[i];
        const char **slot = (const char **)((char *)a + o->off);
        if (o->kind != STR || !(o->cmds & c->bit) || *slot)
            continue;
        const char *env = o->env ? getenv(o->env) : NULL;
        *slot = env && *env ? env : o->def;
    }
    if (a->output)
        a->wait = 1;
    return 0;
}
