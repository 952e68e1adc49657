#include <stdio.h>

#include "cli.h"

/* The job service is issue #4; until it lands `serve` says so plainly. */
int cmd_serve(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "packd serve: the job service is not built yet (see the open issue "
                    "\"packd serve\"); use `packd run JOB.json -o OUT.h5`\n");
    return 2;
}
