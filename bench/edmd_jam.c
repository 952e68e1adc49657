/* bench/edmd_jam — "until jammed" criteria side by side.  One
 * machine-readable line per case:
 *   bench=edmd_jam case=NAME mode=M n=N phi=F p=P criterion=C events=E
 *         cpu_s=T z=Z rattlers=R tol=TOL certified=yes|no kinetic_ratio=K
 *         growth_changes=G
 * Modes: default (pressure stop at 10^12, rate × 0.1 past p = 10^3), const
 * (pressure stop, one rate), dphi (Meier's Δφ < 10^-9 over N events, one
 * rate), stall (Titscher's stall, 10^-12 over max(1000, N) events, one rate),
 * lift_dphi (the former default: the lift rule and the Δφ stop), meier (Eq. 9,
 * no rescaling, Δφ stop: Meier's protocol), rf<f> (the default with
 * jamming.rate_factor f), grow060 (to φ = 0.60, the yardstick).  z, rattlers,
 * tol: of the certificate (pk_jam_certify: the pressure's tolerance, or the
 * ladder's step at which the backbone was rigid).  Cases: 3D monodisperse
 * N = 10^4 (γ = 0.02) and Fuller-like diameters 1–16 (counts ∝ d^-2.5,
 * γ = 0.03), both from the jobs' RSA start at φ = 0.30; 2D Meier A32 and
 * quartz (nop = 1000, γ = 0.02, zero start).  PACKD_BENCH_CASE=TEXT runs the
 * cases whose "case/mode" contains TEXT; the default modes of the 10^4
 * cases take minutes each.  certified: pk_jam_certify's verdict.
 * PACKD_BENCH_RATIO=MODE (empty: default) runs issue 37's grading instead:
 * the two 10^4 cases jammed in MODE and grown to φ = 0.60 (mode grow060),
 * alternating, PACKD_BENCH_REPS times, one line each:
 *   bench=edmd_jam_ratio case=NAME mode=M n=N jam_cpu_s=T grow060_cpu_s=G
 *         ratio=T/G phi=F z=Z rattlers=R certified=yes|no
 * PACKD_BENCH_N=n (PACKD_BENCH_MODE=m, PACKD_BENCH_RATE=γ, default 0.02): one
 * run of n ≤ 10^4 equal spheres, for protocol trials (docs/perf/edmd.md);
 * PACKD_BENCH_SEED=s its seed (default 1), PACKD_BENCH_STAGES its stages
 * (mode `stages`, run_stages), PACKD_BENCH_DUMP=DIR its packing (dump_packing). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "core/edmd/edmd.h"
#include "core/edmd/edmd_contacts.h"
#include "core/edmd/edmd_rigidity.h"
#include "api/solver/sparse_cholmod.h"
#include "core/rsa/rsa.h"

static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
        (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
}

static int wanted(const char *name, const char *mode)
{
    char nm[128];
    snprintf(nm, sizeof nm, "%s/%s", name, mode);
    const char *f = getenv("PACKD_BENCH_CASE");
    return !f || !*f || strstr(nm, f) != NULL;
}

static void set_mode(pk_edmd_params *prm, const char *mode)
{
    if (strcmp(mode, "default") == 0)
        return;
    if (strncmp(mode, "rf", 2) == 0) { /* rf<factor>: the default with another rate factor */
        prm->jam_rate_factor = atof(mode + 2);
        return;
    }
    if (strcmp(mode, "grow060") == 0) { /* the yardstick: grow to φ = 0.60 */
        prm->until = PK_EDMD_UNTIL_TARGET;
        prm->phi_target = 0.60;
        return;
    }
    prm->jam_rate_factor = 1;
    if (strcmp(mode, "stages") == 0) { /* the first stage: G@P (run_stages) */
        const char *sp = getenv("PACKD_BENCH_STAGES");
        const char *at = sp ? strchr(sp, '@') : NULL;
        if (at) {
            prm->growth_rate = atof(sp);
            prm->p_max = atof(at + 1);
        }
        return;
    }
    if (strcmp(mode, "dphi") == 0 || strcmp(mode, "lift_dphi") == 0 || strcmp(mode, "meier") == 0)
        prm->dphi_crit = 1e-9;
    if (strcmp(mode, "stall") == 0)
        prm->stall_growth = 1e-12;
    if (strcmp(mode, "lift_dphi") == 0)
        prm->rule = PK_EDMD_RULE_LIFT;
    if (strcmp(mode, "meier") == 0) {
        prm->rule = PK_EDMD_RULE_MEIER;
        prm->rescale = 0;
    }
}

/* PACKD_BENCH_DUMP=DIR: the final packing in PackingGeneration's folder
 * layout (generation.conf, packing.xyzd, packing.nfo at scale 1), for
 * bench/anchor_certify's tolerance ladder and the anchor's own tools. */
static void dump_packing(const pk_box *b, const pk_particles *p, double phi)
{
    const char *dir = getenv("PACKD_BENCH_DUMP");
    if (!dir || !*dir || b->dim != 3)
        return;
    char path[1024];
    snprintf(path, sizeof path, "%s/generation.conf", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return;
    fprintf(f,
            "Particles count: %zu\nPacking size: %.17g %.17g %.17g\nGeneration start: 0\n"
            "Seed: 1\nSteps to write: 1000\nBoundaries mode: 1\nContraction rate: 1e-2\n",
            p->n, b->L[0], b->L[1], b->L[2]);
    fclose(f);
    snprintf(path, sizeof path, "%s/packing.nfo", dir);
    if ((f = fopen(path, "w")) != NULL) {
        fprintf(f, "N: %zu\n\n Theoretical Porosity: %.17g\nFinal Porosity: %.17g\n", p->n, 1 - phi,
                1 - phi);
        fclose(f);
    }
    snprintf(path, sizeof path, "%s/packing.xyzd", dir);
    if ((f = fopen(path, "wb")) != NULL) {
        for (size_t i = 0; i < p->n; i++) {
            const double rec[4] = {p->x[3 * i], p->x[3 * i + 1], p->x[3 * i + 2], 2 * p->r[i]};
            fwrite(rec, sizeof rec, 1, f);
        }
        fclose(f);
    }
}

static int cmp_u64(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The pairs of p's contact network at tol appended to keys (i·2^32 + j). */
static int collect_pairs(const pk_box *b, const pk_particles *p, double tol, uint64_t **keys,
                         size_t *nk, size_t *cap)
{
    pk_contact_network net;
    pk_contact_stats cs;
    if (pk_contact_network_compute(b, p, 0, 0, tol, &net, &cs) != 0)
        return -1;
    for (size_t k = 0; k < net.npair; k++) {
        if (*nk == *cap) {
            *cap = *cap ? 2 * *cap : 4096;
            uint64_t *t = realloc(*keys, *cap * sizeof *t);
            if (!t)
                return -1;
            *keys = t;
        }
        (*keys)[(*nk)++] = (uint64_t)net.pi[k] << 32 | (uint32_t)net.pj[k];
    }
    pk_contact_network_free(&net);
    return 0;
}

/* The rigidity test (pk_rigidity_test) of the union of the pairs in keys:
 * every pair that touched at one of the snapshots, its normal taken from the
 * last configuration; rattlers (fewer than dim + 1 contacts) peeled
 * iteratively as pk_contact_network_compute does. */
static int union_certify(const pk_box *b, const pk_particles *p, uint64_t *keys, size_t nk,
                         pk_contact_stats *cs, pk_rigidity *rg)
{
    qsort(keys, nk, sizeof *keys, cmp_u64);
    size_t m = 0;
    for (size_t k = 0; k < nk; k++)
        if (m == 0 || keys[k] != keys[m - 1])
            keys[m++] = keys[k];
    pk_contact_network net = {.npair = m};
    net.pi = malloc(m * sizeof *net.pi);
    net.pj = malloc(m * sizeof *net.pj);
    net.normal = malloc(3 * m * sizeof *net.normal);
    net.rattler = calloc(p->n, 1);
    int32_t *deg = calloc(p->n, sizeof *deg);
    int rc = -1;
    if (!net.pi || !net.pj || !net.normal || !net.rattler || !deg)
        goto out;
    for (size_t k = 0; k < m; k++) {
        const int32_t i = (int32_t)(keys[k] >> 32), j = (int32_t)(keys[k] & 0xffffffffu);
        double d[3] = {0, 0, 0}, len = 0;
        for (int a = 0; a < p->dim; a++) {
            d[a] = p->x[3 * j + a] - p->x[3 * i + a];
            if (b->periodic[a])
                d[a] -= b->L[a] * round(d[a] / b->L[a]);
            len += d[a] * d[a];
        }
        len = sqrt(len);
        for (int a = 0; a < 3; a++)
            net.normal[3 * k + a] = d[a] / len;
        net.pi[k] = i;
        net.pj[k] = j;
        deg[i]++;
        deg[j]++;
    }
    for (int changed = 1; changed;) { /* peel the rattlers */
        changed = 0;
        for (size_t i = 0; i < p->n; i++)
            if (!net.rattler[i] && deg[i] < p->dim + 1) {
                net.rattler[i] = 1;
                changed = 1;
                for (size_t k = 0; k < m; k++)
                    if ((size_t)net.pi[k] == i || (size_t)net.pj[k] == i)
                        deg[(size_t)net.pi[k] == i ? net.pj[k] : net.pi[k]]--;
            }
    }
    *cs = (pk_contact_stats){.contacts = m};
    for (size_t i = 0; i < p->n; i++)
        cs->rattlers += net.rattler[i];
    cs->backbone = p->n - cs->rattlers;
    cs->rattler_fraction = (double)cs->rattlers / (double)p->n;
    for (size_t k = 0; k < m; k++)
        cs->backbone_contacts += !net.rattler[net.pi[k]] && !net.rattler[net.pj[k]];
    cs->mean_contacts =
        cs->backbone ? 2.0 * (double)cs->backbone_contacts / (double)cs->backbone : 0;
    rc = pk_rigidity_test(b, p, &net, cs, &pk_sparse_cholmod, rg);
out:
    free(deg);
    free(net.pi);
    free(net.pj);
    free(net.normal);
    free(net.rattler);
    return rc;
}

/* PACKD_BENCH_STAGES: the protocol after the first stage (grown at γ with
 * rate factor 1 to p_max = the first entry's pressure), stage by stage from
 * the grains where the last one left them (new velocities, δ = 1 − 10^-13):
 *   G@P  grow at rate G (rate factor 1) until the reduced pressure P;
 *   hold@K  no growth (γ = 10^-12) for K·N events: the pressure relaxes to
 *           that of the packing's basin at its φ.
 * One line per stage to stderr (φ, p, events, CPU s so far). */
static void run_stages(const pk_box *b, pk_particles *p, pk_edmd_params *prm0, pk_edmd_stats *st)
{
    const char *spec = getenv("PACKD_BENCH_STAGES");
    char buf[512];
    snprintf(buf, sizeof buf, "%s", spec ? spec : "");
    uint64_t events = st->events;
    char *save = NULL;
    int first = 1;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (first) { /* the first stage ran already (set_mode) */
            first = 0;
            continue;
        }
        pk_edmd_params prm = *prm0;
        prm.start_zero = 0;
        prm.delta = 1 - 1e-13; /* < 1 (set_rates); 10^-13 is below every gap at p ≤ 10^12 */
        prm.jam_rate_factor = 1;
        prm.seed = prm0->seed + events;
        const char *at = strchr(tok, '@');
        if (!at)
            break;
        if (strncmp(tok, "net", 3) == 0) { /* net@K: K holds of N events, the union network */
            const int K = atoi(at + 1);
            const double tol = pk_contact_tolerance(b->dim, st->pressure);
            uint64_t *keys = NULL;
            size_t nk = 0, cap = 0;
            prm.growth_rate = 1e-12;
            prm.p_max = INFINITY;
            prm.stall_growth = 0;
            prm.max_events = p->n;
            int ok = collect_pairs(b, p, tol, &keys, &nk, &cap) == 0;
            for (int k = 0; k < K && ok; k++) {
                prm.seed++;
                pk_edmd_run(b, p, &prm, NULL, st);
                events += st->events;
                ok = collect_pairs(b, p, tol, &keys, &nk, &cap) == 0;
            }
            pk_contact_stats cs;
            pk_rigidity rg;
            if (ok && union_certify(b, p, keys, nk, &cs, &rg) == 0)
                fprintf(stderr,
                        "stage %s: union of %d snapshots at tol %.2g: contacts=%zu backbone=%zu "
                        "backbone_contacts=%zu maxwell_min=%zu z=%.3f rattlers=%.4f floppy=%zu "
                        "rigid=%s p=%.3g\n",
                        tok, K + 1, tol, cs.contacts, cs.backbone, cs.backbone_contacts,
                        rg.maxwell_min, cs.mean_contacts, cs.rattler_fraction, rg.floppy,
                        rg.rigid ? "yes" : "no", st->pressure);
            free(keys);
            continue;
        }
        if (strncmp(tok, "hold", 4) == 0) {
            prm.growth_rate = 1e-12;
            prm.p_max = INFINITY;
            prm.stall_growth = 0;
            prm.max_events = (uint64_t)(atof(at + 1) * (double)p->n);
        } else {
            prm.growth_rate = atof(tok);
            prm.p_max = atof(at + 1);
        }
        pk_edmd_run(b, p, &prm, NULL, st);
        events += st->events;
        fprintf(stderr, "stage %s: phi=%.6f p=%.3g events=%llu cpu_s=%.2f\n", tok, st->phi,
                st->pressure, (unsigned long long)events, cpu_s());
    }
    st->events = events;
}

/* radii r (n) in a periodic box filled to φ = 0.5 at those radii; from an
 * RSA start at φ = rsa_phi (> 0) or from zero radii */
typedef struct result {
    double cpu, phi, z, rattlers;
    int certified;
} result;

static result run(const char *name, const char *mode, int dim, const double *r, size_t n,
                  double rate, double rsa_phi)
{
    result res = {0};
    if (!wanted(name, mode))
        return res;
    double vol = 0;
    for (size_t i = 0; i < n; i++)
        vol += pk_ball_measure(dim, r[i]);
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = dim;
    for (int k = 0; k < dim; k++) {
        b.L[k] = pow(vol / 0.5, 1.0 / dim);
        b.periodic[k] = true;
    }
    pk_particles p;
    pk_particles_init(&p, dim, n);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.growth_rate = rate;
    prm.until = PK_EDMD_UNTIL_JAMMED;
    const char *seed = getenv("PACKD_BENCH_SEED"); /* start and velocities (default 1) */
    if (seed && *seed)
        prm.seed = strtoull(seed, NULL, 10);
    set_mode(&prm, mode);
    double c0 = cpu_s();
    if (rsa_phi > 0) {
        double *d = malloc(n * sizeof *d);
        int32_t *sp = calloc(n, sizeof *sp);
        for (size_t i = 0; i < n; i++)
            d[i] = 2 * r[i];
        pk_rsa_stats rs;
        prm.start_zero = 0;
        prm.delta = pk_edmd_start_delta(dim, d, n, 0, pk_box_measure(&b), rsa_phi);
        pk_edmd_start_rsa(&b, d, sp, n, prm.delta, 0, prm.seed, NULL, &p, &rs);
        free(d);
        free(sp);
    } else {
        double x[3] = {0, 0, 0};
        for (size_t i = 0; i < n; i++)
            pk_particles_push(&p, x, r[i], 0);
    }
    pk_edmd_stats st;
    pk_edmd_run(&b, &p, &prm, NULL, &st);
    if (strcmp(mode, "stages") == 0)
        run_stages(&b, &p, &prm, &st);
    dump_packing(&b, &p, st.phi);
    double tol = pk_contact_tolerance(dim, st.pressure);
    pk_contact_stats cs = {0};
    pk_rigidity rg = {0};
    if (prm.until == PK_EDMD_UNTIL_JAMMED)
        pk_jam_certify(&b, &p, 0, 0, tol, &pk_sparse_cholmod, &cs, &rg, &tol);
    res = (result){.cpu = cpu_s() - c0, /* the certificate included */
                   .phi = st.phi,
                   .z = cs.mean_contacts,
                   .rattlers = cs.rattler_fraction,
                   .certified = rg.rigid};
    printf(
        "bench=edmd_jam case=%s mode=%s n=%zu phi=%.5f p=%.3g criterion=%s events=%llu cpu_s=%.2f "
        "z=%.3f rattlers=%.4f tol=%.2g certified=%s kinetic_ratio=%.3g growth_changes=%llu\n",
        name, mode, n, st.phi, st.pressure, pk_edmd_criterion_name(st.criterion),
        (unsigned long long)st.events, res.cpu, cs.mean_contacts, cs.rattler_fraction, tol,
        res.certified ? "yes" : "no", st.kinetic_ratio, (unsigned long long)st.growth_changes);
    fflush(stdout);
    pk_particles_free(&p);
    return res;
}

/* The median of x[0..n) (sorted in place). */
static double median(double *x, int n)
{
    for (int a = 1; a < n; a++)
        for (int c = a; c > 0 && x[c] < x[c - 1]; c--) {
            const double t = x[c];
            x[c] = x[c - 1];
            x[c - 1] = t;
        }
    return x[n / 2];
}

/* Issue 37's grading without the anchor: the jam's CPU time over the time
 * of growing the same grains to φ = 0.60, alternating the two (a loaded
 * machine), each `reps` times; one line with the medians' ratio. */
static void ratio(const char *name, const char *mode, const double *r, size_t n, double rate,
                  int reps)
{
    if (!wanted(name, mode))
        return;
    double jam[8] = {0}, grow[8] = {0};
    result last = {0};
    reps = reps > 8 ? 8 : reps < 1 ? 1 : reps;
    for (int k = 0; k < reps; k++) {
        grow[k] = run(name, "grow060", 3, r, n, rate, 0.30).cpu;
        last = run(name, mode, 3, r, n, rate, 0.30);
        jam[k] = last.cpu;
    }
    const double j = median(jam, reps), g = median(grow, reps);
    printf("bench=edmd_jam_ratio case=%s mode=%s n=%zu jam_cpu_s=%.2f grow060_cpu_s=%.2f "
           "ratio=%.1f phi=%.5f z=%.3f rattlers=%.4f certified=%s\n",
           name, mode, n, j, g, j / g, last.phi, last.z, last.rattlers,
           last.certified ? "yes" : "no");
    fflush(stdout);
}

/* Meier 2007 Tables I/II column IV: counts per class of nop = 1000 */
static size_t meier_radii(const double *d, const int *count, int classes, double *r)
{
    size_t n = 0;
    for (int c = 0; c < classes; c++)
        for (int k = 0; k < count[c]; k++)
            r[n++] = 0.5 * d[c];
    return n;
}

int main(void)
{
    static const char *modes[] = {"default", "const", "dphi", "stall", "lift_dphi", "meier"};
    enum { N = 10000 };
    static double r[N], rf[N];
    for (size_t i = 0; i < N; i++)
        r[i] = 0.5;
    const double a = 1.5, lo = 1, hi = pow(16, -a);
    for (size_t i = 0; i < N; i++) {
        double u = ((double)i + 0.5) / (double)N;
        rf[N - 1 - i] = 0.5 * pow(lo - u * (lo - hi), -1 / a);
    }
    const char *nn = getenv("PACKD_BENCH_N"); /* equal spheres, N given: protocol trials */
    if (nn) {
        const size_t n = (size_t)atol(nn);
        const char *m = getenv("PACKD_BENCH_MODE");
        const char *g = getenv("PACKD_BENCH_RATE");
        run("mono3d", m ? m : "default", 3, r, n < N ? n : N, g ? atof(g) : 0.02, 0.30);
        return 0;
    }
    const char *rmode = getenv("PACKD_BENCH_RATIO"); /* issue 37's two cases only */
    if (rmode) {
        const char *reps = getenv("PACKD_BENCH_REPS");
        const int k = reps ? atoi(reps) : 1;
        ratio("mono3d_1e4_rate0.02", *rmode ? rmode : "default", r, N, 0.02, k);
        ratio("fuller3d_d1to16_1e4_rate0.03", *rmode ? rmode : "default", rf, N, 0.03, k);
        return 0;
    }
    for (int m = 0; m < 5; m++)
        run("mono3d_1e4_rate0.02", modes[m], 3, r, N, 0.02, 0.30);
    for (int m = 0; m < 5; m++)
        run("fuller3d_d1to16_1e4_rate0.03", modes[m], 3, rf, N, 0.03, 0.30);
    static const double a32_d[] = {16, 8, 4, 2, 1};
    static const int a32_n[] = {8, 21, 53, 127, 791};
    static const double qz_d[] = {0.25, 0.16, 0.125, 0.1, 0.063, 0.05};
    static const int qz_n[] = {6, 242, 441, 149, 145, 17};
    size_t na = meier_radii(a32_d, a32_n, 5, r);
    for (int m = 0; m < 6; m++)
        if (m != 3)
            run("meier_a32_2d_rate0.02", modes[m], 2, r, na, 0.02, 0);
    size_t nq = meier_radii(qz_d, qz_n, 6, r);
    for (int m = 0; m < 6; m++)
        if (m != 3)
            run("meier_quartz_2d_rate0.02", modes[m], 2, r, nq, 0.02, 0);
    return 0;
}
