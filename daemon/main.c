/* packd — granular microstructures and their homogenization.
 * One binary: the daemon (serve), its workers and batch users (run) share
 * every code path below api/. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

#ifndef PACKD_VERSION
#define PACKD_VERSION "0.0.0"
#endif

static const struct {
    const char *name;
    int (*fn)(int, char **);
    const char *usage;
} commands[] = {
    {"run", cmd_run, "run JOB.json -o OUT.h5 [--xdmf OUT.xdmf] [--progress] [--progress-fd N]\n"
                     "                                                    run a job, write its result"},
    {"validate", cmd_validate, "validate JOB.json                                 check a job, print its plan or errors"},
    {"inspect", cmd_inspect, "inspect OUT.h5 [--full]                          print a result file's summary as JSON"},
    {"serve", cmd_serve, "serve [--config F] [--bind A] [--port N] [--data DIR] run the job service"},
    {"picture", cmd_picture, "picture OUT.h5 -o FILE.svg|png [--kind packing|grading] draw a result"},
    {"token", cmd_token, "token add NAME [--admin] | list | revoke NAME [--config F] [--data DIR]\n"
                         "                                                    the service's bearer tokens"},
};

static int usage(FILE *f)
{
    fprintf(f, "packd %s — dense granular packings and RVE homogenization\n\nusage:\n", PACKD_VERSION);
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        fprintf(f, "  packd %s\n", commands[i].usage);
    fprintf(f, "  packd version\n");
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
    for (size_t i = 0; i < sizeof commands / sizeof *commands; i++)
        if (!strcmp(argv[1], commands[i].name))
            return commands[i].fn(argc - 1, argv + 1);
    fprintf(stderr, "packd: unknown command '%s'\n", argv[1]);
    return usage(stderr);
}
