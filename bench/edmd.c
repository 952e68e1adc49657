/* bench/edmd — EDMD growth packing.  One machine-readable line per case:
 *   bench=edmd case=NAME n=N phi=F reason=R criterion=C events=E collisions=C
 *         seconds=S cpu_s=T collisions_per_cpu_s=X events_per_cpu_s=Y peak_rss_mb=M p=P
 *         runner_up=K (invalid events replaced by their runner-up, no prediction)
 *         nlist=L (list rebuilds) invalid=I (partner changed course; runner_up of
 *         them took no prediction) wall=W (events = collisions + nlist + invalid
 *         + wall + others)
 * (job cases: rates per wall second of the placement, cpu_s of the whole job)
 * Cases: monodisperse 3D periodic N = 10^4 to φ = 0.60 and to jamming,
 * N = 2000 slow/fast (the MRJ band and the rate dependence), Fuller-like
 * 3D diameters 1–16 (counts ∝ d^-2.5) N = 10^4 to jamming — both from zero
 * radii (Meier) and, …_rsa030, from an RSA start at φ = 0.30 (Titscher/Kansal;
 * the jobs' default start, δ by
 * pk_edmd_start_delta: the dilute phase, where list rebuilds outnumber
 * collisions, is skipped; its RSA time counts), with the monodisperse
 * cases from the same start beside them for the ratio — Meier's 2D
 * quartz and A32 (nop = 1000) to jamming over 3 seeds; N = 10^5 to φ = 0.55
 * from zero radii and from an RSA start at φ = 0.30 (…_rsa030).  The N = 10^6
 * cases (to φ = 0.55, both starts) take minutes: opt in with PACKD_BENCH_LARGE=1.  peak_rss_mb is the
 * process peak so far (getrusage), so it is monotone over the cases.
 * PACKD_BENCH_N=n (PACKD_BENCH_PHI=φ) runs only equal spheres to φ (one_n).
 * PACKD_BENCH_CASE=TEXT runs only the cases whose name contains TEXT (one
 * case under valgrind --tool=callgrind: instructions per collision).
 * Titscher's walled A16 (Δd = 1 mm at φ_M = 53.5 %, both wall rules, through
 * packd's job path) is bench/edmd_titscher.
 * The run leads with the real workloads, job files of bench/jobs/ run
 * through pk_job_run in a child process each (case=job_…: collisions per CPU
 * second of the whole job, the job's own maxrss_kb) and their ratio to the
 * monodisperse job in the same box. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "core/edmd/edmd.h"
#include "api/process.h"
#include "core/rsa/rsa.h"
#include "bench/jobs/bench_job.h"

/* Case filter: PACKD_BENCH_CASE=TEXT keeps the cases whose name contains it. */
static int wanted(const char *name)
{
    const char *f = getenv("PACKD_BENCH_CASE");
    return !f || !*f || strstr(name, f) != NULL;
}

static double peak_mb(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_maxrss / 1024.0;
}

/* CPU seconds of this process: on the shared 2-core machine wall time
 * measures the neighbours' load, CPU time measures the code. */
static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
        (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static void line(const char *name, size_t n, const pk_edmd_stats *st, double cpu)
{
    printf("bench=edmd case=%s n=%zu phi=%.5f reason=%s criterion=%s events=%llu collisions=%llu "
           "seconds=%.3f cpu_s=%.3f collisions_per_cpu_s=%.3g events_per_cpu_s=%.3g "
           "peak_rss_mb=%.1f p=%.3g runner_up=%llu nlist=%llu invalid=%llu wall=%llu\n",
           name, n, st->phi, pk_stop_reason_name(st->reason), pk_edmd_criterion_name(st->criterion),
           (unsigned long long)st->events, (unsigned long long)st->pair, st->seconds, cpu,
           (double)st->pair / cpu, (double)st->events / cpu, peak_mb(), st->pressure,
           (unsigned long long)st->second, (unsigned long long)st->nlist,
           (unsigned long long)st->invalid, (unsigned long long)st->wall);
    fflush(stdout);
}

/* radii r[i] in a periodic cube filled to phi0 at those radii; from zero
 * radii (Meier), or with rsa_phi > 0 from an RSA configuration at δ·d with
 * δ^dim = rsa_phi/phi0 (Titscher §6.2, Kansal), whose CPU time counts */
static void run_core(const char *name, int dim, const double *r, size_t n, double phi0, double rate,
                     int jammed, double phi_target, double rsa_phi, pk_edmd_stats *st)
{
    double vol = 0;
    for (size_t i = 0; i < n; i++)
        vol += pk_ball_measure(dim, r[i]);
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = dim;
    for (int k = 0; k < dim; k++) {
        b.L[k] = pow(vol / phi0, 1.0 / dim);
        b.periodic[k] = true;
    }
    pk_particles p;
    pk_particles_init(&p, dim, n);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.growth_rate = rate;
    prm.until = jammed ? PK_EDMD_UNTIL_JAMMED : PK_EDMD_UNTIL_TARGET;
    prm.phi_target = phi_target;
    if (jammed) { /* the speed series: Meier's Δφ stop at one rate (the
                   * pressure stop at 10^12: bench/edmd_jam) */
        prm.dphi_crit = 1e-9;
        prm.jam_rate_factor = 1;
    }
    double c0 = cpu_s();
    if (rsa_phi > 0) {
        double *d = malloc(n * sizeof *d);
        int32_t *sp = calloc(n, sizeof *sp);
        for (size_t i = 0; i < n; i++)
            d[i] = 2 * r[i];
        pk_rsa_stats rs;
        prm.start_zero = 0;
        /* the job's default start (api/pack/pack_place_edmd.c) at rsa_phi */
        prm.delta = pk_edmd_start_delta(dim, d, n, 0, pk_box_measure(&b), rsa_phi);
        pk_edmd_start_rsa(&b, d, sp, n, prm.delta, 0, prm.seed, NULL, &p, &rs);
        free(d);
        free(sp);
    } else {
        double x[3] = {0, 0, 0};
        for (size_t i = 0; i < n; i++)
            pk_particles_push(&p, x, r[i], 0);
    }
    double c1 = cpu_s();
    pk_edmd_run(&b, &p, &prm, NULL, st);
    double c2 = cpu_s();
    line(name, n, st, c2 - c0);
    if (rsa_phi > 0) /* the engine alone, without the RSA start */
        printf("bench=edmd case=%s edmd_cpu_s=%.3f collisions_per_edmd_cpu_s=%.3g\n", name, c2 - c1,
               (double)st->pair / (c2 - c1));
    fflush(stdout);
    pk_particles_free(&p);
}

static double mono_from(const char *name, size_t n, double rate, int jammed, double phi_target,
                        double rsa_phi)
{
    if (!wanted(name))
        return NAN;
    double *r = malloc(n * sizeof *r);
    for (size_t i = 0; i < n; i++)
        r[i] = 0.5;
    pk_edmd_stats st;
    run_core(name, 3, r, n, jammed ? 0.5 : phi_target, rate, jammed, phi_target, rsa_phi, &st);
    free(r);
    return st.phi;
}

static double mono(const char *name, size_t n, double rate, int jammed, double phi_target)
{
    return mono_from(name, n, rate, jammed, phi_target, 0);
}

/* Fuller-like: diameters 1..16, number density ∝ d^-2.5 (inverse CDF). */
static void fuller(const char *name, size_t n, double rate, double rsa_phi)
{
    if (!wanted(name))
        return;
    double *r = malloc(n * sizeof *r);
    double a = 1.5; /* ∫ d^-2.5 → CDF ∝ 1 − d^-1.5 */
    double lo = 1, hi = pow(16, -a);
    for (size_t i = 0; i < n; i++) {
        double u = ((double)i + 0.5) / (double)n;
        double d = pow(lo - u * (lo - hi), -1 / a);
        r[n - 1 - i] = 0.5 * d; /* descending */
    }
    pk_edmd_stats st;
    run_core(name, 3, r, n, 0.5, rate, 1, 0, rsa_phi, &st);
    free(r);
}

static void job_case(const char *name, const char *json)
{
    json_error_t e;
    json_t *job = json_loads(json, 0, &e);
    if (!job) {
        printf("bench=edmd case=%s error=\"%s\"\n", name, e.text);
        return;
    }
    pk_schema_errors errs = {0};
    json_t *sum = NULL;
    char err[512];
    const char *out = "/tmp/packd-bench-edmd.h5";
    double c0 = cpu_s();
    int rc = pk_job_run(job, NULL, out, &sum, &errs, err, sizeof err);
    double cpu = cpu_s() - c0;
    if (rc == 0) {
        json_t *o = json_object_get(sum, "edmd");
        double s = bench_num(sum, "timing/place_s");
        double coll = (double)json_integer_value(json_object_get(o, "events_pair"));
        double ev = (double)json_integer_value(json_object_get(o, "events"));
        printf("bench=edmd case=%s n=%lld phi=%.5f phi_mix=%.5f reason=%s criterion=%s events=%.0f "
               "collisions=%.0f seconds=%.3f cpu_s=%.3f collisions_per_s=%.3g events_per_s=%.3g "
               "peak_rss_mb=%.1f delta_d=%.4g p=%.3g\n",
               name, (long long)json_integer_value(json_object_get(sum, "count_placed")),
               json_real_value(json_object_get(sum, "phi_resolved")),
               json_real_value(json_object_get(sum, "phi_mix")),
               json_string_value(json_object_get(sum, "termination_reason")),
               json_string_value(json_object_get(o, "termination_criterion")), ev, coll, s, cpu,
               coll / s, ev / s, peak_mb(), json_real_value(json_object_get(o, "delta_d_reached")),
               json_real_value(json_object_get(o, "reduced_pressure")));
    } else {
        printf("bench=edmd case=%s error=\"%s\" cpu_s=%.3f\n", name, err, cpu);
    }
    fflush(stdout);
    remove(out);
    json_decref(sum);
    json_decref(job);
    pk_schema_errors_free(&errs);
}

static const char *QUARTZ =
    "{\"type\":\"classes\",\"classes\":[{\"d\":0.25,\"volume_percent\":2.5},{\"d\":0.16,"
    "\"volume_percent\":39.72},{\"d\":0.125,\"volume_percent\":44.22},{\"d\":0.1,\"volume_"
    "percent\":"
    "9.58},{\"d\":0.063,\"volume_percent\":3.7},{\"d\":0.05,\"volume_percent\":0.28}]}";
static const char *A32 = "{\"type\":\"classes\",\"classes\":[{\"d\":16,\"volume_percent\":38},{"
                         "\"d\":8,\"volume_percent\":"
                         "24},{\"d\":4,\"volume_percent\":15},{\"d\":2,\"volume_percent\":9},{"
                         "\"d\":1,\"volume_percent\":"
                         "14}]}";

static void meier(const char *name, const char *grading, double L, int seed)
{
    char job[2048], nm[64];
    snprintf(job, sizeof job,
             "{\"process\":\"pack\",\"inputs\":{\"dim\":2,\"domain\":{\"box\":{\"size\":[%g,%g],"
             "\"periodic\":true}},\"grading\":%s,\"sampling\":\"discrete\",\"count\":1000,"
             "\"phi\":{\"value\":0.45,\"refers_to\":\"resolved\"},\"algorithm\":\"edmd\","
             "\"edmd\":{\"start\":\"zero\",\"until\":\"jammed\",\"masses\":\"equal\","
             "\"growth_rate\":0.01},\"seed\":%d}}",
             L, L, grading, seed);
    snprintf(nm, sizeof nm, "%s_seed%d", name, seed);
    if (wanted(nm))
        job_case(nm, job);
}

/* A job file of bench/jobs/ with `patch` merged into its inputs, run
 * through pk_job_run in a child process (bench/jobs/bench_job.h): its
 * collisions per CPU second of the whole job (RSA start, EDMD, audit, file)
 * and the job's own peak memory.  NAN on failure. */
static double file_case(const char *name, const char *job, const char *patch)
{
    if (!wanted(name))
        return NAN;
    bench_job r;
    if (bench_job_run(job, patch, &r) != 0) {
        printf("bench=edmd case=%s job=%s error=\"%s\"\n", name, job, r.err);
        fflush(stdout);
        return NAN;
    }
    json_t *o = json_object_get(r.sum, "edmd");
    double coll = bench_num(o, "events_pair"), ev = bench_num(o, "events");
    printf("bench=edmd case=%s job=%s n=%.0f phi=%.5f phi_mix=%.5f reason=%s events=%.0f "
           "collisions=%.0f seconds=%.3f cpu_s=%.3f collisions_per_cpu_s=%.3g "
           "events_per_cpu_s=%.3g maxrss_kb=%ld\n",
           name, job, bench_num(r.sum, "count_placed"), bench_num(r.sum, "phi_resolved"),
           bench_num(r.sum, "phi_mix"),
           json_string_value(json_object_get(r.sum, "termination_reason")), ev, coll,
           bench_num(r.sum, "timing/place_s"), r.cpu_s, coll / r.cpu_s, ev / r.cpu_s, r.maxrss_kb);
    fflush(stdout);
    json_decref(r.sum);
    return coll / r.cpu_s;
}

/* The real workloads first: Titscher's walled A16 (Δd = 1 mm) grown past
 * RSA's reach (φ_M 0.40 → 0.50, default RSA start), B16 likewise, the
 * Fuller curve 0.5–16 (Δd 0.25) and Meier's sand at 10⁵ grains, beside the
 * monodisperse job in the same box for the ratio. */
static void jobs(void)
{
    const char *to50 = "{\"algorithm\":\"edmd\",\"phi\":{\"value\":0.50}}";
    double a = file_case("job_a16_dd1_4e3_phiM050", "a16-dd1-4e3", to50);
    file_case("job_b16_dd1_4e3_phiM050", "b16-dd1-4e3", to50);
    file_case("job_fuller_q05_d05to16_dd025_phiM050", "fuller-q05-d05-16", to50);
    file_case("job_meier_quartz_2d_1e5_phi060", "meier-quartz-2d-1e5",
              "{\"algorithm\":\"edmd\",\"phi\":{\"value\":0.60}}");
    double m = file_case("job_mono_d5_4e3_phi055", "mono-d5-4e3", NULL);
    if (!isnan(a) && !isnan(m))
        printf("bench=edmd case=job_a16_over_mono collision_rate_ratio=%.3f\n", a / m);
    fflush(stdout);
}

/* PACKD_BENCH_N=n (PACKD_BENCH_PHI=φ, default 0.60): only equal spheres,
 * n of them, grown to φ from the RSA start at φ = 0.30 (the rate against N:
 * 10^4, 10^5, 10^6). */
static int one_n(void)
{
    const char *nn = getenv("PACKD_BENCH_N"), *ph = getenv("PACKD_BENCH_PHI");
    if (!nn || !*nn)
        return 0;
    const size_t n = (size_t)strtod(nn, NULL);
    const double phi = ph && *ph ? atof(ph) : 0.60;
    char name[64];
    snprintf(name, sizeof name, "mono3d_%zu_to_phi%03.0f_rsa030", n, 100 * phi);
    mono_from(name, n, 0.1, 0, phi, 0.30);
    return 1;
}

int main(void)
{
    if (one_n())
        return 0;
    jobs();
    mono("mono3d_1e3_to_phi060", 1000, 0.1, 0, 0.60);
    mono("mono3d_1e4_to_phi060", 10000, 0.1, 0, 0.60);
    mono_from("mono3d_1e4_to_phi060_rsa030", 10000, 0.1, 0, 0.60, 0.30);
    mono("mono3d_1e4_jam_rate0.02", 10000, 0.02, 1, 0);
    double slow = mono("mono3d_2000_jam_rate0.01", 2000, 0.01, 1, 0);
    double fast = mono("mono3d_2000_jam_rate0.1", 2000, 0.1, 1, 0);
    if (!isnan(slow) && !isnan(fast))
        printf("bench=edmd case=mono3d_2000_check band_0.634_0.652=%s faster_is_looser=%s\n",
               slow >= 0.634 && slow <= 0.652 ? "yes" : "no", fast < slow ? "yes" : "no");
    fuller("fuller3d_d1to16_1e4_jam", 10000, 0.01, 0);
    fuller("fuller3d_d1to16_1e4_jam_rsa030", 10000, 0.01, 0.30);
    mono_from("mono3d_1e4_jam_rate0.02_rsa030", 10000, 0.02, 1, 0, 0.30);
    for (int s = 1; s <= 3; s++)
        meier("meier_quartz_2d_jam", QUARTZ, 3.0, s);
    for (int s = 1; s <= 3; s++)
        meier("meier_a32_2d_jam", A32, 100.0, s);
    /* From zero radii (Meier) and from an RSA start at φ = 0.30 (below RSA's
     * saturation 0.384): the same growth rate, and the
     * same reduced pressure at φ = 0.55 within the spread of single runs
     * (N = 2·10⁴: p = 25.3 from zero, 25.4/26.6/24.9 from RSA at 0.2/0.3/0.4),
     * for half the events: the dilute flights from zero radii cost a list
     * rebuild every ~3 events. */
    mono("mono3d_1e5_to_phi055", 100000, 0.1, 0, 0.55);
    mono_from("mono3d_1e5_to_phi055_rsa030", 100000, 0.1, 0, 0.55, 0.30);
    if (getenv("PACKD_BENCH_LARGE") && atoi(getenv("PACKD_BENCH_LARGE"))) {
        mono("mono3d_1e6_to_phi055", 1000000, 0.1, 0, 0.55);
        mono_from("mono3d_1e6_to_phi055_rsa030", 1000000, 0.1, 0, 0.55, 0.30);
    } else if (wanted("mono3d_1e6_to_phi055")) {
        printf("bench=edmd case=mono3d_1e6_to_phi055 skipped=set_PACKD_BENCH_LARGE=1\n");
    }
    return 0;
}
