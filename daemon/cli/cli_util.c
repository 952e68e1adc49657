/* cli_util.c — helpers shared by the commands: JSON files, schema errors, --help.
 * Contract: daemon/cli/cli.h. */
#include <stdio.h>
#include <string.h>

#include "cli.h"

#include "api/inputs/input_open.h"
#include "api/inputs/json_depth.h"

static void print_json(json_t *out)
{
    json_dumpf(out, stdout, JSON_INDENT(2));
    putchar('\n');
    fflush(stdout);
}

static void print_errors_json(const char *path, const pk_schema_errors *errs)
{
    json_t *out = json_object();
    json_object_set_new(out, "valid", json_false());
    json_object_set_new(out, "file", json_string(path));
    json_object_set_new(out, "errors", pk_schema_errors_json(errs));
    print_json(out);
    json_decref(out);
}

json_t *cli_load_json(const char *path)
{
    json_error_t e;
    char err[256];
    FILE *f = strcmp(path, "-") == 0 ? stdin : pk_input_fopen(path, 0, err, sizeof err);
    if (!f) { /* not the JSON's fault: no line and column, no rule "json" */
        pk_schema_errors errs = {0};
        pk_schema_errors_add(&errs, "", "file", "%s", err);
        print_errors_json(path, &errs);
        pk_schema_errors_free(&errs);
        fprintf(stderr, "packd: %s\n", err);
        return NULL;
    }
    json_t *j = json_loadf(f, JSON_REJECT_DUPLICATES, &e);
    if (f != stdin)
        fclose(f);
    if (!j) {
        pk_schema_errors errs = {0};
        pk_schema_errors_add(&errs, "", "json", "line %d, column %d: %s", e.line, e.column, e.text);
        cli_print_errors(path, &errs);
        pk_schema_errors_free(&errs);
    } else if (!pk_json_depth_within(j, PK_JSON_MAX_DEPTH)) {
        pk_schema_errors errs = {0};
        pk_schema_errors_add(&errs, "", "depth", "objects and arrays nest deeper than %d levels",
                             PK_JSON_MAX_DEPTH);
        cli_print_errors(path, &errs);
        pk_schema_errors_free(&errs);
        json_decref(j);
        j = NULL;
    }
    return j;
}

void cli_print_errors(const char *path, const pk_schema_errors *errs)
{
    print_errors_json(path, errs);
    for (size_t i = 0; i < errs->n; i++)
        fprintf(stderr, "%s: %s: %s (rule %s)\n", path,
                errs->items[i].pointer[0] ? errs->items[i].pointer : "/", errs->items[i].message,
                errs->items[i].rule);
}

int cli_help_requested(int argc, char **argv)
{
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; i++)
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h"))
            return 1;
    return 0;
}
