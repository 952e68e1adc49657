/* bench/rsa — RSA placement rate.  It leads with the real workloads, job
 * files of bench/jobs/ run through `packd run`'s code path (pk_job_run), each
 * run in a child process (`rsa jobs`: only these):
 *   bench=rsa case=NAME job=FILE n=N placed=N reason=R phi_mix=F seconds=S
 *             cpu_s=S rate=GRAINS_PER_CPU_S rate_wall=GRAINS_PER_S
 *             draws_per_grain=X maxrss_kb=N ... reps=K rate_min rate_max
 * (rate: grains placed per CPU second of the whole job; seconds: the
 * placement's wall time; maxrss_kb: the job's peak resident memory; the line
 * is the median run's) and a scaling line for A16.  Then the monodisperse
 * references, one line per case:
 *   bench=rsa case=NAME n=N placed=N seconds=S cpu_s=S sys_s=S minflt=N
 *             rate=PLACEMENTS_PER_S draws_per_grain=X maxrss_kb=N
 * and a final line with the rate ratio 1e6/1e4 (flat = the placer scales).
 * The monodisperse cases without suffix take the default path (batched runs of
 * equal grains, rsa_batch.h, drawing from the open region once most draws
 * fail, rsa_region.h); *_batch_plain the batched path with plain draws all
 * along (draws = plain: the packing of plain draws, bit for bit); *_plain
 * runs the reference (draws = plain, test.one_at_a_time: one uniform draw at a
 * time) and *_voxels the per-grain voxel-pruned path (draws = open,
 * test.one_at_a_time) for the ratios;
 * 1e6 plain and voxels are left out (a minute / 20 s).  Each run is a child
 * process of its own (fresh memory, as a job's worker), each default-path
 * case runs several times (reps=; 9, 5, 3 at 10^4, 10^5, 10^6) and its line
 * is the median run's, with rate_min and rate_max of all.  maxrss_kb: the
 * run's peak resident memory; cpu_s:
 * the placement's CPU time (user + system; on a loaded machine the wall
 * seconds wander 2-3x, compare cpu_s old vs new back to back); sys_s and
 * minflt: the placement's system time and page faults (a page's first touch
 * costs ~2 µs here: at 10^6 grains ~15 % of the run); audit_s: the gap audit
 * every job runs on its packing (core/space/gap_audit.h, horizon r_max as the jobs
 * pass it), timed after the placement, with its ratio to the placement.
 * `rsa mono` runs only the default-path monodisperse cases (1e4, 1e5, 1e6)
 * and the scaling line: a quick re-measurement.  `rsa gap` runs only A16 with
 * Δd 1 mm at 10^3..10^6 grains and Titscher's 150 mm specimen (gap()).
 * The first line, case=machine, is the machine's state at the time: the
 * latency of a dependent load from a 64 MB array (a random cycle).  The
 * placer is bound by such loads, and this VM's latency wanders (150-200 ns
 * per load; rates 0.8-1.4 M/s at 10^6 grains within an hour, the same
 * binary): read a rate beside it, or compare binaries run alternately. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/space/gap_audit.h"
#include "api/pack/pack_job.h"
#include "api/process.h"
#include "core/rsa/rsa.h"
#include "bench/jobs/bench_job.h"

enum path { PLAIN, VOXELS, BATCH_PLAIN, BATCHED };
/* Runs of the default path's cases (medians; ~0.1, 0.4 and 2.5 s in all). */
#define REPS_1E4 9
#define REPS_1E5 5
#define REPS_1E6 3

static double cpu_seconds(const struct rusage *ru)
{
    return (double)(ru->ru_utime.tv_sec + ru->ru_stime.tv_sec) +
        1e-6 * (double)(ru->ru_utime.tv_usec + ru->ru_stime.tv_usec);
}

static double sys_seconds(const struct rusage *ru)
{
    return (double)ru->ru_stime.tv_sec + 1e-6 * (double)ru->ru_stime.tv_usec;
}

/* Nanoseconds per dependent load over a random cycle of 16M entries (64 MB,
 * twice the last-level cache and far beyond the TLB's reach). */
static double dram_chase_ns(void)
{
    const size_t n = (size_t)1 << 24;
    uint32_t *a = malloc(n * sizeof *a);
    if (!a)
        return NAN;
    for (size_t i = 0; i < n; i++)
        a[i] = (uint32_t)i;
    uint64_t s = 0x9E3779B97F4A7C15ull;
    for (size_t i = n - 1; i > 0; i--) { /* Sattolo: one cycle through all entries */
        s ^= s << 13, s ^= s >> 7, s ^= s << 17;
        size_t k = (size_t)(s % i);
        uint32_t t = a[i];
        a[i] = a[k];
        a[k] = t;
    }
    const long steps = 4000000;
    uint32_t j = 0;
    double t0 = pk_wall_seconds();
    for (long q = 0; q < steps; q++)
        j = a[j];
    double ns = 1e9 * (pk_wall_seconds() - t0) / (double)steps;
    free(a);
    return j == UINT32_MAX ? NAN : ns; /* (j used: the loop stays) */
}

/* One placement of n unit spheres (dim, phi, path): its rate; *line gets the
 * case's line, with the gap audit when audit is set. */
static double mono_once(const char *name, int dim, size_t n, double phi, enum path path, int audit,
                        char *line, size_t size)
{
    /* box edge so that n unit spheres fill phi */
    double v = dim == 3 ? 3.14159265358979 / 6 : 3.14159265358979 / 4;
    double L = dim == 3 ? cbrt((double)n * v / phi) : sqrt((double)n * v / phi);
    pk_box b = {.dim = dim, .L = {L, L, dim == 3 ? L : 0}, .periodic = {true, true, true}};
    double *d = malloc(n * sizeof *d);
    int32_t *sp = calloc(n, sizeof *sp);
    for (size_t i = 0; i < n; i++)
        d[i] = 1.0;
    pk_particles p;
    pk_particles_init(&p, dim, n);
    pk_rsa_params prm = {.delta_d = 0,
                         .max_failed_draws = 1000000,
                         .seed = 1,
                         .draws = path == PLAIN || path == BATCH_PLAIN ? PK_RSA_DRAWS_PLAIN
                                                                       : PK_RSA_DRAWS_OPEN,
                         .test.one_at_a_time = path == PLAIN || path == VOXELS};
    pk_rsa_stats st;
    struct rusage ru0, ru;
    getrusage(RUSAGE_SELF, &ru0);
    pk_rsa_place(&b, d, sp, n, &prm, NULL, &p, &st);
    getrusage(RUSAGE_SELF, &ru);
    double rate = (double)st.placed / st.seconds;
    /* the job's gap audit of the same packing (after the placement's clock) */
    pk_gap_report gap = {.min_gap = NAN};
    double audit_s = NAN;
    if (audit) {
        double t0 = pk_wall_seconds();
        if (pk_gap_audit(&b, &p, 0, 1e-12 * L, 0.5, &gap) == 0)
            audit_s = pk_wall_seconds() - t0;
    }
    snprintf(line, size,
             "bench=rsa case=%s n=%zu placed=%zu seconds=%.3f cpu_s=%.3f sys_s=%.3f minflt=%ld "
             "rate=%.0f draws_per_grain=%.3f maxrss_kb=%ld audit_s=%.3f audit_over_place=%.3f "
             "smallest_gap=%.3g",
             name, n, st.placed, st.seconds, cpu_seconds(&ru) - cpu_seconds(&ru0),
             sys_seconds(&ru) - sys_seconds(&ru0), ru.ru_minflt - ru0.ru_minflt, rate,
             (double)st.draws / (double)(st.placed ? st.placed : 1), (long)ru.ru_maxrss, audit_s,
             audit_s / st.seconds, gap.min_gap);
    free(d);
    free(sp);
    pk_particles_free(&p);
    return rate;
}

/* mono_once in a child process: each run maps fresh memory and pays its
 * first touches, as a job's worker does (in one process the heap keeps the
 * pages an earlier run freed: 10^5 grains then ran at ~1.9 M/s instead of
 * ~1.2, with 400 page faults instead of 9 000).  NAN if the child failed. */
static double mono_child(const char *name, int dim, size_t n, double phi, enum path path, int audit,
                         char *line, size_t size)
{
    int fd[2];
    fflush(stdout);
    if (pipe(fd) != 0)
        return NAN;
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return NAN;
    }
    if (pid == 0) {
        close(fd[0]);
        char buf[512];
        double rate = mono_once(name, dim, n, phi, path, audit, buf, sizeof buf);
        FILE *f = fdopen(fd[1], "w");
        if (f) {
            fprintf(f, "%.17g\n%s\n", rate, buf);
            fclose(f);
        }
        _exit(0);
    }
    close(fd[1]);
    double rate = NAN;
    FILE *f = fdopen(fd[0], "r");
    if (f) {
        if (fscanf(f, "%lf\n", &rate) != 1 || !fgets(line, (int)size, f))
            rate = NAN;
        line[strcspn(line, "\n")] = 0;
        fclose(f);
    } else {
        close(fd[0]);
    }
    int status;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? rate : NAN;
}

/* The case run reps times, each in its own process (the same seed: the same
 * packing each time, so the audit runs once): the line of the run with the
 * median rate, with the slowest and fastest rates beside it.  Medians
 * because this VM's speed wanders by tens of percent within minutes
 * (case=machine). */
#define MAX_REPS 15
static double mono(const char *name, int dim, size_t n, double phi, enum path path, int reps)
{
    static char line[MAX_REPS][512];
    double rate[MAX_REPS];
    int order[MAX_REPS];
    reps = reps < 1 ? 1 : (reps > MAX_REPS ? MAX_REPS : reps);
    for (int k = 0; k < reps; k++) {
        line[k][0] = 0;
        rate[k] = mono_child(name, dim, n, phi, path, k == 0, line[k], sizeof line[k]);
        if (!(rate[k] >= 0)) {
            printf("bench=rsa case=%s error=\"run %d failed\"\n", name, k);
            return NAN;
        }
        order[k] = k;
    }
    for (int i = 1; i < reps; i++) /* insertion sort by rate */
        for (int j = i; j > 0 && rate[order[j]] < rate[order[j - 1]]; j--) {
            int t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
    int med = order[reps / 2];
    const char *audit = strstr(line[0], " audit_s=");
    char *own = strstr(line[med], " audit_s=");
    if (med != 0 && audit && own) /* the audit's figures are the first run's */
        snprintf(own, sizeof line[med] - (size_t)(own - line[med]), "%s", audit);
    printf("%s reps=%d rate_min=%.0f rate_max=%.0f\n", line[med], reps, rate[order[0]],
           rate[order[reps - 1]]);
    fflush(stdout);
    return rate[med];
}

/* A job file of bench/jobs/ (`patch` merged into its inputs) run reps times
 * through pk_job_run, each in a child process: the line of the run with the
 * median rate (grains placed per CPU second of the whole job: sizes,
 * placement, audit, file), with the slowest and fastest rates beside it. */
static double job_case(const char *name, const char *job, const char *patch, int reps)
{
    double rate[MAX_REPS];
    bench_job run[MAX_REPS];
    int order[MAX_REPS];
    reps = reps < 1 ? 1 : (reps > MAX_REPS ? MAX_REPS : reps);
    for (int k = 0; k < reps; k++) {
        if (bench_job_run(job, patch, &run[k]) != 0) {
            printf("bench=rsa case=%s job=%s error=\"%s\"\n", name, job, run[k].err);
            for (int i = 0; i < k; i++)
                json_decref(run[i].sum);
            return NAN;
        }
        rate[k] = bench_num(run[k].sum, "count_placed") / run[k].cpu_s;
        order[k] = k;
    }
    for (int i = 1; i < reps; i++) /* insertion sort by rate */
        for (int j = i; j > 0 && rate[order[j]] < rate[order[j - 1]]; j--) {
            int t = order[j];
            order[j] = order[j - 1];
            order[j - 1] = t;
        }
    const bench_job *m = &run[order[reps / 2]];
    json_t *sum = m->sum, *rsa = json_object_get(sum, "rsa");
    double placed = bench_num(sum, "count_placed"), wall = bench_num(sum, "timing/place_s");
    printf("bench=rsa case=%s job=%s n=%.0f placed=%.0f reason=%s phi_mix=%.4f seconds=%.3f "
           "cpu_s=%.3f rate=%.0f rate_wall=%.0f draws_per_grain=%.2f maxrss_kb=%ld "
           "smallest_gap=%.6g smallest_wall_gap=%.6g reps=%d rate_min=%.0f rate_max=%.0f\n",
           name, job, bench_num(sum, "count_requested"), placed,
           json_string_value(json_object_get(sum, "termination_reason")), bench_num(sum, "phi_mix"),
           wall, m->cpu_s, rate[order[reps / 2]], placed / wall, bench_num(rsa, "draws_per_grain"),
           m->maxrss_kb, bench_num(sum, "smallest_gap"),
           json_object_get(sum, "smallest_wall_gap") ? bench_num(sum, "smallest_wall_gap") : NAN,
           reps, rate[order[0]], rate[order[reps - 1]]);
    fflush(stdout);
    double r = rate[order[reps / 2]];
    for (int k = 0; k < reps; k++)
        json_decref(run[k].sum);
    return r;
}

/* The real workloads (bench/jobs/): DIN A16 and B16 with Δd = 1 mm, a Fuller
 * curve q = 0.5 from 0.5 to 16 mm, Meier's quartz sand; the 4·10⁵-grain A16
 * and Titscher's 150 mm specimen with PACKD_BENCH_LARGE=1. */
static void jobs(void)
{
    int large = getenv("PACKD_BENCH_LARGE") && atoi(getenv("PACKD_BENCH_LARGE"));
    double a3 = job_case("a16_dd1_4e3", "a16-dd1-4e3", NULL, 5);
    double a4 = job_case("a16_dd1_4e4", "a16-dd1-4e4", NULL, 3);
    double a5 = large ? job_case("a16_dd1_4e5", "a16-dd1-4e5", NULL, 1) : NAN;
    job_case("a16_dd1_4e3_wall_gap_none", "a16-dd1-4e3", "{\"rsa\":{\"wall_gap\":\"none\"}}", 5);
    double z4 = job_case("a16_dd0_4e4", "a16-dd0-4e4", NULL, 3);
    job_case("b16_dd1_4e3", "b16-dd1-4e3", NULL, 5);
    job_case("b16_dd1_4e4", "b16-dd1-4e4", NULL, 3);
    job_case("fuller_q05_d05to16_dd025", "fuller-q05-d05-16", NULL, 3);
    job_case("meier_quartz_2d_1e5", "meier-quartz-2d-1e5", NULL, 3);
    if (large)
        job_case("titscher150_a16_dmin05_dd05", "titscher150-a16-dmin05", NULL, 1);
    else
        printf("bench=rsa case=a16_dd1_4e5 skipped=set_PACKD_BENCH_LARGE=1\n"
               "bench=rsa case=titscher150_a16_dmin05_dd05 skipped=set_PACKD_BENCH_LARGE=1\n");
    printf("bench=rsa case=a16_scaling rate_ratio_4e4_over_4e3=%.3f rate_ratio_4e5_over_4e3=%.3f "
           "rate_ratio_dd1_over_dd0_4e4=%.3f\n",
           a4 / a3, a5 / a3, a4 / z4);
    fflush(stdout);
}

/* `rsa gap`: RSA with a gap at scale (issue targets: A16 with Δd 1 mm at
 * >= 10^5 grains per CPU second, flat from 10^3 to 10^6 grains; Titscher's
 * 150 mm specimen < 5 CPU s).  a16-dd1-4e3 in cubes of edge 172 mm ·
 * (N / 37 937)^(1/3) (the 172 mm cube holds 37 937 grains), then the
 * specimen; a summary line says which targets hold. */
static void gap(void)
{
    static const struct {
        const char *name;
        double edge_mm;
        int reps;
    } size[] = {{"a16_dd1_1e3", 51, 5},
                {"a16_dd1_1e4", 111, 3},
                {"a16_dd1_1e5", 238, 1},
                {"a16_dd1_1e6", 513, 1}};
    enum { NSIZE = sizeof size / sizeof size[0] };
    double rate[NSIZE], lo = INFINITY;
    for (int k = 0; k < NSIZE; k++) {
        char patch[128];
        snprintf(patch, sizeof patch, "{\"domain\":{\"box\":{\"size\":[%g,%g,%g]}}}",
                 size[k].edge_mm, size[k].edge_mm, size[k].edge_mm);
        rate[k] = job_case(size[k].name, "a16-dd1-4e3", patch, size[k].reps);
        lo = fmin(lo, rate[k]);
    }
    bench_job t;
    double t_cpu = NAN;
    long t_rss = 0;
    if (bench_job_run("titscher150-a16-dmin05", NULL, &t) == 0) {
        t_cpu = t.cpu_s;
        t_rss = t.maxrss_kb;
        printf("bench=rsa case=titscher150_a16_dmin05_dd05 n=%.0f placed=%.0f reason=%s "
               "cpu_s=%.3f maxrss_kb=%ld draws_per_grain=%.2f smallest_gap=%.6g\n",
               bench_num(t.sum, "count_requested"), bench_num(t.sum, "count_placed"),
               json_string_value(json_object_get(t.sum, "termination_reason")), t.cpu_s,
               t.maxrss_kb, bench_num(json_object_get(t.sum, "rsa"), "draws_per_grain"),
               bench_num(t.sum, "smallest_gap"));
        json_decref(t.sum);
    } else {
        printf("bench=rsa case=titscher150_a16_dmin05_dd05 error=\"%s\"\n", t.err);
    }
    printf("bench=rsa case=gap_targets rate_min=%.0f rate_ratio_1e6_over_1e3=%.3f "
           "rate_target=100000 rate_met=%d titscher_cpu_s=%.3f titscher_maxrss_kb=%ld "
           "titscher_target_cpu_s=5 titscher_met=%d\n",
           lo, rate[NSIZE - 1] / rate[0], lo >= 1e5, t_cpu, t_rss, t_cpu < 5);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    printf("bench=rsa case=machine dram_chase_ns=%.1f\n", dram_chase_ns());
    fflush(stdout);
    if (argc > 1 && strcmp(argv[1], "gap") == 0) {
        gap();
        return 0;
    }
    if (argc > 1 && strcmp(argv[1], "mono") == 0) {
        double r4 = mono("mono3d_phi030_1e4", 3, 10000, 0.30, BATCHED, REPS_1E4);
        double r5 = mono("mono3d_phi030_1e5", 3, 100000, 0.30, BATCHED, REPS_1E5);
        double r6 = mono("mono3d_phi030_1e6", 3, 1000000, 0.30, BATCHED, REPS_1E6);
        printf("bench=rsa case=scaling rate_ratio_1e6_over_1e4=%.3f rate_ratio_1e5_over_1e4=%.3f\n",
               r6 / r4, r5 / r4);
        return 0;
    }
    jobs();
    if (argc > 1 && strcmp(argv[1], "jobs") == 0)
        return 0;
    double p4 = mono("mono3d_phi030_1e4_plain", 3, 10000, 0.30, PLAIN, 3);
    double p5 = mono("mono3d_phi030_1e5_plain", 3, 100000, 0.30, PLAIN, 1);
    double v4 = mono("mono3d_phi030_1e4_voxels", 3, 10000, 0.30, VOXELS, 3);
    double v5 = mono("mono3d_phi030_1e5_voxels", 3, 100000, 0.30, VOXELS, 1);
    double b5 = mono("mono3d_phi030_1e5_batch_plain", 3, 100000, 0.30, BATCH_PLAIN, 3);
    double b6 = mono("mono3d_phi030_1e6_batch_plain", 3, 1000000, 0.30, BATCH_PLAIN, 1);
    double r4 = mono("mono3d_phi030_1e4", 3, 10000, 0.30, BATCHED, REPS_1E4);
    double r5 = mono("mono3d_phi030_1e5", 3, 100000, 0.30, BATCHED, REPS_1E5);
    double r6 = mono("mono3d_phi030_1e6", 3, 1000000, 0.30, BATCHED, REPS_1E6);
    printf("bench=rsa case=speedup rate_ratio_batched_over_plain_1e4=%.3f "
           "rate_ratio_batched_over_plain_1e5=%.3f rate_ratio_batched_over_voxels_1e4=%.3f "
           "rate_ratio_batched_over_voxels_1e5=%.3f\n",
           r4 / p4, r5 / p5, r4 / v4, r5 / v5);
    printf("bench=rsa case=region rate_ratio_over_batch_plain_1e5=%.3f "
           "rate_ratio_over_batch_plain_1e6=%.3f\n",
           r5 / b5, r6 / b6);
    printf("bench=rsa case=scaling rate_ratio_1e6_over_1e4=%.3f rate_ratio_1e5_over_1e4=%.3f\n",
           r6 / r4, r5 / r4);
    return 0;
}
