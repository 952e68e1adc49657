/* test_pack_extremes.c — the pack process at the extremes of its inputs
 * (issue 21): every numeric field of the pack schema with 1e308, -1e308 and
 * -0 (valid → a correct result, invalid → an error naming the field), NaN /
 * Infinity / 1e999 refused by the parser with a position; N = 1, 2, 8 in
 * walled and periodic boxes; size ratio 1:1000; Δd above the smallest grain;
 * one class and empty classes; the same job scaled by 1e-6 and 1e6.  Never a
 * crash, a hang (alarm) or a result that breaks its own audit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/pack/pack_job.h"
#include "api/process.h"

/* checks as on the user's own machine (packd run / validate) */
static const pk_check_ctx local = {0};

/* Base jobs that hold every numeric field of the schema between them. */
static const char *const bases[] = {
    "{\"dim\":2,\"domain\":{\"box\":{\"size\":[20,20],\"periodic\":[true,false]}},"
    "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":60},"
    "{\"d\":1,\"volume_percent\":40}]},\"d_min\":0.5,\"phi\":{\"value\":0.3,\"refers_to\":"
    "\"resolved\"},"
    "\"delta_d\":0.1,\"seed\":3,\"rsa\":{\"max_failed_draws\":100000},"
    "\"limits\":{\"max_particles\":100000,\"wall_time_s\":5}}",

    "{\"dim\":2,\"domain\":{\"box\":{\"size\":[20,20]}},\"grading\":{\"type\":\"classes\","
    "\"classes\":"
    "[{\"d\":2,\"mass_percent\":50,\"density\":2.6},{\"d\":1,\"mass_percent\":50,\"density\":2}]},"
    "\"count\":30}",

    "{\"dim\":3,\"domain\":{\"box\":{\"size\":[12,12,12],\"periodic\":true}},"
    "\"grading\":{\"type\":\"sieve\",\"sizes\":[1,2],\"passing\":[0,100]},"
    "\"phi\":{\"value\":0.2,\"refers_to\":\"mix\"}}",

    "{\"dim\":2,\"domain\":{\"box\":{\"size\":[30,30]}},"
    "\"grading\":{\"type\":\"fuller\",\"q\":0.5,\"d_max\":4},\"d_min\":1,"
    "\"phi\":{\"value\":0.3,\"refers_to\":\"mix\"}}",

    "{\"dim\":2,\"domain\":{\"box\":{\"size\":[20,20]}},"
    "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]},\"count\":"
    "30,"
    "\"delta_d\":0.1,\"algorithm\":\"edmd\",\"limits\":{\"wall_time_s\":5},"
    "\"edmd\":{\"delta\":0.5,\"growth_rate\":0.05,\"jamming\":{\"reduced_pressure\":1e6,\"rate_"
    "factor\":0.1,"
    "\"full_rate_above\":1e5,\"delta_phi\":1e-9,\"events\":100},\"stall\":{\"events\":1000,"
    "\"growth\":1e-12},"
    "\"rescale_tolerance\":0.1,\"skin\":0.6,\"max_events\":1000000}}",

    "{\"dim\":3,\"domain\":{\"box\":{\"size\":[8,8,8]}},\"algorithm\":\"tetfill\",\"count\":40,"
    "\"tetfill\":{\"r_min\":0.6,\"ratio\":2,\"epsilon\":1e-4,\"vertex_weight\":0.5,\"z_min\":3,"
    "\"neighbours\":8,\"max_combos\":30,\"max_passes\":2,\"max_tets\":100000}}",

    "{\"dim\":3,\"domain\":{\"box\":{\"size\":[8,8,8]}},\"algorithm\":\"tetfill\","
    "\"phi\":{\"value\":0.3,\"refers_to\":\"resolved\"},\"tetfill\":{\"r_min\":0.6,\"r_max\":1.2,"
    "\"max_passes\":2}}",

    "{\"dim\":3,\"algorithm\":\"tetfill\",\"count\":20,\"tetfill\":{\"ratio\":2,\"max_passes\":2},"
    "\"domain\":{\"mesh\":{\"nodes\":[[0,0,0],[8,0,0],[0,8,0],[8,8,0],[0,0,8],[8,0,8],[0,8,8],[8,8,"
    "8]],"
    "\"tets\":[[0,1,3,7],[0,1,5,7],[0,2,3,7],[0,2,6,7],[0,4,5,7],[0,4,6,7]],"
    "\"regions\":[1,1,1,1,1,1]}}}",
};
#define NBASES (sizeof bases / sizeof *bases)

/* ---- numeric leaves of the schema (pointer templates, array items as "*") */

static json_t *resolve(json_t *root, json_t *s)
{
    const char *ref = json_string_value(json_object_get(s, "$ref"));
    if (ref && !strncmp(ref, "#/$defs/", 8))
        return json_object_get(json_object_get(root, "$defs"), ref + 8);
    return s;
}

static int numeric_schema(json_t *s)
{
    const char *t = json_string_value(json_object_get(s, "type"));
    if (t && (!strcmp(t, "number") || !strcmp(t, "integer")))
        return 1;
    json_t *e = json_object_get(s, "enum");
    return json_array_size(e) && json_is_number(json_array_get(e, 0));
}

static void schema_leaves(json_t *root, json_t *s, const char *at, json_t *out, int depth)
{
    s = resolve(root, s);
    if (!json_is_object(s) || depth > 12)
        return;
    if (numeric_schema(s))
        json_array_append_new(out, json_string(at));
    const char *k;
    json_t *v;
    json_object_foreach (json_object_get(s, "properties"), k, v) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s/%s", at, k);
        schema_leaves(root, v, sub, out, depth + 1);
    }
    json_t *items = json_object_get(s, "items");
    if (items) {
        char sub[256];
        snprintf(sub, sizeof sub, "%s/*", at);
        schema_leaves(root, items, sub, out, depth + 1);
    }
    const char *comb[] = {"oneOf", "anyOf", "allOf"};
    for (int c = 0; c < 3; c++) {
        size_t i;
        json_array_foreach (json_object_get(s, comb[c]), i, v)
            schema_leaves(root, v, at, out, depth + 1);
    }
}

/* ---- numeric leaves of an instance: (pointer, template) */

typedef struct leaf {
    char ptr[256], tmpl[256];
    json_t *parent; /* borrowed: object or array holding the value */
    char key[64];
    size_t index;
} leaf;

static void instance_leaves(json_t *v, const char *ptr, const char *tmpl, leaf *out, size_t *n,
                            size_t cap, json_t *parent, const char *key, size_t index)
{
    if (json_is_number(v) && *n < cap) {
        leaf *l = &out[(*n)++];
        snprintf(l->ptr, sizeof l->ptr, "%s", ptr);
        snprintf(l->tmpl, sizeof l->tmpl, "%s", tmpl);
        l->parent = parent;
        snprintf(l->key, sizeof l->key, "%s", key ? key : "");
        l->index = index;
        return;
    }
    char p2[256], t2[256];
    if (json_is_object(v)) {
        const char *k;
        json_t *c;
        json_object_foreach (v, k, c) {
            snprintf(p2, sizeof p2, "%s/%s", ptr, k);
            snprintf(t2, sizeof t2, "%s/%s", tmpl, k);
            instance_leaves(c, p2, t2, out, n, cap, v, k, 0);
        }
    } else if (json_is_array(v)) {
        size_t i;
        json_t *c;
        json_array_foreach (v, i, c) {
            snprintf(p2, sizeof p2, "%s/%zu", ptr, i);
            snprintf(t2, sizeof t2, "%s/*", tmpl);
            instance_leaves(c, p2, t2, out, n, cap, v, NULL, i);
        }
    }
}

static void set_leaf(const leaf *l, json_t *value)
{
    if (json_is_object(l->parent))
        json_object_set_new(l->parent, l->key, value);
    else
        json_array_set_new(l->parent, l->index, value);
}

/* Run inputs (schema-valid): rc of pk_job_run, summary in *sum. */
static int run_job(json_t *inputs, json_t **sum)
{
    char out[] = "/tmp/packd-test-extremes-XXXXXX";
    int fd = mkstemp(out);
    close(fd);
    json_t *job = json_pack("{s:s,s:O}", "process", "pack", "inputs", inputs);
    pk_schema_errors errs = {0};
    char err[512] = "";
    *sum = NULL;
    int rc = pk_job_run(job, NULL, out, sum, &errs, err, sizeof err);
    if (rc != 0 && rc != 2)
        fprintf(stderr, "  run: rc %d: %s\n", rc, err);
    unlink(out);
    json_decref(job);
    pk_schema_errors_free(&errs);
    return rc;
}

/* A finished run's summary is sane: φ finite in [0, 1), the audit clean
 * unless the verdict says failed. */
static int sane(const json_t *sum, int rc)
{
    if (!sum)
        return 0;
    double phi = json_real_value(json_object_get(sum, "phi_resolved"));
    int failed = json_object_get(sum, "failure") != NULL;
    if (!(isfinite(phi) && phi >= 0 && phi < 1) || (rc == 2) != failed)
        return 0;
    return failed || json_integer_value(json_object_get(sum, "pairs_below_delta_d")) == 0;
}

/* Every numeric field of the schema is in some base job; every one of them,
 * set to 1e308, -1e308 or -0, ends valid and sane or refused naming it. */
static void test_numeric_fields_walk(void)
{
    json_t *schema = pk_schema_get("pack.inputs.schema.json");
    json_t *want = json_array();
    schema_leaves(schema, schema, "", want, 0);
    CHECK(json_array_size(want) > 30);
    enum { CAP = 256 };
    static leaf leaves[CAP];
    json_t *covered = json_object();
    const double values[] = {1e308, 1e100, -1e308, -0.0, 1e-300};
    size_t runs = 0, refusals = 0, named_direct = 0;
    for (size_t b = 0; b < NBASES; b++) {
        json_t *base = json_loads(bases[b], 0, NULL);
        CHECK_MSG(base != NULL, "base %zu does not parse", b);
        if (!base)
            continue;
        pk_schema_errors errs = {0};
        CHECK_MSG(pk_process_validate_inputs(pk_process_find("pack"), base, &local, &errs) == 0,
                  "base %zu invalid: %s %s", b, errs.n ? errs.items[0].pointer : "",
                  errs.n ? errs.items[0].message : "");
        pk_schema_errors_free(&errs);
        size_t n = 0;
        instance_leaves(base, "", "", leaves, &n, CAP, NULL, NULL, 0);
        for (size_t i = 0; i < n; i++) {
            json_object_set_new(covered, leaves[i].tmpl, json_true());
            for (size_t v = 0; v < sizeof values / sizeof *values; v++) {
                json_t *job = json_deep_copy(base);
                size_t m = 0;
                static leaf mine[CAP];
                instance_leaves(job, "", "", mine, &m, CAP, NULL, NULL, 0);
                set_leaf(&mine[i], json_real(values[v]));
                pk_schema_errors e = {0};
                pk_process_validate_inputs(pk_process_find("pack"), job, &local, &e);
                if (e.n) {
                    refusals++;
                    /* the field, one inside it or the object holding it
                     * (e.g. sumTo100 at /grading/classes) */
                    int named = 0;
                    for (size_t k = 0; k < e.n; k++) {
                        const char *ep = e.items[k].pointer, *lp = leaves[i].ptr;
                        size_t el = strlen(ep), ll = strlen(lp);
                        if (!strncmp(ep, lp, ll) ||
                            (el > 0 && el < ll && !strncmp(ep, lp, el) && lp[el] == '/'))
                            named = 1;
                    }
                    /* rules between fields: their message gives both sides */
                    const char *relational[] = {"wallSize",      "periodicSize", "periodicJamming",
                                                "ascending",     "lessThanDmax", "sumTo100",
                                                "positiveTotal", "maxParticles", "resolvedBelow1",
                                                "radii",         "mesh",         "meshScale",
                                                "grading"};
                    for (size_t k = 0; k < e.n && !named; k++)
                        for (size_t r = 0; r < sizeof relational / sizeof *relational; r++)
                            if (!strcmp(e.items[k].rule, relational[r]))
                                named = 2;
                    named_direct += named == 1;
                    CHECK_MSG(named, "base %zu %s = %g: refused at %s (%s: %s), not at the field",
                              b, leaves[i].ptr, values[v], e.items[0].pointer, e.items[0].rule,
                              e.items[0].message);
                } else {
                    json_t *sum;
                    int rc = run_job(job, &sum);
                    runs++;
                    CHECK_MSG((rc == 0 || rc == 2) && sane(sum, rc), "base %zu %s = %g: rc %d", b,
                              leaves[i].ptr, values[v], rc);
                    json_decref(sum);
                }
                pk_schema_errors_free(&e);
                json_decref(job);
            }
        }
        json_decref(base);
    }
    size_t i;
    json_t *w;
    json_array_foreach (want, i, w) {
        const char *t = json_string_value(w);
        CHECK_MSG(json_object_get(covered, t), "numeric field %s is in no base job", t);
    }
    printf("  %zu numeric fields, %zu runs, %zu refusals (%zu at the field, the others by a rule "
           "between fields)\n",
           json_array_size(want), runs, refusals, named_direct);
    json_decref(covered);
    json_decref(want);
}

/* NaN, Infinity and an overflowing literal anywhere: the parser refuses the
 * file with a line and column (no number reaches the validator). */
static void test_non_finite_literals(void)
{
    const char *lits[] = {"NaN", "Infinity", "-Infinity", "1e999", "-1e999"};
    for (size_t b = 0; b < NBASES; b++) {
        json_t *base = json_loads(bases[b], 0, NULL);
        enum { CAP = 256 };
        static leaf leaves[CAP];
        size_t n = 0;
        instance_leaves(base, "", "", leaves, &n, CAP, NULL, NULL, 0);
        for (size_t i = 0; i < n; i++) {
            json_t *job = json_deep_copy(base);
            static leaf mine[CAP];
            size_t m = 0;
            instance_leaves(job, "", "", mine, &m, CAP, NULL, NULL, 0);
            set_leaf(&mine[i], json_string("@@"));
            char *text = json_dumps(job, JSON_COMPACT);
            char *at = strstr(text, "\"@@\"");
            for (size_t l = 0; at && l < sizeof lits / sizeof *lits; l++) {
                char buf[4096];
                snprintf(buf, sizeof buf, "%.*s%s%s", (int)(at - text), text, lits[l], at + 4);
                json_error_t e;
                json_t *parsed = json_loads(buf, 0, &e);
                CHECK_MSG(!parsed && e.line == 1 && e.column > 0, "%s = %s parsed", leaves[i].ptr,
                          lits[l]);
                json_decref(parsed);
            }
            free(text);
            json_decref(job);
        }
        json_decref(base);
    }
}

/* Run an inputs text; the summary (new ref), rc in *rc. */
static json_t *run_text(const char *inputs_json, int *rc)
{
    json_t *in = json_loads(inputs_json, 0, NULL);
    json_t *sum = NULL;
    *rc = in ? run_job(in, &sum) : -9;
    json_decref(in);
    return sum;
}

static long long placed(const json_t *sum)
{
    return json_integer_value(json_object_get(sum, "count_placed"));
}

static double phi_of(const json_t *sum)
{
    return json_real_value(json_object_get(sum, "phi_resolved"));
}

/* N = 1, 2, 8 in walled and periodic boxes, 2D and 3D, RSA and EDMD: every
 * grain placed, complete, the audit clean. */
static void test_few_grains(void)
{
    const char *algs[] = {"rsa", "edmd"};
    for (int dim = 2; dim <= 3; dim++)
        for (int n = 1; n <= 8; n *= 2)
            for (int per = 0; per < 2; per++)
                for (int a = 0; a < 2; a++) {
                    char buf[512];
                    snprintf(
                        buf, sizeof buf,
                        "{\"dim\":%d,\"domain\":{\"box\":{\"size\":[10,10%s],\"periodic\":%s}},"
                        "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_"
                        "percent\":100}]},"
                        "\"count\":%d,\"delta_d\":0.1,\"algorithm\":\"%s\"}",
                        dim, dim == 3 ? ",10" : "", per ? "true" : "false", n, algs[a]);
                    int rc;
                    json_t *sum = run_text(buf, &rc);
                    CHECK_MSG(rc == 0 && sane(sum, rc) && placed(sum) == n &&
                                  json_is_true(json_object_get(sum, "complete")),
                              "dim %d N %d periodic %d %s: rc %d placed %lld", dim, n, per, algs[a],
                              rc, placed(sum));
                    json_decref(sum);
                }
}

/* Size ratio 1:1000 in 3D: one grain of d = 1000 and 200 of d = 1 (RSA and
 * EDMD), walled and (where the big grain allows) periodic. */
static void test_size_ratio_1000(void)
{
    const char *algs[] = {"rsa", "edmd"};
    for (int a = 0; a < 2; a++) {
        char buf[512];
        snprintf(buf, sizeof buf,
                 "{\"dim\":3,\"domain\":{\"box\":{\"size\":[2500,2500,2500],\"periodic\":[true,"
                 "false,true]}},"
                 "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":1000,\"volume_percent\":99."
                 "99998},"
                 "{\"d\":1,\"volume_percent\":0.00002}]},\"count\":201,\"algorithm\":\"%s\","
                 "\"limits\":{\"wall_time_s\":20}}",
                 algs[a]);
        int rc;
        json_t *sum = run_text(buf, &rc);
        json_t *cls = json_object_get(sum, "classes");
        CHECK_MSG(rc == 0 && sane(sum, rc) && placed(sum) == 201 &&
                      json_integer_value(json_object_get(json_array_get(cls, 0), "placed")) == 1,
                  "%s: rc %d placed %lld", algs[a], rc, placed(sum));
        json_decref(sum);
    }
}

/* Δd three times the smallest grain: every gap >= Δd (RSA, EDMD relative
 * growth, EDMD shell growth). */
static void test_gap_above_smallest_grain(void)
{
    const char *algs[] = {"\"rsa\"", "\"edmd\"", "\"edmd\",\"edmd\":{\"growth\":\"shell\"}"};
    for (int a = 0; a < 3; a++) {
        char buf[512];
        snprintf(buf, sizeof buf,
                 "{\"dim\":3,\"domain\":{\"box\":{\"size\":[20,20,20]}},"
                 "\"grading\":{\"type\":\"sieve\",\"sizes\":[1,2],\"passing\":[0,100]},"
                 "\"count\":50,\"delta_d\":3,\"algorithm\":%s}",
                 algs[a]);
        int rc;
        json_t *sum = run_text(buf, &rc);
        CHECK_MSG(rc == 0 && sane(sum, rc) && placed(sum) == 50 &&
                      json_real_value(json_object_get(sum, "smallest_gap")) >= 3 * (1 - 1e-12),
                  "%s: rc %d", algs[a], rc);
        json_decref(sum);
    }
}

/* A grading with one class, one with empty classes (0 %), a sieve with flat
 * stretches: the empty classes place nothing, the rest as asked. */
static void test_one_and_empty_classes(void)
{
    const char *gradings[] = {
        "{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]}",
        "{\"type\":\"classes\",\"classes\":[{\"d\":4,\"volume_percent\":0},{\"d\":2,\"volume_"
        "percent\":100},"
        "{\"d\":1,\"volume_percent\":0}]}",
        "{\"type\":\"sieve\",\"sizes\":[1,2,3,4],\"passing\":[0,0,100,100]}",
    };
    for (size_t g = 0; g < sizeof gradings / sizeof *gradings; g++)
        for (int a = 0; a < 2; a++) {
            char buf[512];
            snprintf(buf, sizeof buf,
                     "{\"dim\":2,\"domain\":{\"box\":{\"size\":[30,30]}},\"grading\":%s,"
                     "\"phi\":{\"value\":0.2,\"refers_to\":\"mix\"},\"algorithm\":\"%s\"}",
                     gradings[g], a ? "edmd" : "rsa");
            int rc;
            json_t *sum = run_text(buf, &rc);
            CHECK_MSG(rc == 0 && sane(sum, rc) && json_is_true(json_object_get(sum, "complete")) &&
                          fabs(phi_of(sum) - 0.2) < 0.02,
                      "grading %zu %s: rc %d φ %g", g, a ? "edmd" : "rsa", rc, phi_of(sum));
            size_t i;
            json_t *c;
            json_array_foreach (json_object_get(sum, "classes"), i, c) {
                if (json_real_value(json_object_get(c, "target_fraction")) == 0)
                    CHECK(json_integer_value(json_object_get(c, "placed")) == 0);
            }
            json_decref(sum);
        }
}

/* The same job in lengths × 1e-6 and × 1e6: the same counts and φ (RSA:
 * the same packing, φ to 1e-9; EDMD: its target φ to 1e-9). */
static void test_scale_invariance(void)
{
    const double scales[] = {1e-6, 1, 1e6};
    for (int a = 0; a < 2; a++) {
        long long n0 = -1;
        double phi0 = -1;
        for (int k = 0; k < 3; k++) {
            double f = scales[k];
            char buf[640];
            snprintf(
                buf, sizeof buf,
                "{\"dim\":3,\"domain\":{\"box\":{\"size\":[%.17g,%.17g,%.17g],\"periodic\":[true,"
                "false,true]}},"
                "\"grading\":{\"type\":\"sieve\",\"sizes\":[%.17g,%.17g],\"passing\":[0,100]},"
                "\"phi\":{\"value\":0.3,\"refers_to\":\"resolved\"},\"delta_d\":%.17g,\"seed\":3,"
                "\"algorithm\":\"%s\"}",
                12 * f, 12 * f, 12 * f, 1 * f, 2 * f, 0.1 * f, a ? "edmd" : "rsa");
            int rc;
            json_t *sum = run_text(buf, &rc);
            CHECK_MSG(rc == 0 && sane(sum, rc) && json_is_true(json_object_get(sum, "complete")),
                      "%s × %g: rc %d", a ? "edmd" : "rsa", f, rc);
            CHECK(json_real_value(json_object_get(sum, "smallest_gap")) >= 0.1 * f * (1 - 1e-9));
            if (k == 0) {
                n0 = placed(sum);
                phi0 = phi_of(sum);
            } else {
                CHECK_MSG(placed(sum) == n0, "%s × %g: %lld grains, %lld at × 1e-6",
                          a ? "edmd" : "rsa", f, placed(sum), n0);
                CHECK_MSG(fabs(phi_of(sum) - phi0) <= 1e-9 * phi0, "%s × %g: φ %.12g vs %.12g",
                          a ? "edmd" : "rsa", f, phi_of(sum), phi0);
            }
            json_decref(sum);
        }
    }
}

/* A target φ above what the algorithm reaches (RSA 0.95 of disks, EDMD 0.95
 * of equal disks until target): successful, complete false, a warning with
 * the φ reached and the target. */
static void test_target_above_reachable(void)
{
    for (int a = 0; a < 2; a++) {
        char buf[512];
        snprintf(
            buf, sizeof buf,
            "{\"dim\":2,\"domain\":{\"box\":{\"size\":[20,20]}},"
            "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]},"
            "\"phi\":{\"value\":0.95,\"refers_to\":\"resolved\"},\"algorithm\":\"%s\"%s,"
            "\"limits\":{\"wall_time_s\":20}}",
            a ? "edmd" : "rsa", a ? "" : ",\"rsa\":{\"max_failed_draws\":10000}");
        int rc;
        json_t *sum = run_text(buf, &rc);
        const char *w = json_string_value(json_array_get(json_object_get(sum, "warnings"), 0));
        CHECK_MSG(rc == 0 && sane(sum, rc) && json_is_false(json_object_get(sum, "complete")) &&
                      w && strstr(w, "0.95") && phi_of(sum) < 0.92,
                  "%s: rc %d φ %g warning %s", a ? "edmd" : "rsa", rc, phi_of(sum),
                  w ? w : "(none)");
        json_decref(sum);
    }
}

int main(void)
{
    alarm(300); /* a hang is a failure, not a stuck suite */
    RUN(test_numeric_fields_walk);
    RUN(test_non_finite_literals);
    RUN(test_few_grains);
    RUN(test_size_ratio_1000);
    RUN(test_gap_above_smallest_grain);
    RUN(test_one_and_empty_classes);
    RUN(test_scale_invariance);
    RUN(test_target_above_reachable);
    return check_summary();
}
