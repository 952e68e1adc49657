/* cmd_inspect.c — `packd inspect OUT.h5 [--full]`: a result file as JSON.
 * Contract: daemon/cli/cli.h; the view is api/results/h5_inspect.h's. */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "api/results/h5_inspect.h"

int cmd_inspect(int argc, char **argv)
{
    const char *path = NULL;
    size_t max_array = 64;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--full"))
            max_array = (size_t)-1;
        else if (!path)
            path = argv[i];
        else
            path = NULL, i = argc;
    }
    if (!path) {
        fprintf(stderr, "usage: packd inspect OUT.h5 [--full]\n");
        return 64;
    }
    char err[512];
    json_t *j = pk_h5_inspect(path, max_array, err, sizeof err);
    if (!j) {
        fprintf(stderr, "packd inspect: %s\n", err);
        return 2;
    }
    json_dumpf(j, stdout, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
    putchar('\n');
    json_decref(j);
    return 0;
}
