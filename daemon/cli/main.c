/* packd — granular microstructures and their homogenization.
 * One binary: the daemon (serve), its workers and batch users (run) share
 * every code path below api/. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "client_args.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

static void own_help(const char *name, FILE *f);

static const struct {
    const char *name;
    int (*fn)(int, char **);
    const char *args;                        /* the synopsis after "packd NAME" */
    const char *what;                        /* one line: what it does */
    void (*help)(const char *name, FILE *f); /* --help; NULL: the usage line */
} commands[] = {
    {"run", cmd_run, "JOB.json -o OUT.h5 [--xdmf OUT.xdmf] [--json] [--progress] [--progress-fd N]",
     "run a job, write its result", own_help},
    {"validate", cmd_validate, "JOB.json", "check a job, print its plan or errors", NULL},
    {"inspect", cmd_inspect, "OUT.h5 [--full]", "print a result file's summary as JSON", NULL},
    {"serve", cmd_serve, "[--config F] [--bind A] [--port N] [--data DIR]", "run the job service",
     cmd_serve_help},
    {"picture", cmd_picture, "OUT.h5 -o FILE.svg|png [--kind KIND]", "draw a result", own_help},
    {"token", cmd_token, "add NAME [--admin] | list | revoke NAME [--config F] [--data DIR]",
     "the service's bearer tokens", own_help},
    {"submit", cmd_submit, "JOB.json [--server URL] [--token T] [--wait] [-o OUT.h5]",
     "submit a job to a service (-o: wait, download, verify)", pk_client_help},
    {"jobs", cmd_jobs, "[--server URL] [--status S]", "list a service's jobs", pk_client_help},
    {"cancel", cmd_cancel, "ID [--server URL]", "dismiss a job", pk_client_help},
    {"fetch", cmd_fetch, "ID -o OUT.h5 [--server URL]", "download a result, verify its SHA-256",
     pk_client_help},
    {"backup", cmd_backup, "FILE [--data DIR | --config F]",
     "online copy of the service's database", cmd_backup_help},
    {"version", NULL, "", "print the version", NULL},
};
#define NCOMMANDS (sizeof commands / sizeof *commands)

/* The description column: after the widest synopsis of at most SYNOPSIS_WRAP
 * characters; a longer synopsis has its description on the next line there. */
#define SYNOPSIS_WRAP 50

static int synopsis(char *out, size_t n, size_t i)
{
    return snprintf(out, n, "packd %s%s%s", commands[i].name, *commands[i].args ? " " : "",
                    commands[i].args);
}

static int description_column(void)
{
    int col = 0;
    char s[256];
    for (size_t i = 0; i < NCOMMANDS; i++) {
        int w = synopsis(s, sizeof s, i);
        if (w <= SYNOPSIS_WRAP && w > col)
            col = w;
    }
    return 2 + col + 2;
}

/* A command that prints its own --help. */
static void own_help(const char *name, FILE *f)
{
    (void)f;
    char help[] = "--help", *argv[] = {(char *)name, help, NULL};
    for (size_t i = 0; i < NCOMMANDS; i++)
        if (!strcmp(commands[i].name, name) && commands[i].fn)
            commands[i].fn(2, argv);
}

static int usage(FILE *f)
{
    fprintf(f, "packd %s — dense granular packings and RVE homogenization\n\nusage:\n",
            PACKD_VERSION);
    const int col = description_column();
    for (size_t i = 0; i < NCOMMANDS; i++) {
        char s[256];
        int w = synopsis(s, sizeof s, i);
        if (2 + w + 2 > col)
            fprintf(f, "  %s\n%*s%s\n", s, col, "", commands[i].what);
        else
            fprintf(f, "  %-*s%s\n", col - 2, s, commands[i].what);
    }
    return f == stderr ? 64 : 0;
}

int main(int argc, char **argv)
{
    if (argc < 2)
        return usage(stderr);
    if (!strcmp(argv[1], "-h") || !strcmp(argv[1], "--help") || !strcmp(argv[1], "help"))
        return usage(stdout);
    if (!strcmp(argv[1], "version") || !strcmp(argv[1], "--version")) {
        printf("packd %s\n", PACKD_VERSION);
        return 0;
    }
    for (size_t i = 0; i < NCOMMANDS; i++) {
        if (strcmp(argv[1], commands[i].name) != 0 || !commands[i].fn)
            continue;
        if (cli_help_requested(argc - 1, argv + 1)) {
            if (commands[i].help)
                commands[i].help(commands[i].name, stdout);
            else
                printf("usage: packd %s %s\n", commands[i].name, commands[i].args);
            return 0;
        }
        return commands[i].fn(argc - 1, argv + 1);
    }
    fprintf(stderr, "packd: unknown command '%s'\n", argv[1]);
    return usage(stderr);
}
