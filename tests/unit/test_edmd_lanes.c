/* test_edmd_lanes.c — the vector neighbour loops of core/edmd/edmd_predict.c (AVX2
 * four lanes, AVX-512 eight lanes) give the scalar loop's events bit for
 * bit: the same run through each path ends with identical counts and
 * positions.  Polydisperse 3D (lists of every length, so full and short last
 * groups of four and of eight lanes) and 2D (zero third components), from
 * zero radii to jamming (touching lanes after every collision).  A one-ulp
 * change of one lane's root fails it, in either vector loop (checked by
 * mutation).  A path the CPU lacks is a SKIP, not a pass. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "core/edmd/edmd.h"
#include "edmd_fixture.h"
#include "core/edmd/edmd_state.h"

typedef struct outcome {
    pk_edmd_stats st;
    pk_particles p;
} outcome;

typedef enum path { PATH_SCALAR, PATH_LANES4, PATH_LANES8 } path;

/* n grains, diameters 1..ratio (every 5th the coarse one), periodic box at
 * φ = 0.5 for the target sizes, grown from zero until jammed, through the
 * neighbour loop `via`. */
static void run(int dim, int n, double ratio, path via, outcome *o)
{
    pk_particles_init(&o->p, dim, (size_t)n);
    double x[3] = {0, 0, 0};
    for (int i = 0; i < n; i++)
        pk_particles_push(&o->p, x, 0.5 * (i % 5 == 0 ? ratio : 1 + (ratio - 1) * 0.1 * (i % 3)),
                          0);
    pk_box b = edmd_fixture_periodic_box(&o->p, 0.5);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = 0.05;
    prm.seed = 7;
    /* the cheap Δφ stop (Meier Eq. 11) at one rate: this test is about the
     * engine's bookkeeping, not the jamming criterion (test_edmd_jam) */
    prm.dphi_crit = 1e-9;
    prm.jam_rate_factor = 1;
    edmd_scalar_only = via == PATH_SCALAR;
    edmd_lanes4_only = via == PATH_LANES4;
    CHECK(pk_edmd_run(&b, &o->p, &prm, NULL, &o->st) == 0);
    edmd_scalar_only = 0;
    edmd_lanes4_only = 0;
}

static void same(const outcome *v, const outcome *s)
{
    CHECK(v->st.events > 10000); /* long enough for the trajectories to diverge at any difference */
    CHECK(v->st.events == s->st.events);
    CHECK(v->st.pair == s->st.pair);
    CHECK(v->st.nlist == s->st.nlist);
    CHECK(v->st.invalid == s->st.invalid);
    /* bit-identical: chaotic dynamics would amplify a one-ulp difference */
    CHECK(memcmp(v->p.x, s->p.x, 3 * v->p.n * sizeof *v->p.x) == 0);
    CHECK(memcmp(v->p.r, s->p.r, v->p.n * sizeof *v->p.r) == 0);
}

/* The scalar run of each case, computed once for both vector paths. */
static outcome scalar[2];
static int scalar_done[2];

static void same_run(int dim, int n, double ratio, path via)
{
    outcome *s = &scalar[dim - 2], v;
    if (!scalar_done[dim - 2]) {
        run(dim, n, ratio, PATH_SCALAR, s);
        scalar_done[dim - 2] = 1;
        printf("  dim=%d n=%d ratio=%g: events=%llu collisions=%llu phi=%.6f\n", dim, n, ratio,
               (unsigned long long)s->st.events, (unsigned long long)s->st.pair, s->st.phi);
    }
    run(dim, n, ratio, via, &v);
    same(&v, s);
    pk_particles_free(&v.p);
}

static void test_lanes4_match_scalar_3d(void) { same_run(3, 600, 4.0, PATH_LANES4); }
static void test_lanes8_match_scalar_3d(void) { same_run(3, 600, 4.0, PATH_LANES8); }
static void test_lanes4_match_scalar_2d(void) { same_run(2, 400, 3.0, PATH_LANES4); }
static void test_lanes8_match_scalar_2d(void) { same_run(2, 400, 3.0, PATH_LANES8); }

int main(void)
{
    const char *no4 = "this CPU has no AVX2: the 4-lane loop cannot run";
    const char *no8 = "this CPU has no AVX-512F: the 8-lane loop cannot run";
    if (edmd_lanes_available()) {
        RUN(test_lanes4_match_scalar_3d);
        RUN(test_lanes4_match_scalar_2d);
    } else {
        SKIP(test_lanes4_match_scalar_3d, "%s", no4);
        SKIP(test_lanes4_match_scalar_2d, "%s", no4);
    }
    if (edmd_lanes8_available()) {
        RUN(test_lanes8_match_scalar_3d);
        RUN(test_lanes8_match_scalar_2d);
    } else {
        SKIP(test_lanes8_match_scalar_3d, "%s", no8);
        SKIP(test_lanes8_match_scalar_2d, "%s", no8);
    }
    for (int d = 0; d < 2; d++)
        if (scalar_done[d])
            pk_particles_free(&scalar[d].p);
    return check_summary();
}
