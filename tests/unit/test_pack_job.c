/* test_pack_job.c — the pack job's plan (what a job implies before drawing)
 * reproduces the reference counts of spec §1.6 through the JSON inputs, and
 * a full run's sampled count agrees with the plan within its spread. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/pack/pack_job.h"
#include "api/pack/pack_placer.h"
#include "api/process.h"

/* checks as on the user's own machine (packd run / validate) */
static const pk_check_ctx local = {0};

static int plan_from(const char *inputs_json, pk_pack_plan *plan)
{
    json_error_t e;
    json_t *in = json_loads(inputs_json, 0, &e);
    if (!in)
        return -1;
    pk_schema_errors errs = {0};
    pk_pack_job job;
    size_t n = pk_schema_validate_embedded("pack.inputs.schema.json", in, &errs);
    if (!n)
        n = pk_pack_job_from_json(in, &job, &errs) + pk_pack_plan_make(&job, plan, &errs);
    for (size_t i = 0; i < errs.n; i++)
        fprintf(stderr, "  %s %s %s\n", errs.items[i].pointer, errs.items[i].rule,
                errs.items[i].message);
    pk_schema_errors_free(&errs);
    json_decref(in);
    return n ? -1 : 0;
}

/* Schema + semantic errors of an inputs object: is there one at `ptr` with `rule`? */
static int refused(const char *inputs_json, const char *ptr, const char *rule)
{
    json_t *in = json_loads(inputs_json, 0, NULL);
    if (!in)
        return 0;
    pk_schema_errors errs = {0};
    pk_process_validate_inputs(pk_process_find("pack"), in, &local, &errs);
    int hit = 0;
    for (size_t i = 0; i < errs.n; i++) {
        if (!strcmp(errs.items[i].pointer, ptr) && !strcmp(errs.items[i].rule, rule))
            hit = 1;
    }
    if (!hit)
        for (size_t i = 0; i < errs.n; i++)
            fprintf(stderr, "  (got %s %s %s)\n", errs.items[i].pointer, errs.items[i].rule,
                    errs.items[i].message);
    pk_schema_errors_free(&errs);
    json_decref(in);
    return hit;
}

/* Run a pack job (inputs JSON) to a temporary file: pk_job_run's return, the
 * summary (new ref) and whether a result file was written. */
static int run_inputs(const char *inputs_json, json_t **sum, int *file_written)
{
    char out[] = "/tmp/packd-test-pack-XXXXXX";
    int fd = mkstemp(out);
    close(fd);
    unlink(out);
    json_t *job =
        json_pack("{s:s,s:o}", "process", "pack", "inputs", json_loads(inputs_json, 0, NULL));
    pk_schema_errors errs = {0};
    char err[512] = "";
    *sum = NULL;
    int rc = pk_job_run(job, NULL, out, sum, &errs, err, sizeof err);
    if (rc != 0 && rc != 2) /* 2: a failed verdict, its file written */
        fprintf(stderr, "  run: rc %d: %s %s\n", rc, err, errs.n ? errs.items[0].message : "");
    *file_written = access(out, F_OK) == 0;
    unlink(out);
    json_decref(job);
    pk_schema_errors_free(&errs);
    return rc;
}

static const char *first_warning(const json_t *sum)
{
    return json_string_value(json_array_get(json_object_get(sum, "warnings"), 0));
}

/* Expected counts at a = 150 mm, φ_M = 0.70, d_min = 2 mm (spec §1.6;
 * Titscher §3 "≈ 44 000 / 40 000"; Eq. 13 sign-corrected for Fuller).  ±1
 * absorbs the rounding of the published integers. */
static void test_plan_reference_counts(void)
{
    const char *fmt = "{\"dim\":3,\"domain\":{\"box\":{\"size\":[150,150,150]}},\"grading\":%s,"
                      "\"d_min\":2,\"phi\":{\"value\":0.7,\"refers_to\":\"mix\"},"
                      "\"limits\":{\"max_particles\":100000000}}";
    struct {
        const char *grading;
        double n, phi_eff;
    } cases[] = {
        {"{\"type\":\"preset\",\"name\":\"A16\"}", 44202, 0.553},
        {"{\"type\":\"preset\",\"name\":\"B16\"}", 40049, 0.406},
        {"{\"type\":\"fuller\",\"q\":0.7,\"d_max\":16}", 39704, 0.537},
        {"{\"type\":\"fuller\",\"q\":0.35,\"d_max\":16}", 35831, 0.362},
    };
    for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
        char buf[512];
        snprintf(buf, sizeof buf, fmt, cases[i].grading);
        pk_pack_plan plan;
        CHECK(plan_from(buf, &plan) == 0);
        CHECK_NEAR(plan.expected_n, cases[i].n, 1.0);
        CHECK_NEAR(plan.phi_resolved, cases[i].phi_eff, 0.0005); /* 3 printed digits */
        CHECK_NEAR(plan.phi_mix, 0.7, 1e-12);
    }
}

/* φ given as resolved: φ_M follows from the cut (Eq. 17). */
static void test_plan_resolved_target(void)
{
    pk_pack_plan plan;
    CHECK(plan_from("{\"dim\":3,\"domain\":{\"box\":{\"size\":[80,80,80]}},"
                    "\"grading\":{\"type\":\"preset\",\"name\":\"A16\"},\"d_min\":2,"
                    "\"phi\":{\"value\":0.4227,\"refers_to\":\"resolved\"}}",
                    &plan) == 0);
    CHECK_NEAR(plan.mass_cut, 0.21, 1e-12);
    CHECK_NEAR(plan.phi_mix, 0.4227 / 0.79, 1e-12);
    CHECK_NEAR(plan.expected_n, 5125, 1.5); /* Titscher §6.3: φ_M = 0.535 → 5 125 */
}

/* A whole run through the one job path: sampled count within 4 standard
 * deviations of the plan (σ ≈ 0.7 % of N for A16, measured over 32 seeds in
 * test_psd; 4σ ≈ 3 %), φ_eff within one coarse grain of the target. */
static void test_run_count_matches_plan(void)
{
    char out[] = "/tmp/packd-test-pack-XXXXXX";
    int fd = mkstemp(out);
    close(fd);
    json_t *job = json_loads(
        "{\"process\":\"pack\",\"inputs\":{\"dim\":3,\"domain\":{\"box\":{\"size\":[80,80,80]}},"
        "\"grading\":{\"type\":\"preset\",\"name\":\"A16\"},\"d_min\":2,"
        "\"phi\":{\"value\":0.3,\"refers_to\":\"mix\"},\"seed\":5}}",
        0, NULL);
    pk_schema_errors errs = {0};
    json_t *sum = NULL;
    char err[256];
    CHECK(pk_job_run(job, NULL, out, &sum, &errs, err, sizeof err) == 0);
    if (sum) {
        double expected = json_real_value(json_object_get(sum, "count_expected"));
        double placed = (double)json_integer_value(json_object_get(sum, "count_placed"));
        CHECK_NEAR(expected, 5125.0 * 0.3 / 0.535, 1.5);
        CHECK_MSG(fabs(placed - expected) < 0.03 * expected, "placed %g expected %g", placed,
                  expected);
        double phi = json_real_value(json_object_get(sum, "phi_mix"));
        /* one 16 mm grain is 0.4 % of the 80 mm cube: the overshoot bound */
        CHECK(phi >= 0.3 && phi < 0.3 + 0.005);
        CHECK(json_is_true(json_object_get(sum, "complete")));
    }
    json_decref(sum);
    json_decref(job);
    pk_schema_errors_free(&errs);
    unlink(out);
}

#define MONO2D(L)                                                                                  \
    "\"dim\":2,\"domain\":{\"box\":{\"size\":[" L "," L "]}},"                                     \
    "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]}"

/* Issue 21 item 4: an integer written as a decimal is that integer (jansson
 * reads 0 for a real: 500.0 grains became 1), and 1e308 breaks a maximum. */
static void test_integer_as_real(void)
{
    pk_pack_plan plan;
    CHECK(plan_from("{" MONO2D("20") ",\"count\":50.0}", &plan) == 0);
    CHECK_NEAR(plan.expected_n, 50, 0);
    json_t *a, *b;
    int fa, fb;
    CHECK(
        run_inputs(
            "{" MONO2D("20") ",\"count\":50.0,\"seed\":5.0,\"rsa\":{\"max_failed_draws\":1000.0}}",
            &a, &fa) == 0);
    CHECK(
        run_inputs("{" MONO2D("20") ",\"count\":50,\"seed\":5,\"rsa\":{\"max_failed_draws\":1000}}",
                   &b, &fb) == 0);
    CHECK(json_integer_value(json_object_get(a, "count_placed")) == 50);
    CHECK(json_integer_value(json_object_get(json_object_get(a, "rsa"), "max_failed_draws")) ==
          1000);
    /* same seed: the same packing */
    CHECK(json_real_value(json_object_get(a, "smallest_gap")) ==
          json_real_value(json_object_get(b, "smallest_gap")));
    json_decref(a);
    json_decref(b);
    CHECK(refused("{" MONO2D("20") ",\"count\":1e308}", "/count", "maximum"));
    CHECK(refused("{" MONO2D("20") ",\"count\":5,\"limits\":{\"max_particles\":1e308}}",
                  "/limits/max_particles", "maximum"));
    CHECK(refused(
        "{" MONO2D("20") ",\"count\":5,\"algorithm\":\"edmd\",\"edmd\":{\"max_events\":1e308}}",
        "/edmd/max_events", "maximum"));
    CHECK(refused(
        "{" MONO2D(
            "20") ",\"count\":5,\"algorithm\":\"edmd\",\"edmd\":{\"stall\":{\"events\":1e308}}}",
        "/edmd/stall/events", "maximum"));
    CHECK(refused("{" MONO2D("20") ",\"count\":2.5}", "/count", "type"));
}

/* Issue 21 item 5: a count implying φ > 1 (500 grains of d = 2 in a 20 × 20
 * box: φ 3.93) is refused, also when only the gaps Δd push it over 1. */
static void test_phi_implied_above_one(void)
{
    CHECK(refused("{" MONO2D("20") ",\"count\":500}", "/count", "resolvedBelow1"));
    /* φ 0.353, with shells d + Δd = 4 in the 22-box (walls Δd/2): 1.17 */
    CHECK(refused("{" MONO2D("20") ",\"count\":45,\"delta_d\":2}", "/delta_d", "resolvedBelow1"));
    pk_pack_plan plan;
    CHECK(plan_from("{" MONO2D("20") ",\"count\":45,\"delta_d\":0.5}", &plan) == 0);
}

/* Issue 21 item 9: periodic EDMD until jammed with few grains: the engine's
 * minimum-image rule, refused at validation naming it; until a target the
 * same small counts run. */
static void test_periodic_jamming_rule(void)
{
    const char *fmt =
        "{\"dim\":3,\"domain\":{\"box\":{\"size\":[10,10,10],\"periodic\":true}},"
        "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]},"
        "\"count\":%d,\"algorithm\":\"edmd\",\"edmd\":{\"until\":\"%s\"}}";
    char buf[512];
    snprintf(buf, sizeof buf, fmt, 8, "jammed");
    CHECK(refused(buf, "/domain/box/size/0", "periodicJamming"));
    snprintf(buf, sizeof buf, fmt, 15, "jammed"); /* N > 48/π = 15.3 needed */
    CHECK(refused(buf, "/domain/box/size/0", "periodicJamming"));
    pk_pack_plan plan;
    snprintf(buf, sizeof buf, fmt, 16, "jammed");
    CHECK(plan_from(buf, &plan) == 0);
    for (int n = 1; n <= 8; n *= 2) {
        snprintf(buf, sizeof buf, fmt, n, "target");
        json_t *sum;
        int f;
        CHECK(run_inputs(buf, &sum, &f) == 0 && f);
        CHECK(json_integer_value(json_object_get(sum, "count_placed")) == n);
        CHECK(json_is_true(json_object_get(sum, "complete")));
        json_decref(sum);
    }
}

/* A target φ above what RSA reaches: successful, complete false, a warning
 * with the φ reached and the target (was: complete false, no word why). */
static void test_saturated_warns(void)
{
    json_t *sum;
    int f;
    CHECK(run_inputs("{" MONO2D("20") ",\"phi\":{\"value\":0.8,\"refers_to\":\"resolved\"},"
                                      "\"rsa\":{\"max_failed_draws\":1000}}",
                     &sum, &f) == 0 &&
          f);
    CHECK(json_is_false(json_object_get(sum, "complete")));
    CHECK(!json_object_get(sum, "failure"));
    const char *w = first_warning(sum);
    CHECK_MSG(w && strstr(w, "saturated") && strstr(w, "0.8"), "warning: %s", w ? w : "(none)");
    json_decref(sum);
}

/* Out of wall time: failed, the partial file kept (was: complete false,
 * successful). */
static void test_wall_time_fails(void)
{
    json_t *sum;
    int f;
    int rc = run_inputs(
        "{\"dim\":3,\"domain\":{\"box\":{\"size\":[30,30,30],\"periodic\":true}},"
        "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]},"
        "\"phi\":{\"value\":0.5,\"refers_to\":\"resolved\"},\"algorithm\":\"edmd\","
        "\"edmd\":{\"until\":\"jammed\"},\"limits\":{\"wall_time_s\":0.2}}",
        &sum, &f);
    CHECK(rc == 2 && f);
    const char *why = json_string_value(json_object_get(sum, "failure"));
    CHECK_MSG(why && strstr(why, "wall time"), "failure: %s", why ? why : "(none)");
    CHECK(json_is_false(json_object_get(sum, "complete")));
    json_decref(sum);
}

/* Cancel once the RSA start of an EDMD run has placed some grains. */
static int cancel_in_rsa(const pk_progress *pg, void *ctx)
{
    (void)ctx;
    return pg->stage && !strcmp(pg->stage, "rsa") && pg->done > 0;
}

/* Stopped inside the EDMD's RSA start (grains placed at δ·d; shell growth at
 * gap 0): failed, the partial file holds the grains as placed and passes its
 * audit (was: radii at the target sizes, hundreds of overlapping pairs). */
static void test_stop_in_rsa_start(void)
{
    const char *shapes[] = {"\"until\":\"jammed\"", "\"maximize\":\"delta_d\""};
    for (int k = 0; k < 2; k++) {
        char buf[640];
        snprintf(buf, sizeof buf,
                 "{\"process\":\"pack\",\"inputs\":{\"dim\":3,\"domain\":{\"box\":{\"size\":"
                 "[30,30,30],\"periodic\":true}},\"grading\":{\"type\":\"classes\",\"classes\":"
                 "[{\"d\":2,\"volume_percent\":100}]},\"phi\":{\"value\":0.5,\"refers_to\":"
                 "\"resolved\"},\"delta_d\":0.1,\"algorithm\":\"edmd\",\"edmd\":{%s}}}",
                 shapes[k]);
        json_t *job = json_loads(buf, 0, NULL);
        char out[] = "/tmp/packd-test-pack-XXXXXX";
        int fd = mkstemp(out);
        close(fd);
        pk_monitor mon = {.fn = cancel_in_rsa, .interval_s = 1e-9};
        pk_run_ctx run = PK_RUN_CTX_DEFAULT;
        run.mon = &mon;
        pk_schema_errors errs = {0};
        json_t *sum = NULL;
        char err[512];
        CHECK(pk_job_run(job, &run, out, &sum, &errs, err, sizeof err) == 2);
        const char *why = json_string_value(json_object_get(sum, "failure"));
        CHECK_MSG(why && strstr(why, "cancelled"), "%s: failure %s", shapes[k],
                  why ? why : "(none)");
        long long placed = json_integer_value(json_object_get(sum, "count_placed"));
        CHECK(placed > 0 && placed < 3223);
        CHECK(json_integer_value(json_object_get(sum, "pairs_below_delta_d")) == 0);
        json_decref(sum);
        json_decref(job);
        pk_schema_errors_free(&errs);
        unlink(out);
    }
}

/* Issue 21 item 10: maximize delta_d short of the job's delta_d keeps the
 * maximized packing (was: exit 2, no file), complete false with the Δd
 * reached; every gap of the file is >= that Δd. */
static void test_maximize_short_keeps_file(void)
{
    json_t *sum;
    int f;
    int rc =
        run_inputs("{" MONO2D("20") ",\"count\":50,\"delta_d\":1.4,\"algorithm\":\"edmd\","
                                    "\"edmd\":{\"maximize\":\"delta_d\",\"wall_gap\":\"half\"}}",
                   &sum, &f);
    CHECK(rc == 0 && f);
    double dd = json_real_value(json_object_get(json_object_get(sum, "edmd"), "delta_d_reached"));
    CHECK(dd > 0.5 && dd < 1.4);
    CHECK(json_real_value(json_object_get(sum, "smallest_gap")) >= dd * (1 - 1e-9));
    CHECK(json_is_false(json_object_get(sum, "complete")));
    const char *w = first_warning(sum);
    CHECK_MSG(w && strstr(w, "short of the job's delta_d = 1.4"), "warning: %s", w ? w : "(none)");
    json_decref(sum);
}

/* "until": "jammed" that jams did what it was asked: complete, stopped by
 * the pressure criterion (the stop named as what it is).  Seed 2: eight
 * spheres on their lattice grow ~γ/p per window, at the round-off of the
 * sizes near p = 10¹²; with seed 1 the stall detector ends the run first
 * (p 2·10¹¹), 1 of seeds 1–6, which one depends on the last bit. */
static void test_until_jammed_complete(void)
{
    json_t *sum;
    int f;
    CHECK(run_inputs(
              "{\"dim\":3,\"domain\":{\"box\":{\"size\":[10,10,10]}},"
              "\"grading\":{\"type\":\"classes\",\"classes\":[{\"d\":2,\"volume_percent\":100}]},"
              "\"count\":8,\"algorithm\":\"edmd\",\"edmd\":{\"until\":\"jammed\"},\"seed\":2}",
              &sum, &f) == 0);
    CHECK(!strcmp(json_string_value(json_object_get(sum, "termination_reason")), "pressure"));
    CHECK(json_is_true(json_object_get(sum, "complete")));
    json_decref(sum);
}

/* A packing that fails its own gap audit, or holds a non-finite number, is
 * failed (was: -1, no file) — the verdict on fabricated audits. */
static void test_verdict_audit_and_non_finite(void)
{
    pk_pack_job job = {.dim = 2, .algorithm = "rsa"};
    pk_pack_plan plan = {.phi_resolved = 0.3};
    pk_place_stats st = {.reason = PK_STOP_COMPLETE, .placed = 2, .requested = 2};
    pk_particles p;
    pk_particles_init(&p, 2, 2);
    double x[3] = {1, 1, 0}, y[3] = {2, 1, 0};
    pk_particles_push(&p, x, 0.5, 0);
    pk_particles_push(&p, y, 0.5, 0);
    pk_gap_report gap = {.min_gap = -0.1, .min_wall_gap = 0.5, .pairs_below = 1};
    json_t *sum = json_object();
    pk_pack_verdict(&job, &plan, &st, &p, &gap, 0.3, 0.1, sum);
    const char *why = json_string_value(json_object_get(sum, "failure"));
    CHECK_MSG(why && strstr(why, "gap audit"), "failure: %s", why ? why : "(none)");
    CHECK(json_is_false(json_object_get(sum, "complete")));
    json_decref(sum);
    gap = (pk_gap_report){.min_gap = 0.1, .min_wall_gap = 0.5};
    p.x[0] = NAN;
    sum = json_object();
    pk_pack_verdict(&job, &plan, &st, &p, &gap, 0.3, 0.1, sum);
    why = json_string_value(json_object_get(sum, "failure"));
    CHECK_MSG(why && strstr(why, "non-finite"), "failure: %s", why ? why : "(none)");
    json_decref(sum);
    p.x[0] = 1;
    sum = json_object();
    pk_pack_verdict(&job, &plan, &st, &p, &gap, 0.3, 0.1, sum);
    CHECK(json_is_true(json_object_get(sum, "complete")) && !json_object_get(sum, "failure"));
    json_decref(sum);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_plan_reference_counts);
    RUN(test_plan_resolved_target);
    RUN(test_run_count_matches_plan);
    RUN(test_integer_as_real);
    RUN(test_phi_implied_above_one);
    RUN(test_periodic_jamming_rule);
    RUN(test_saturated_warns);
    RUN(test_wall_time_fails);
    RUN(test_stop_in_rsa_start);
    RUN(test_maximize_short_keeps_file);
    RUN(test_until_jammed_complete);
    RUN(test_verdict_audit_and_non_finite);
    return check_summary();
}
