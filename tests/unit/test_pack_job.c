/* test_pack_job.c — the pack job's plan (what a job implies before drawing)
 * reproduces the reference counts of spec §1.6 through the JSON inputs, and
 * a full run's sampled count agrees with the plan within its spread. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "pack_job.h"
#include "process.h"

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
        fprintf(stderr, "  %s %s %s\n", errs.items[i].pointer, errs.items[i].rule, errs.items[i].message);
    pk_schema_errors_free(&errs);
    json_decref(in);
    return n ? -1 : 0;
}

/* Expected counts at a = 150 mm, φ_M = 0.70, d_min = 2 mm (spec §1.6;
 * Titscher §3 "≈ 44 000 / 40 000"; Eq. 13 sign-corrected for Fuller).  ±1
 * absorbs the rounding of the published integers. */
static void test_plan_reference_counts(void)
{
    const char *fmt = "{\"dim\":3,\"domain\":{\"box\":{\"size\":[150,150,150]}},\"grading\":%s,"
                      "\"d_min\":2,\"phi\":{\"value\":0.7,\"refers_to\":\"mix\"},"
                      "\"limits\":{\"max_particles\":100000000}}";
    struct { const char *grading; double n, phi_eff; } cases[] = {
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
                    "\"phi\":{\"value\":0.4227,\"refers_to\":\"resolved\"}}", &plan) == 0);
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
        "\"phi\":{\"value\":0.3,\"refers_to\":\"mix\"},\"seed\":5}}", 0, NULL);
    pk_schema_errors errs = {0};
    json_t *sum = NULL;
    char err[256];
    CHECK(pk_job_run(job, out, NULL, &sum, &errs, err, sizeof err) == 0);
    if (sum) {
        double expected = json_real_value(json_object_get(sum, "count_expected"));
        double placed = (double)json_integer_value(json_object_get(sum, "count_placed"));
        CHECK_NEAR(expected, 5125.0 * 0.3 / 0.535, 1.5);
        CHECK_MSG(fabs(placed - expected) < 0.03 * expected, "placed %g expected %g", placed, expected);
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

int main(void)
{
    RUN(test_plan_reference_counts);
    RUN(test_plan_resolved_target);
    RUN(test_run_count_matches_plan);
    return check_summary();
}
