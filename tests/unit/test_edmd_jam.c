/* test_edmd_jam.c — EDMD jamming densities (issue 3 validation, sized for
 * the unit suite: ~4 s plain, well under a minute under ASan).  The
 * full-size cases (3D N = 2000 and 10^4, Meier's 2D examples, Titscher's
 * A16) are in bench/edmd.c. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "edmd_fixture.h"
#include "edmd.h"
#include "gap_audit.h"

static void check_no_overlap(const pk_box *b, const pk_particles *p)
{
    double rmax = 0, rmin = INFINITY;
    for (size_t i = 0; i < p->n; i++) {
        rmax = fmax(rmax, p->r[i]);
        rmin = fmin(rmin, p->r[i]);
    }
    pk_gap_report rep;
    /* independent sort-and-sweep audit; 1e-9 relative is the bar */
    CHECK(pk_gap_audit(b, p, 0, 1e-9 * 2 * rmin, rmax, &rep) == 0);
    CHECK_MSG(rep.pairs_below == 0, "%zu overlapping pairs, min gap %g", rep.pairs_below,
              rep.min_gap);
}

/* n grains, every other one of radius 0.5·ratio, periodic box at φ = 0.5
 * for the start sizes; grown by relative growth from zero until jammed. */
static double jam(int dim, int n, double ratio, double rate, uint64_t seed)
{
    pk_particles p;
    pk_particles_init(&p, dim, (size_t)n);
    double x[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        pk_particles_push(&p, x, i % 2 ? 0.5 * ratio : 0.5, 0);
    pk_box b = edmd_fixture_periodic_box(&p, 0.5);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = rate;
    prm.equal_masses = 1;
    prm.seed = seed;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    CHECK(st.reason == PK_STOP_JAMMED);
    CHECK(st.overlaps == 0);
    check_no_overlap(&b, &p);
    printf("  dim=%d n=%d ratio=%g rate=%g seed=%llu: phi=%.5f p=%.3g (%s) events=%llu\n", dim, n,
           ratio, rate, (unsigned long long)seed, st.phi, st.pressure,
           pk_edmd_criterion_name(st.criterion), (unsigned long long)st.events);
    pk_particles_free(&p);
    return st.phi;
}

/* 2D bidisperse 50:50, size ratio 1.4: φ_J ≈ 0.84 (O'Hern et al.; issue:
 * ±0.01).  N = 500 (not the literature's larger N): seed-to-seed spread
 * measured 0.8435–0.8469 over seeds and code revisions, so ±0.01 holds
 * with margin. */
static void test_bidisperse_2d(void)
{
    for (uint64_t seed = 1; seed <= 2; seed++) {
        double phi = jam(2, 500, 1.4, 0.01, seed);
        CHECK_NEAR(phi, 0.84, 0.01);
    }
}

/* 3D monodisperse periodic, slow growth: MRJ band [0.634, 0.652] (issue,
 * for N = 2000 — bench/edmd.c runs that size).  N = 500 here to keep the
 * unit suite fast: measured 0.6420–0.6456 over seeds, inside the band;
 * the band is kept as is (a finite-size shift of N = 500 is < 0.003). */
static void test_monodisperse_3d_band_and_rate(void)
{
    double slow = jam(3, 500, 1.0, 0.01, 1);
    CHECK(slow >= 0.634 && slow <= 0.652);
    /* faster growth quenches earlier: measured 0.615–0.619 at γ = 0.1;
     * require a clear drop (0.01, ~5× the seed spread) */
    double fast = jam(3, 500, 1.0, 0.1, 1);
    CHECK_MSG(fast < slow - 0.01, "fast %g vs slow %g", fast, slow);
}

int main(void)
{
    RUN(test_bidisperse_2d);
    RUN(test_monodisperse_3d_band_and_rate);
    return check_summary();
}
