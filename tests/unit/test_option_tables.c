/* test_option_tables.c — every option table (api/schemas/option_table.h)
 * against its embedded schema: each row's pointer names a property of the
 * schema, each "default" of the schema is a row's default and the other way
 * round (implicit rows have none), enum rows list the schema's values, integer
 * rows the schema's range; a bad value is an error naming the field and the
 * rule; a sieve curve without sizes is refused, not read at pc[-1]. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "api/fe2/fe2_job.h"
#include "api/homog/homog_job.h"
#include "api/pack/pack_job.h"
#include "api/pack/pack_placer.h"
#include "api/schemas/option_table.h"

#define MAXN 16

/* The schema nodes that describe the instance at ptr (through $ref,
 * oneOf/anyOf/allOf and if/then/else). */
static void nodes_at(json_t *doc, json_t *node, const char *ptr, json_t **out, size_t *n, int depth)
{
    if (!json_is_object(node) || depth > 32 || *n >= MAXN)
        return;
    const char *ref = json_string_value(json_object_get(node, "$ref"));
    if (ref && ref[0] == '#')
        nodes_at(doc, pk_json_at(doc, ref + 1), ptr, out, n, depth + 1);
    static const char *const comb[] = {"oneOf", "anyOf", "allOf"};
    for (int c = 0; c < 3; c++) {
        json_t *arr = json_object_get(node, comb[c]), *item;
        size_t i;
        json_array_foreach (arr, i, item)
            nodes_at(doc, item, ptr, out, n, depth + 1);
    }
    nodes_at(doc, json_object_get(node, "then"), ptr, out, n, depth + 1);
    nodes_at(doc, json_object_get(node, "else"), ptr, out, n, depth + 1);
    if (!*ptr) {
        if (*n < MAXN)
            out[(*n)++] = node;
        return;
    }
    const char *end = strchr(ptr + 1, '/');
    size_t len = end ? (size_t)(end - ptr - 1) : strlen(ptr + 1);
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)len, ptr + 1);
    nodes_at(doc, json_object_get(json_object_get(node, "properties"), key), ptr + 1 + len, out, n,
             depth + 1);
}

static int same_value(json_t *a, json_t *b)
{
    if (json_is_number(a) && json_is_number(b))
        return json_number_value(a) == json_number_value(b);
    return json_equal(a, b);
}

/* One row against the schema; returns the number of failures printed. */
static int check_row(json_t *doc, const pk_option_table *t, const pk_option *o, const void *filled)
{
    json_t *nodes[MAXN];
    size_t n = 0;
    int bad = 0;
    nodes_at(doc, doc, o->pointer, nodes, &n, 0);
    if (!n) {
        fprintf(stderr, "  %s %s: no such property\n", t->schema, o->pointer);
        return 1;
    }
    json_t *dflt = pk_option_default_json(o, filled);
    int with_default = 0;
    double lo = INFINITY, hi = -INFINITY;
    json_t *values = json_array();
    for (size_t i = 0; i < n; i++) {
        json_t *d = json_object_get(nodes[i], "default");
        if (d) {
            with_default = 1;
            if (!dflt || !same_value(d, dflt)) {
                char *a = json_dumps(d, JSON_ENCODE_ANY),
                     *b = dflt ? json_dumps(dflt, JSON_ENCODE_ANY) : NULL;
                fprintf(stderr, "  %s: schema default %s, table %s\n", o->pointer, a,
                        b ? b : "implicit");
                free(a);
                free(b);
                bad++;
            }
        }
        json_t *mn = json_object_get(nodes[i], "minimum"),
               *mx = json_object_get(nodes[i], "maximum");
        if (mn)
            lo = fmin(lo, json_number_value(mn));
        if (mx)
            hi = fmax(hi, json_number_value(mx));
        if (o->type == PK_OPT_ENUM) { /* the schema's values (enum or const) */
            json_t *vals = json_object_get(nodes[i], "enum"), *v;
            if (json_object_get(nodes[i], "const"))
                json_array_append(values, json_object_get(nodes[i], "const"));
            size_t k;
            json_array_foreach (vals, k, v)
                json_array_append(values, v);
        }
    }
    if (o->type == PK_OPT_ENUM) { /* the same names in the table and the schema */
        size_t k;
        json_t *v;
        json_array_foreach (values, k, v) {
            int found = 0;
            for (size_t j = 0; o->names[j]; j++)
                found |= json_is_string(v) && !strcmp(o->names[j], json_string_value(v));
            if (!found) {
                fprintf(stderr, "  %s: schema value %s not in the table\n", o->pointer,
                        json_string_value(v));
                bad++;
            }
        }
        for (size_t j = 0; o->names[j]; j++) {
            int found = 0;
            json_array_foreach (values, k, v)
                found |= json_is_string(v) && !strcmp(o->names[j], json_string_value(v));
            if (!found) {
                fprintf(stderr, "  %s: table name %s not in the schema\n", o->pointer, o->names[j]);
                bad++;
            }
        }
    }
    json_decref(values);
    if (dflt && !with_default) {
        fprintf(stderr, "  %s: the table has a default, the schema none\n", o->pointer);
        bad++;
    }
    if (o->type == PK_OPT_INTEGER &&
        ((isfinite(lo) && lo != o->lo) || (isfinite(hi) && hi != o->hi))) {
        fprintf(stderr, "  %s: range [%g, %g], schema [%g, %g]\n", o->pointer, o->lo, o->hi, lo,
                hi);
        bad++;
    }
    json_decref(dflt);
    return bad;
}

static const pk_option_table *tables[8];
static size_t ntables;

static void collect_tables(void)
{
    tables[ntables++] = &pk_pack_options;
    tables[ntables++] = &pk_homog_options;
    tables[ntables++] = &pk_fe2_options;
    for (size_t i = 0; pk_placer_at(i); i++)
        if (pk_placer_at(i)->options)
            tables[ntables++] = pk_placer_at(i)->options;
}

static int table_has(const char *schema, const char *pointer)
{
    for (size_t i = 0; i < ntables; i++)
        for (size_t j = 0; !strcmp(tables[i]->schema, schema) && j < tables[i]->n; j++)
            if (!strcmp(tables[i]->rows[j].pointer, pointer))
                return 1;
    return 0;
}

/* Every "default" of the schema belongs to a row. */
static int defaults_covered(const char *schema, json_t *doc, json_t *node, const char *path,
                            int depth)
{
    if (!json_is_object(node) || depth > 32)
        return 0;
    int bad = 0;
    if (json_object_get(node, "default") && !table_has(schema, path)) {
        fprintf(stderr, "  %s %s: a default no table row has\n", schema, path);
        bad++;
    }
    const char *ref = json_string_value(json_object_get(node, "$ref"));
    if (ref && ref[0] == '#')
        bad += defaults_covered(schema, doc, pk_json_at(doc, ref + 1), path, depth + 1);
    static const char *const comb[] = {"oneOf", "anyOf", "allOf"};
    for (int c = 0; c < 3; c++) {
        json_t *arr = json_object_get(node, comb[c]), *item;
        size_t i;
        json_array_foreach (arr, i, item)
            bad += defaults_covered(schema, doc, item, path, depth + 1);
    }
    bad += defaults_covered(schema, doc, json_object_get(node, "then"), path, depth + 1);
    bad += defaults_covered(schema, doc, json_object_get(node, "else"), path, depth + 1);
    const char *key;
    json_t *sub;
    json_object_foreach (json_object_get(node, "properties"), key, sub) {
        char p[256];
        snprintf(p, sizeof p, "%s/%s", path, key);
        bad += defaults_covered(schema, doc, sub, p, depth + 1);
    }
    return bad;
}

static void test_tables_match_schemas(void)
{
    json_t *empty = json_object();
    int bad = 0;
    for (size_t i = 0; i < ntables; i++) {
        const pk_option_table *t = tables[i];
        json_t *doc = pk_schema_get(t->schema);
        CHECK_MSG(doc != NULL, "%s", t->schema);
        if (!doc)
            continue;
        void *filled = calloc(1, t->size);
        pk_schema_errors errs = {0};
        CHECK(pk_options_fill(t, empty, filled, &errs) == 0);
        pk_schema_errors_free(&errs);
        for (size_t j = 0; j < t->n; j++)
            bad += check_row(doc, t, &t->rows[j], filled);
        free(filled);
    }
    static const char *const schemas[] = {
        "pack.inputs.schema.json", "homogenize.inputs.schema.json", "fe2.inputs.schema.json"};
    for (int s = 0; s < 3; s++)
        bad += defaults_covered(schemas[s], pk_schema_get(schemas[s]), pk_schema_get(schemas[s]),
                                "", 0);
    CHECK_MSG(bad == 0, "%d mismatches between the option tables and the schemas", bad);
    json_decref(empty);
}

static int has_error(const pk_schema_errors *e, const char *ptr, const char *rule)
{
    for (size_t i = 0; i < e->n; i++)
        if (!strcmp(e->items[i].pointer, ptr) && !strcmp(e->items[i].rule, rule))
            return 1;
    return 0;
}

/* Inputs that bypass the schema: the filler names the field and the rule. */
static void test_bad_values_named(void)
{
    json_t *in = json_loads("{\"dim\": 3, \"seed\": 1.5, \"unit\": 7, \"algorithm\": \"edmd\","
                            "\"edmd\": {\"growth\": \"sideways\", \"stall\": {\"events\": 3}}}",
                            0, NULL);
    pk_pack_job job;
    pk_schema_errors errs = {0};
    pk_pack_job_from_json(in, &job, &errs);
    CHECK(has_error(&errs, "/seed", "integer"));
    CHECK(has_error(&errs, "/unit", "type"));
    CHECK(has_error(&errs, "/edmd/growth", "enum"));
    CHECK(has_error(&errs, "/edmd/stall/events", "integer"));
    CHECK(job.seed == 1 && !strcmp(job.unit, "mm")); /* the defaults stand in */
    pk_schema_errors_free(&errs);
    json_decref(in);
}

/* A sieve curve of no sizes (the schema's minItems bypassed). */
static void test_empty_sieve_refused(void)
{
    json_t *in =
        json_loads("{\"dim\": 2, \"domain\": {\"box\": {\"size\": [10, 10]}}, \"count\": 5,"
                   "\"grading\": {\"type\": \"sieve\", \"sizes\": [], \"passing\": []}}",
                   0, NULL);
    pk_pack_job job;
    pk_schema_errors errs = {0};
    pk_pack_job_from_json(in, &job, &errs);
    CHECK(has_error(&errs, "/grading/sizes", "minItems"));
    pk_schema_errors_free(&errs);
    json_decref(in);
}

/* root[pointer] = v (objects made on the way). */
static void set_at(json_t *root, const char *pointer, json_t *v)
{
    char key[128];
    const char *p = pointer + 1, *end;
    json_t *o = root;
    while ((end = strchr(p, '/'))) {
        snprintf(key, sizeof key, "%.*s", (int)(end - p), p);
        if (!json_object_get(o, key))
            json_object_set_new(o, key, json_object());
        o = json_object_get(o, key);
        p = end + 1;
    }
    json_object_set_new(o, p, v);
}

static double field_number(const pk_option *o, const void *filled)
{
    json_t *v = pk_option_default_json(o, filled);
    double x = json_number_value(v);
    json_decref(v);
    return x;
}

/* Each quality column: a draft / fine job takes its value, a standard job the
 * row's default, and an explicit value wins over every preset. */
static void test_quality_columns(void)
{
    int columns = 0;
    for (size_t i = 0; i < ntables; i++) {
        const pk_option_table *t = tables[i];
        void *plain = calloc(1, t->size), *filled = calloc(1, t->size);
        pk_schema_errors errs = {0};
        json_t *empty = json_object(), *std = json_pack("{s:s}", "quality", "standard");
        pk_options_fill(t, empty, plain, &errs);
        pk_options_fill(t, std, filled, &errs);
        CHECK_MSG(!memcmp(plain, filled, t->size), "%s: standard is the default", t->schema);
        for (size_t j = 0; j < t->n; j++) {
            const pk_option *o = &t->rows[j];
            if (!o->by_quality)
                continue;
            columns++;
            CHECK_MSG(o->type == PK_OPT_NUMBER || o->type == PK_OPT_INTEGER, "%s", o->pointer);
            const char *q[] = {"draft", "fine"};
            const double want[] = {o->draft, o->fine};
            for (int k = 0; k < 2; k++) {
                json_t *in = json_pack("{s:s}", "quality", q[k]);
                pk_options_fill(t, in, filled, &errs);
                CHECK_MSG(field_number(o, filled) == want[k], "%s %s: %g, column %g", o->pointer,
                          q[k], field_number(o, filled), want[k]);
                /* an explicit value (the other column's) wins */
                set_at(in, o->pointer, json_real(want[1 - k]));
                pk_options_fill(t, in, filled, &errs);
                CHECK_MSG(field_number(o, filled) == want[1 - k], "%s explicit under %s",
                          o->pointer, q[k]);
                json_decref(in);
            }
        }
        CHECK(errs.n == 0);
        pk_schema_errors_free(&errs);
        json_decref(empty);
        json_decref(std);
        free(plain);
        free(filled);
    }
    CHECK(columns >= 4); /* EDMD growth rate and pressure, RSA N^F, DR tolerance */
}

/* The knob values docs/presets.md documents for each preset. */
static void test_documented_presets(void)
{
    static const struct {
        const char *quality;
        double gamma, p_max, nf, tol;
    } doc[] = {
        {"draft", 0.03, 1e4, 1e5, 1e-5},
        {"standard", 0.01, 1e12, 1e6, 1e-8},
        {"fine", 0.003, 1e12, 1e7, 1e-10},
    };
    for (int q = 0; q < 3; q++) {
        pk_schema_errors errs = {0};
        pk_pack_job job;
        pk_homog_job hj;
        char text[256];
        snprintf(text, sizeof text, "{\"algorithm\": \"edmd\", \"quality\": \"%s\"}",
                 doc[q].quality);
        json_t *in = json_loads(text, 0, NULL);
        pk_pack_job_from_json(in, &job, &errs);
        CHECK_MSG(job.opt.edmd.prm.growth_rate == doc[q].gamma, "%s γ %g", doc[q].quality,
                  job.opt.edmd.prm.growth_rate);
        CHECK_MSG(job.opt.edmd.prm.p_max == doc[q].p_max, "%s p %g", doc[q].quality,
                  job.opt.edmd.prm.p_max);
        json_object_set_new(in, "algorithm", json_string("rsa"));
        pk_pack_job_from_json(in, &job, &errs);
        CHECK_MSG((double)job.opt.rsa.max_failed_draws == doc[q].nf, "%s N^F", doc[q].quality);
        pk_options_fill(&pk_homog_options, in, &hj, &errs);
        CHECK_MSG(hj.tol == doc[q].tol, "%s tol %g", doc[q].quality, hj.tol);
        pk_schema_errors_free(&errs);
        json_decref(in);
    }
}

int main(void)
{
    collect_tables();
    RUN(test_tables_match_schemas);
    RUN(test_quality_columns);
    RUN(test_documented_presets);
    RUN(test_bad_values_named);
    RUN(test_empty_sieve_refused);
    return check_summary();
}
