/* cmd_picture.c — `packd picture RESULT.h5 -o FILE.{svg,png} [--kind K]`:
 * draw a result file (api/picture/picture.h). */
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "api/picture/picture.h"

static int usage(FILE *f)
{
    fprintf(f,
            "usage: packd picture RESULT.h5 -o FILE.svg|FILE.png [--kind KIND]\n"
            "kinds (default: field for an fe2 result, else packing; a kind needs its data in "
            "the file):\n");
    const char *name, *help;
    for (int i = 0; (name = pk_picture_kind_name(i, NULL, NULL, &help)); i++)
        fprintf(f, "  %-9s %s\n", name, help);
    return f == stderr ? 64 : 0;
}

int cmd_picture(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *kind_name = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help"))
            return usage(stdout);
        if (!strcmp(argv[i], "-o") && i + 1 < argc)
            out = argv[++i];
        else if (!strcmp(argv[i], "--kind") && i + 1 < argc)
            kind_name = argv[++i];
        else if (!in && argv[i][0] != '-')
            in = argv[i];
        else
            return usage(stderr);
    }
    pk_picture_kind kind;
    if (!in || !out || (kind_name && pk_picture_kind_parse(kind_name, &kind) != 0))
        return usage(stderr);
    if (!kind_name)
        kind = pk_picture_default(in);
    char err[1024];
    int rc = pk_picture_write(in, kind, out, err, sizeof err);
    pk_picture_release();
    if (rc != 0) {
        fprintf(stderr, "packd picture: %s\n", err);
        return 2;
    }
    return 0;
}
