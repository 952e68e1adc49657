/* bench/edmd_titscher — Titscher & Unger §6.3, the meshable A16 specimen
 * (a = 80 mm walled, d_min = 2 mm, Δd = 1 mm) through `packd run`'s code
 * path (pk_job_run).  One line per case:
 *   bench=edmd_titscher case=NAME phi_M=F seed=S wall_gap=half|none n=N
 *         reached=yes|no delta_d=D phi_shell=F criterion=C events=E seconds=S cpu_s=T
 * Cases: Δd_max with walls at Δd/2 (maximize, 3 seeds) and Titscher's t_end
 * protocol with wall_gap none at φ_M = 53.5 % (3 seeds); PACKD_BENCH_LARGE=1
 * adds the success-rate sweep φ_M = 53.5/54/54.5 % over 5 seeds (the paper:
 * maximum 53.5 % with 90 % success, Fig. 9). */
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "api/process.h"

static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
        (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static double num(json_t *o, const char *key) { return json_number_value(json_object_get(o, key)); }

/* maximize: grow the shell until jammed (job delta_d 0.5 as the floor). */
static void a16(const char *name, double phi_mix, int seed, const char *wall_gap, int maximize)
{
    char txt[1024];
    snprintf(txt, sizeof txt,
             "{\"process\":\"pack\",\"inputs\":{\"dim\":3,\"domain\":{\"box\":{\"size\":[80,80,80],"
             "\"periodic\":false}},\"grading\":{\"type\":\"preset\",\"name\":\"A16\"},\"d_min\":2,"
             "\"phi\":{\"value\":%g,\"refers_to\":\"mix\"},\"delta_d\":%g,\"algorithm\":\"edmd\","
             "\"edmd\":{%s\"growth_rate\":0.01,\"wall_gap\":\"%s\"},\"seed\":%d}}",
             phi_mix, maximize ? 0.5 : 1.0,
             maximize ? "\"maximize\":\"delta_d\"," : "\"growth\":\"shell\",", wall_gap, seed);
    json_error_t e;
    json_t *job = json_loads(txt, 0, &e);
    pk_schema_errors errs = {0};
    json_t *sum = NULL;
    char err[512] = "";
    const char *out = "/tmp/packd-bench-edmd-titscher.h5";
    double c0 = cpu_s();
    int rc = job ? pk_job_run(job, NULL, out, &sum, &errs, err, sizeof err) : -1;
    double cpu = cpu_s() - c0;
    printf("bench=edmd_titscher case=%s phi_M=%g seed=%d wall_gap=%s ", name, phi_mix, seed,
           wall_gap);
    if (rc == 0) {
        json_t *o = json_object_get(sum, "edmd");
        double dd = num(o, "delta_d_reached");
        printf(
            "n=%lld reached=%s delta_d=%.4f phi_mix=%.4f phi_shell=%.4f criterion=%s events=%.0f "
            "seconds=%.2f cpu_s=%.2f\n",
            (long long)json_integer_value(json_object_get(sum, "count_placed")),
            dd >= 1 - 1e-12 ? "yes" : "no", dd, num(sum, "phi_mix"), num(o, "phi_shell"),
            json_string_value(json_object_get(o, "termination_criterion")),
            (double)json_integer_value(json_object_get(o, "events")), num(sum, "seconds_place"),
            cpu);
    } else {
        printf("reached=no error=\"%s\" cpu_s=%.2f\n", err, cpu);
    }
    fflush(stdout);
    remove(out);
    json_decref(sum);
    json_decref(job);
    pk_schema_errors_free(&errs);
}

int main(void)
{
    for (int s = 1; s <= 3; s++)
        a16("a16_dd_max_walls_half", 0.535, s, "half", 1);
    for (int s = 1; s <= 3; s++)
        a16("a16_dd1_walls_none", 0.535, s, "none", 0);
    if (getenv("PACKD_BENCH_LARGE") && atoi(getenv("PACKD_BENCH_LARGE"))) {
        const double phis[] = {0.535, 0.54, 0.545};
        for (int k = 0; k < 3; k++)
            for (int s = 1; s <= 5; s++)
                a16("a16_dd1_walls_none_sweep", phis[k], s, "none", 0);
    } else {
        printf(
            "bench=edmd_titscher case=a16_dd1_walls_none_sweep skipped=set_PACKD_BENCH_LARGE=1\n");
    }
    return 0;
}
