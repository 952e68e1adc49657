/* test_edmd_rules.c — the pair collision rules (pk_edmd_rule): one
 * collision against its closed form, and whole runs under Meier's Eq. (9)
 * against the default rule. */
#include <math.h>
#include <string.h>

#include "check.h"
#include "edmd_fixture.h"
#include "core/edmd/edmd_state.h"
#include "core/space/gap_audit.h"

/* Two touching unit-mass grains on the x axis (i at 0, j at 1, n = +x),
 * v_i = (0.3, 0.2), v_j = (−0.1, 0.5), radius rates g_i = 0.01, g_j = 0.03:
 * returns σ·J and the velocities after one collision under rule. */
static double collide_once(pk_edmd_rule rule, double vi[3], double vj[3])
{
    edmd_state S;
    memset(&S, 0, sizeof S);
    edmd_kin k[2];
    memset(k, 0, sizeof k);
    double m[2] = {1, 1};
    S.k = k;
    S.m = m;
    S.n = 2;
    S.dim = 2;
    S.rule = rule;
    S.eps_v = 1e-12;
    k[0].a = k[1].a = 0.5;
    k[1].p[0] = 1;
    k[0].v[0] = 0.3, k[0].v[1] = 0.2, k[0].g = 0.01;
    k[1].v[0] = -0.1, k[1].v[1] = 0.5, k[1].g = 0.03;
    const double sj = edmd_collide_pair(&S, 0, 1);
    memcpy(vi, k[0].v, sizeof k[0].v);
    memcpy(vj, k[1].v, sizeof k[1].v);
    /* the bookkeeping of K matches the velocities */
    const double K0 = 0.5 * (0.09 + 0.04 + 0.01 + 0.25);
    const double K1 = 0.5 * (vi[0] * vi[0] + vi[1] * vi[1] + vj[0] * vj[0] + vj[1] * vj[1]);
    CHECK_NEAR(S.K, K1 - K0, 1e-15);
    return sj;
}

/* Meier Eq. (9): v_ni' = min(v_ni, v_nj) − g_i = −0.11, v_nj' = max + g_j
 * = 0.33: the pair gains g_i + g_j = 0.04 on the swap; tangential speeds
 * kept; J = ½(|Δv_ni| + |Δv_nj|) = ½(0.41 + 0.43). */
static void test_meier_eq9(void)
{
    double vi[3], vj[3];
    const double sj = collide_once(PK_EDMD_RULE_MEIER, vi, vj);
    CHECK_NEAR(vi[0], -0.11, 1e-15);
    CHECK_NEAR(vj[0], 0.33, 1e-15);
    CHECK(vi[1] == 0.2 && vj[1] == 0.5);
    CHECK_NEAR(sj, 0.42, 1e-15);
}

/* Default: the gap rate w − G reversed, w' = 2G − w (+ε_v) = 0.48, with the
 * momentum kept (v_ni + v_nj = 0.2); the lift rule needs no push here
 * (w' = −w = 0.4, the elastic swap). */
static void test_elastic_and_lift(void)
{
    double vi[3], vj[3];
    collide_once(PK_EDMD_RULE_ELASTIC, vi, vj);
    CHECK_NEAR(vj[0] - vi[0], 0.48, 2e-12); /* + ε_v */
    CHECK_NEAR(vi[0] + vj[0], 0.2, 1e-15);
    collide_once(PK_EDMD_RULE_LIFT, vi, vj);
    CHECK_NEAR(vi[0], -0.1, 1e-15);
    CHECK_NEAR(vj[0], 0.3, 1e-15);
}

/* 2D, 200 disks (every 4th of diameter 1.4) from zero radii at γ = 0.05 to
 * the Δφ stop (Meier's protocol): Meier's rule with and without rescaling,
 * and the default rule; no overlap, and each changes the run (rescale once
 * changed nothing: 0 rescales either way). */
static pk_edmd_stats meier_run(pk_edmd_rule rule, int rescale)
{
    pk_particles p;
    pk_particles_init(&p, 2, 200);
    double x[3] = {0, 0, 0};
    for (int i = 0; i < 200; i++)
        pk_particles_push(&p, x, i % 4 ? 0.5 : 0.7, 0);
    pk_box b = edmd_fixture_periodic_box(&p, 0.5);
    pk_edmd_params prm;
    pk_edmd_params_default(&prm);
    prm.until = PK_EDMD_UNTIL_JAMMED;
    prm.growth_rate = 0.05;
    prm.dphi_crit = 1e-9;
    prm.jam_rate_factor = 1;
    prm.rule = rule;
    prm.rescale = rescale;
    pk_edmd_stats st;
    CHECK(pk_edmd_run(&b, &p, &prm, NULL, &st) == 0);
    CHECK(st.reason == PK_STOP_JAMMED && st.overlaps == 0);
    pk_gap_report rep;
    CHECK(pk_gap_audit(&b, &p, 0, 1e-9, 0.7 * 2, &rep) == 0);
    CHECK(rep.pairs_below == 0);
    printf("  rule %d rescale %d: phi=%.5f p=%.3g (%s) events=%llu rescales=%llu K/K0=%.3g\n",
           (int)rule, rescale, st.phi, st.pressure, pk_edmd_criterion_name(st.criterion),
           (unsigned long long)st.events, (unsigned long long)st.rescales, st.kinetic_ratio);
    pk_particles_free(&p);
    return st;
}

static void test_meier_runs(void)
{
    pk_edmd_stats mf = meier_run(PK_EDMD_RULE_MEIER, 0);
    pk_edmd_stats mt = meier_run(PK_EDMD_RULE_MEIER, 1);
    pk_edmd_stats el = meier_run(PK_EDMD_RULE_ELASTIC, 1);
    CHECK(mf.rescales == 0 && mf.kinetic_ratio > 1.1); /* the gain of energy Meier notes */
    CHECK(mt.rescales > 0);
    CHECK(mf.events != mt.events && mt.events != el.events);
    /* all jam in the 2D bidisperse band */
    CHECK(mf.phi > 0.82 && mt.phi > 0.82 && el.phi > 0.82);
}

int main(void)
{
    RUN(test_meier_eq9);
    RUN(test_elastic_and_lift);
    RUN(test_meier_runs);
    return check_summary();
}
