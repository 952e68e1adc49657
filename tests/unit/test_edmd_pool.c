/* test_edmd_pool.c — the pooled neighbour lists (core/edmd/edmd_nlist.c: one
 * block of slots, lists moving to its end when they outgrow their slot, the
 * pool regrown and compacted in grain order) and the Z-order numbering of
 * the start (core/edmd/edmd_order.c) over a long run: N = 4096 grains to jamming
 * (~2·10^6 events, the pool regrown a dozen times).  Sized for the unit
 * suite: 2D, rate 0.02, ~1.5 s CPU plain. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "edmd_fixture.h"
#include "core/edmd/edmd.h"
#include "core/space/gap_audit.h"

#define N 4096

/* 2D bidisperse (2:1 by count), size ratio 1.4, periodic, jammed from zero radii;
 * grain i has radius r0[i] before and k·r0[i] after (relative growth). */
static void test_pooled_lists_keep_grains_and_gaps(void)
{
    pk_particles p;
    CHECK(pk_particles_init(&p, 2, N) == 0);
    double x[3] = {0, 0, 0}, r0[N];
    for (int i = 0; i < N; i++) {
        /* radii in an order that is no spatial order: a mix-up of the
         * engine's numbering (perm) would give grains the wrong size */
        r0[i] = (i * 7919) % 3 ? 0.5 : 0.7;
        pk_particles_push(&p, x, r0[i], 0);
    }
    pk_box b = edmd_fixture_periodic_box(&p, 0.5);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = 0.02;
    prm.equal_masses = 1;
    prm.seed = 5;
    /* the cheap Δφ stop (Meier Eq. 11) at one rate: this test is about the
     * engine's bookkeeping, not the jamming criterion (test_edmd_jam) */
    prm.dphi_crit = 1e-9;
    prm.jam_rate_factor = 1;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    printf("  n=%d phi=%.5f p=%.3g (%s) events=%llu\n", N, st.phi, st.pressure,
           pk_edmd_criterion_name(st.criterion), (unsigned long long)st.events);
    CHECK(st.reason == PK_STOP_JAMMED);
    CHECK(st.overlaps == 0);
    /* every grain keeps its own size: r/r0 is one growth factor for all
     * (1e-12 relative: one product a + g·t per grain, no accumulation) */
    const double k = p.r[0] / r0[0];
    double worst = 0;
    for (int i = 0; i < N; i++)
        worst = fmax(worst, fabs(p.r[i] / r0[i] - k) / k);
    CHECK_MSG(worst < 1e-12, "radius ratio spread %g", worst);
    /* independent sort-and-sweep audit; 1e-9 relative is the bar */
    pk_gap_report rep;
    CHECK(pk_gap_audit(&b, &p, 0, 1e-9 * 2 * k * 0.5, k * 0.7, &rep) == 0);
    CHECK_MSG(rep.pairs_below == 0, "%zu overlapping pairs, min gap %g", rep.pairs_below,
              rep.min_gap);
    /* jammed 2D bidisperse (ratio 1.4): ≈ 0.84 (issue 3; test_edmd_jam
     * holds the ±0.01 band at rate 0.01); lists that lost neighbours would
     * overlap or jam far off it, so ±0.02 for one seed, a 2:1 mix and the
     * faster rate */
    CHECK_MSG(st.phi > 0.82 && st.phi < 0.86, "phi=%.4f", st.phi);
    pk_particles_free(&p);
}

int main(void)
{
    RUN(test_pooled_lists_keep_grains_and_gaps);
    return check_summary();
}
