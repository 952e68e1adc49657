/* test_rsa_draws.c — the job option rsa.draws reaches the placer: a
 * monodisperse pack job with "draws": "plain" makes exactly the draws of
 * core RSA with PK_RSA_DRAWS_PLAIN one grain at a time (Titscher's loop), the
 * default ("open") those of PK_RSA_DRAWS_OPEN — far fewer for the same grains
 * — and a value outside the enum is refused by the schema. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "api/process.h"
#include "core/rsa/rsa.h"

#define NGRAIN 2000
#define BOX_L 10.0
#define SEED 3

static const char *job_fmt =
    "{\"process\": \"pack\", \"inputs\": {\"dim\": 3, \"unit\": \"mm\","
    " \"domain\": {\"box\": {\"size\": [10, 10, 10], \"periodic\": true}},"
    " \"grading\": {\"type\": \"classes\", \"classes\": [{\"d\": 1.0, \"volume_percent\": 100}]},"
    " \"sampling\": \"discrete\", \"count\": 2000, \"phi\": {\"value\": 0.33, \"refers_to\": "
    "\"resolved\"},"
    " \"algorithm\": \"rsa\", \"seed\": 3%s}}";

/* Runs the job with `extra` appended to its inputs; the summary (new ref) or NULL. */
static json_t *run_job(const char *extra, pk_schema_errors *errs)
{
    char text[1024], out[] = "/tmp/packd-test-rsa-draws-XXXXXX";
    snprintf(text, sizeof text, job_fmt, extra);
    int fd = mkstemp(out);
    close(fd);
    unlink(out);
    json_t *job = json_loads(text, 0, NULL);
    json_t *sum = NULL;
    char err[512] = "";
    int rc = pk_job_run(job, NULL, out, &sum, errs, err, sizeof err);
    json_decref(job);
    unlink(out);
    if (rc != 0) {
        json_decref(sum);
        return NULL;
    }
    return sum;
}

/* Draws of core RSA for the job's grains (diameter: the summary's size_scale). */
static uint64_t core_draws(double d, pk_rsa_draws draws, int one_at_a_time)
{
    pk_box b = {.dim = 3, .L = {BOX_L, BOX_L, BOX_L}, .periodic = {true, true, true}};
    double *dd = malloc(NGRAIN * sizeof *dd);
    int32_t *sp = calloc(NGRAIN, sizeof *sp);
    for (size_t i = 0; i < NGRAIN; i++)
        dd[i] = d;
    pk_particles p;
    pk_particles_init(&p, 3, NGRAIN);
    pk_rsa_params prm = {.max_failed_draws = 1000000,
                         .seed = SEED,
                         .draws = draws,
                         .test.one_at_a_time = one_at_a_time};
    pk_rsa_stats st;
    CHECK(pk_rsa_place(&b, dd, sp, NGRAIN, &prm, NULL, &p, &st) == 0 && st.placed == NGRAIN);
    pk_particles_free(&p);
    free(dd);
    free(sp);
    return st.draws;
}

static uint64_t job_draws(const json_t *sum)
{
    return (uint64_t)json_integer_value(json_object_get(json_object_get(sum, "rsa"), "draws"));
}

static void test_job_draws_reach_core(void)
{
    pk_schema_errors errs = {0};
    json_t *plain = run_job(", \"rsa\": {\"draws\": \"plain\"}", &errs);
    json_t *open = run_job("", &errs);
    CHECK(plain && open && errs.n == 0);
    if (plain && open) {
        double d = json_real_value(json_object_get(plain, "size_scale"));
        uint64_t ref_plain = core_draws(d, PK_RSA_DRAWS_PLAIN, 1);
        uint64_t ref_open = core_draws(d, PK_RSA_DRAWS_OPEN, 0);
        printf("  plain: job %llu, core %llu draws; open: job %llu, core %llu\n",
               (unsigned long long)job_draws(plain), (unsigned long long)ref_plain,
               (unsigned long long)job_draws(open), (unsigned long long)ref_open);
        CHECK(job_draws(plain) == ref_plain);
        CHECK(job_draws(open) == ref_open);
        CHECK(ref_open < ref_plain / 2);
    }
    json_decref(plain);
    json_decref(open);
    pk_schema_errors_free(&errs);
}

static void test_unknown_draws_refused(void)
{
    pk_schema_errors errs = {0};
    json_t *sum = run_job(", \"rsa\": {\"draws\": \"fast\"}", &errs);
    CHECK(sum == NULL);
    int hit = 0;
    for (size_t i = 0; i < errs.n; i++)
        hit |= strcmp(errs.items[i].pointer, "/inputs/rsa/draws") == 0 &&
            strcmp(errs.items[i].rule, "enum") == 0;
    CHECK(hit);
    json_decref(sum);
    pk_schema_errors_free(&errs);
}

int main(void)
{
    RUN(test_job_draws_reach_core);
    RUN(test_unknown_draws_refused);
    return check_summary();
}
