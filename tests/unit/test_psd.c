/* test_psd.c — grading curve → particle sizes (core/psd/psd.c).
 * Reference numbers: Titscher & Unger §2–3 (Eqs. 1–13), Meier, Kuhl & Steinmann
 * Eqs. 12–13, DIN 1045-2. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "core/psd/psd.h"
#include "core/base/rng.h"

#define PI 3.14159265358979323846

static double gmeas(int dim, double d) { return dim == 2 ? PI / 4 * d * d : PI / 6 * d * d * d; }

/* ∫_a^b d^(s−1) dd by composite Simpson in t = ln d (integrand e^(s t)).
 * Independent of the library's closed forms; with 4000 panels the relative
 * error is < 1e-12 for the ranges used here (ln b/a <= 7, |s| <= 6). */
static double simpson_pow(double s, double a, double b)
{
    const int n = 4000;
    double t0 = log(a), h = (log(b) - t0) / n, sum = 0;
    for (int k = 0; k <= n; k++) {
        double w = (k == 0 || k == n) ? 1 : (k % 2 ? 4 : 2);
        sum += w * exp(s * (t0 + k * h));
    }
    return sum * h / 3;
}

static pk_size_class mkclass(double lo, double hi, double beta)
{
    pk_size_class c = {lo, hi, lo, 1.0, beta};
    return c;
}

static int contains(const char *hay, const char *needle) { return strstr(hay, needle) != NULL; }

/* ---------------------------------------------------------------- test 1 */

/* Eq. (10) limits and the spec's worked value; CDF/inverse round trip;
 * number CDF against Eq. (8) and against quadrature for the general law. */
static void test_inverse_transform(void)
{
    pk_size_class c = mkclass(2, 4, 0);
    /* Exact endpoints: the sampler clamps and the formulas are exact at 0, 1. */
    CHECK(pk_class_sample(&c, 3, 0.0) == 2.0);
    CHECK(pk_class_sample(&c, 3, 1.0) == 4.0);
    /* 8/36^(1/3) = 2.42283…; 1e-12 relative = a few ulp of expm1/log1p/exp. */
    CHECK_NEAR(pk_class_sample(&c, 3, 0.5), 8.0 / cbrt(36.0), 1e-12);
    CHECK_NEAR(pk_class_sample(&c, 3, 0.5), 2.4228, 5e-5); /* spec's 4 decimals */
    /* Eq. (10) and Eq. (8) verbatim on a grid of U and d (tolerance: ulp level). */
    for (int k = 0; k <= 20; k++) {
        double u = k / 20.0, a = 2, b = 4;
        double eq10 = a * b / cbrt(b * b * b * (1 - u) + a * a * a * u);
        CHECK_NEAR(pk_class_sample(&c, 3, u), eq10, 1e-12 * eq10);
        double d = a + (b - a) * k / 20.0;
        double eq8 =
            b * b * b * a * a * a / (b * b * b - a * a * a) * (1 / (a * a * a) - 1 / (d * d * d));
        CHECK_NEAR(pk_class_number_cdf(&c, 3, d), eq8, 1e-13);
    }
    /* General law, dims 2/3, β = 0 / 0.35 / 0.7, ratios 2 … 1000: the number
     * CDF equals ∫ d^(β−dim−1) normalised (quadrature, 1e-10 abs), and the
     * sampler inverts it (|F(F⁻¹(u)) − u| <= 1e-12). */
    const double bounds[][2] = {{2, 4}, {2, 16}, {0.016, 16}, {0.25, 0.5}};
    const double betas[] = {0, 0.35, 0.7};
    for (int ib = 0; ib < 4; ib++)
        for (int ibe = 0; ibe < 3; ibe++)
            for (int dim = 2; dim <= 3; dim++) {
                pk_size_class k = mkclass(bounds[ib][0], bounds[ib][1], betas[ibe]);
                double s = betas[ibe] - dim, tot = simpson_pow(s, k.d_lo, k.d_hi);
                for (int j = 1; j < 10; j++) {
                    double d = k.d_lo * pow(k.d_hi / k.d_lo, j / 10.0);
                    CHECK_NEAR(pk_class_number_cdf(&k, dim, d), simpson_pow(s, k.d_lo, d) / tot,
                               1e-10);
                    double u = j / 10.0;
                    CHECK_NEAR(pk_class_number_cdf(&k, dim, pk_class_sample(&k, dim, u)), u, 1e-12);
                }
                /* extreme tails keep relative precision */
                double dt = pk_class_sample(&k, dim, 1.0 - 0x1p-40);
                CHECK(dt < k.d_hi && dt > k.d_lo);
                CHECK(pk_class_sample(&k, dim, 0x1p-40) > k.d_lo);
            }
    /* Discrete class: a step, every sample is d. */
    pk_size_class dc = mkclass(3, 3, 0);
    CHECK(pk_class_sample(&dc, 2, 0.3) == 3.0);
    CHECK(pk_class_number_cdf(&dc, 2, 2.9) == 0.0 && pk_class_number_cdf(&dc, 2, 3.0) == 1.0);
    /* Log-linear mass CDF (Eq. 2) through pk_grading_passing: at the geometric
     * midpoint of A16's 2–4 class the passing is the mean of 21 % and 36 %. */
    pk_grading g;
    CHECK(pk_grading_preset(&g, "A16") == 0);
    CHECK_NEAR(pk_grading_passing(&g, sqrt(8.0)), 0.285, 1e-12);
}

/* ---------------------------------------------------------------- test 2 */

static const double quartz_d[7] = {0.315, 0.250, 0.160, 0.125, 0.100, 0.063, 0.050};
static const double quartz_v[7] = {0.00, 2.50, 39.72, 44.22, 9.58, 3.70, 0.28};
static const double a32_d[6] = {32, 16, 8, 4, 2, 1};
static const double a32_v[6] = {0, 38, 24, 15, 9, 14};

/* Meier Tables I/II: particle % printed with 4 decimals → tolerance half a
 * unit of the last digit (5e-5 %, i.e. 5e-7 as a fraction); counts exact. */
static void test_meier_tables(void)
{
    pk_grading g;
    double sh[8];
    size_t cnt[8];
    const double t1_pct[7] = {0, 0.6227, 24.1531, 44.0557, 14.9131, 14.5119, 1.7435};
    const size_t t1_cnt[7] = {0, 6, 242, 441, 149, 145, 17};
    CHECK(pk_grading_from_classes(&g, quartz_d, quartz_v, NULL, 7) == 0);
    CHECK(g.nclass == 7 && g.cls[0].d_rep == 0.315 && g.cls[6].d_rep == 0.05);
    pk_discrete_number_shares(&g, 2, sh);
    pk_discrete_counts(&g, 2, 1000, cnt);
    for (int i = 0; i < 7; i++) {
        CHECK_NEAR(100 * sh[i], t1_pct[i], 5e-5);
        CHECK_MSG(cnt[i] == t1_cnt[i], "Table I row %d: %zu != %zu", i, cnt[i], t1_cnt[i]);
    }
    CHECK(pk_discrete_nop_min(&g, 2) == 161);

    const double t2_pct[6] = {0, 0.8381, 2.1173, 5.2933, 12.7040, 79.0472};
    const size_t t2_cnt[6] = {0, 8, 21, 53, 127, 791};
    CHECK(pk_grading_from_classes(&g, a32_d, a32_v, NULL, 6) == 0);
    pk_discrete_number_shares(&g, 2, sh);
    pk_discrete_counts(&g, 2, 1000, cnt);
    for (int i = 0; i < 6; i++) {
        CHECK_NEAR(100 * sh[i], t2_pct[i], 5e-5);
        CHECK_MSG(cnt[i] == t2_cnt[i], "Table II row %d: %zu != %zu", i, cnt[i], t2_cnt[i]);
    }
    CHECK(pk_discrete_nop_min(&g, 2) == 120);
    /* nop_min really gives every class with mass at least one grain. */
    pk_discrete_counts(&g, 2, 120, cnt);
    for (int i = 1; i < 6; i++)
        CHECK(cnt[i] >= 1);

    /* 3D shares (d³ weighting), same 4-decimal tolerance. */
    const double a32_3d[6] = {0, 0.0602, 0.3041, 1.5204, 7.2978, 90.8175};
    pk_discrete_number_shares(&g, 3, sh);
    for (int i = 0; i < 6; i++)
        CHECK_NEAR(100 * sh[i], a32_3d[i], 5e-5);
    CHECK(pk_discrete_nop_min(&g, 3) == 1662);
    const double q_3d[7] = {0, 0.2707, 16.4040, 38.2992, 16.2057, 25.0312, 3.7892};
    CHECK(pk_grading_from_classes(&g, quartz_d, quartz_v, NULL, 7) == 0);
    pk_discrete_number_shares(&g, 3, sh);
    for (int i = 0; i < 7; i++)
        CHECK_NEAR(100 * sh[i], q_3d[i], 5e-5);
    CHECK(pk_discrete_nop_min(&g, 3) == 370);

    /* Realised discrete set: Table I counts, sorted descending, species = row. */
    pk_sizes s;
    CHECK(pk_sample_discrete(&g, 2, 1000, &s) == 0);
    CHECK(s.n == 1000);
    for (size_t k = 1; k < s.n; k++)
        CHECK(s.d[k] <= s.d[k - 1]);
    CHECK(s.d[0] == 0.25 && s.species[0] == 1 && s.d[999] == 0.05 && s.species[999] == 6);
    size_t n16 = 0;
    for (size_t k = 0; k < s.n; k++)
        n16 += s.species[k] == 2;
    CHECK(n16 == 242);
    pk_sizes_free(&s);

    /* Mass shares with densities: volume ∝ share/density.  Equal densities
     * change nothing; doubling one density halves that class's volume. */
    const double rho1[7] = {2.65, 2.65, 2.65, 2.65, 2.65, 2.65, 2.65};
    pk_grading g2;
    CHECK(pk_grading_from_classes(&g2, quartz_d, quartz_v, rho1, 7) == 0);
    for (int i = 0; i < 7; i++)
        CHECK_NEAR(g2.cls[i].mass_fraction, g.cls[i].mass_fraction, 1e-15);
    const double dd[2] = {1, 2}, ms[2] = {1, 1}, rho2[2] = {2, 1};
    CHECK(pk_grading_from_classes(&g2, dd, ms, rho2, 2) == 0);
    CHECK_NEAR(g2.cls[0].mass_fraction, 2.0 / 3, 1e-15); /* d = 2, ρ = 1 */
}

/* ---------------------------------------------------------------- test 3 */

/* DIN 1045-2 presets: k-values (exact two-decimal published numbers; the
 * D-sum is a sum of exact percentages → 1e-9), and Titscher's counts.  Counts
 * to ±1 (the published values are rounded integers), φ_eff to half a unit of
 * the printed last digit. */
static void test_din(void)
{
    const char *names[9] = {"A8", "B8", "C8", "A16", "B16", "C16", "A32", "B32", "C32"};
    const double kval[9] = {3.63, 2.90, 2.27, 4.60, 3.66, 2.75, 5.48, 4.20, 3.30};
    const double sieves9[9] = {0.25, 0.5, 1, 2, 4, 8, 16, 31.5, 63};
    pk_grading g;
    for (int p = 0; p < 9; p++) {
        CHECK(pk_grading_preset(&g, names[p]) == 0);
        double dsum = 0;
        for (int k = 0; k < 9; k++)
            dsum += 100 * pk_grading_passing(&g, sieves9[k]);
        CHECK_NEAR((900 - dsum) / 100, kval[p], 1e-9);
    }
    CHECK(pk_grading_preset(&g, "a16") == 0); /* case-insensitive */

    const double V150 = 150.0 * 150 * 150, V80 = 80.0 * 80 * 80;
    const struct {
        const char *name;
        double dmin, phiM, V, N, phieff, phitol;
    } cases[] = {
        {"A16", 2, 0.70, V150, 44202, 0.553, 5e-4},
        {"B16", 2, 0.70, V150, 40049, 0.406, 5e-4},
        {"A16", 0.5, 0.70, V150, 822630, 0.644, 5e-4},
        {"B16", 0.5, 0.70, V150, 2052570, 0.560, 5e-4},
        {"A16", 1, 0.70, V150, 215076, 0.616, 5e-4},
        {"B16", 1, 0.70, V150, 229909, 0.476, 5e-4},
        {"A16", 4, 0.70, V150, 8603, 0.448, 5e-4},
        {"B16", 4, 0.70, V150, 6823, 0.308, 5e-4},
        {"A16", 2, 0.535, V80, 5125, 0.4227, 5e-5},
        {"A16", 2, 0.48, V80, 4598, 0.379, 5e-4},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        CHECK(pk_grading_preset(&g, cases[i].name) == 0);
        CHECK(pk_grading_truncate(&g, cases[i].dmin) == 0);
        double n = pk_grading_expected_count(&g, 3, cases[i].phiM * cases[i].V, NULL);
        CHECK_MSG(fabs(n - cases[i].N) <= 1, "%s d_min %g: E[N] = %.2f, spec %.0f", cases[i].name,
                  cases[i].dmin, n, cases[i].N);
        CHECK_NEAR(cases[i].phiM * (1 - g.mass_below), cases[i].phieff, cases[i].phitol);
    }
    /* The per-class closed form of Titscher & Unger Eq. 6 (3D, β = 0) written out. */
    CHECK(pk_grading_preset(&g, "A16") == 0);
    CHECK(pk_grading_truncate(&g, 2) == 0);
    double cnt[PK_PSD_MAX_CLASSES], tot = 0;
    double n = pk_grading_expected_count(&g, 3, 0.7 * V150, cnt);
    for (int i = 0; i < g.nclass; i++) {
        double a = g.cls[i].d_lo, b = g.cls[i].d_hi, Vi = 0.7 * V150 * g.cls[i].mass_fraction;
        double ni = 2 * Vi / PI * (pow(a, -3) - pow(b, -3)) / log(b / a);
        CHECK_NEAR(cnt[i], ni, 1e-9 * ni);
        tot += cnt[i];
    }
    CHECK_NEAR(n, tot, 1e-9 * n);
}

/* ---------------------------------------------------------------- test 4 */

static double eq13(double phiV, double q, double dmax, double dmin)
{
    return phiV * 6 * q / (PI * pow(dmax, q) * (3 - q)) * (pow(dmin, q - 3) - pow(dmax, q - 3));
}

/* Fuller: one exact class reproduces the corrected Eq. (13) to round-off
 * (1e-10 relative) and the spec's rounded numbers to ±1. */
static void test_fuller(void)
{
    const double V150 = 150.0 * 150 * 150;
    const double dmins[4] = {0.5, 1, 2, 4};
    const double q[2] = {0.7, 0.35};
    const double N[2][4] = {{970685, 196843, 39704, 7795}, {1417223, 225670, 35831, 5586}};
    /* φ_eff = 0.7·(1 − (d_min/16)^q).  Spec §1.6 prints 0.600 for q = 0.7,
     * d_min = 1; the exact value is 0.59949 → 0.599 (a rounding slip in the
     * spec), so 0.599 is checked here. */
    const double pe[2][4] = {{0.638, 0.599, 0.537, 0.435}, {0.492, 0.435, 0.362, 0.269}};
    pk_grading g, h;
    for (int iq = 0; iq < 2; iq++)
        for (int k = 0; k < 4; k++) {
            CHECK(pk_grading_from_fuller(&g, q[iq], 16, dmins[k]) == 0);
            double n = pk_grading_expected_count(&g, 3, 0.7 * V150, NULL);
            CHECK_NEAR(n, eq13(0.7 * V150, q[iq], 16, dmins[k]), 1e-10 * n);
            CHECK_MSG(fabs(n - N[iq][k]) <= 1, "q %g d_min %g: %.2f vs %.0f", q[iq], dmins[k], n,
                      N[iq][k]);
            CHECK_NEAR(0.7 * (1 - g.mass_below), pe[iq][k], 5e-4);
            /* Same result via a finer Fuller curve truncated at d_min. */
            CHECK(pk_grading_from_fuller(&h, q[iq], 16, 0.1) == 0);
            CHECK(pk_grading_truncate(&h, dmins[k]) == 0);
            CHECK_NEAR(pk_grading_expected_count(&h, 3, 0.7 * V150, NULL), n, 1e-10 * n);
            CHECK_NEAR(h.mass_below, g.mass_below, 1e-14);
        }
    /* [T] §6.2: q = 0.5, d 2…16, prescribed φ_eff: φ_M = φ_eff/(1 − (2/16)^0.5). */
    CHECK(pk_grading_from_fuller(&g, 0.5, 16, 2) == 0);
    const double phe[5] = {0.55, 0.60, 0.65, 0.665, 0.70};
    const double n80[5] = {7313, 7978, 8643, 8842, 9307};
    for (int k = 0; k < 5; k++) {
        double n = pk_grading_expected_count(&g, 3, phe[k] * 512000.0 / (1 - g.mass_below), NULL);
        CHECK_MSG(fabs(n - n80[k]) <= 1, "a=80 phi_eff %g: %.2f vs %.0f", phe[k], n, n80[k]);
    }
    /* a = 32: "468 … 596" for φ_eff 0.55 … 0.70. */
    CHECK(fabs(pk_grading_expected_count(&g, 3, 0.55 * 32768.0 / (1 - g.mass_below), NULL) - 468) <=
          1);
    CHECK(fabs(pk_grading_expected_count(&g, 3, 0.70 * 32768.0 / (1 - g.mass_below), NULL) - 596) <=
          1);
    /* passing = Fuller's P(d) exactly (relative round-off). */
    for (double d = 2; d <= 16; d *= 1.3)
        CHECK_NEAR(pk_grading_passing(&g, d), sqrt(d / 16), 1e-14);
}

/* ---------------------------------------------------------------- test 5 */

/* Moments of the grain measure v = c·d^dim under a class's number pdf, by
 * quadrature (independent of psd.c). */
static void class_moments(const pk_size_class *c, int dim, double *mu, double *var)
{
    double s = c->beta - dim, z = simpson_pow(s, c->d_lo, c->d_hi);
    double cc = gmeas(dim, 1.0);
    double m1 = cc * simpson_pow(s + dim, c->d_lo, c->d_hi) / z;
    double m2 = cc * cc * simpson_pow(s + 2 * dim, c->d_lo, c->d_hi) / z;
    *mu = m1;
    *var = m2 - m1 * m1;
}

#define NSEED 32

/* Algorithm 1 (cumulative targets, coarse → fine) against the expectation.
 *  - Mean count over NSEED seeds within 4 standard errors of E[N]; the SD of
 *    N is the renewal result Var N ≈ Σ_i M_i σ_i²/μ_i³ (M_i class measure,
 *    μ_i, σ_i² mean/variance of one grain's measure).  The O(1) renewal bias
 *    (overshoot, ≈ (1 + σ²/μ²)/2 ≈ 1–6 grains) is far below 4 SE (≈ 20–50
 *    grains here).  The sample SD must agree with the theory within
 *    [0.55, 1.5]: for 31 dof the 99.9 % band of s/σ is [0.60, 1.43]
 *    (Wilson–Hilferty), widened a little because Var N above is asymptotic.
 *  - Achieved measure: 0 <= M − target < one grain of the finest class
 *    (the last grain drawn is the only overshoot) – exact, no statistics.
 *  - Class measures: with cumulative targets the cumulative overshoot after
 *    class i lies in [0, v_max,i), so class i's measure misses its share by
 *    less than one grain of class i (excess) or of class i−1 (deficit) –
 *    exact bound, checked for every seed.
 *  - In-class mass distribution: sampled mass passing at the geometric class
 *    midpoints vs the curve within 4 SE (sample SD over seeds). */
static void run_sampling_case(const char *label, pk_grading *g, double resolved, double expect_N)
{
    const int dim = 3;
    double en = pk_grading_expected_count(g, dim, resolved / (1 - g->mass_below), NULL);
    CHECK_NEAR(en, expect_N, 1.0); /* same numbers as tests 3/4 */
    double msum = 0, var_th = 0, vmax[PK_PSD_MAX_CLASSES];
    for (int i = 0; i < g->nclass; i++)
        msum += g->cls[i].mass_fraction;
    for (int i = 0; i < g->nclass; i++) {
        double mu, var, Mi = resolved * g->cls[i].mass_fraction / msum;
        class_moments(&g->cls[i], dim, &mu, &var);
        var_th += Mi * var / (mu * mu * mu);
        vmax[i] = gmeas(dim, g->cls[i].d_hi);
    }
    double sd_th = sqrt(var_th);
    double mids[PK_PSD_MAX_CLASSES];
    int nm = g->nclass;
    for (int i = 0; i < nm; i++)
        mids[i] = sqrt(g->cls[i].d_lo * g->cls[i].d_hi);
    double sN = 0, sN2 = 0, sF[PK_PSD_MAX_CLASSES] = {0}, sF2[PK_PSD_MAX_CLASSES] = {0};
    double maxshare = 0, maxover = 0;
    for (int seed = 1; seed <= NSEED; seed++) {
        pk_rng r;
        pk_rng_seed(&r, (uint64_t)seed, 0);
        pk_sizes s;
        CHECK(pk_sample_by_measure(g, dim, resolved, &r, 10000000, &s) == 0);
        double N = (double)s.n;
        sN += N;
        sN2 += N * N;
        double M = pk_sizes_measure(&s, dim), cm[PK_PSD_MAX_CLASSES] = {0};
        size_t cn[PK_PSD_MAX_CLASSES] = {0};
        double below[PK_PSD_MAX_CLASSES] = {0};
        for (size_t k = 0; k < s.n; k++) {
            int sp = s.species[k];
            CHECK(sp >= 0 && sp < g->nclass);
            CHECK(s.d[k] >= g->cls[sp].d_lo && s.d[k] <= g->cls[sp].d_hi);
            if (k)
                CHECK(s.d[k] <= s.d[k - 1]);
            double v = gmeas(dim, s.d[k]);
            cm[sp] += v;
            cn[sp]++;
            for (int j = 0; j < nm; j++)
                if (s.d[k] < mids[j])
                    below[j] += v;
        }
        int last = g->nclass - 1;
        CHECK(M >= resolved && M - resolved < vmax[last]);
        maxover = fmax(maxover, (M - resolved) / vmax[last]);
        double tgt = 0, act = 0;
        for (int i = 0; i < g->nclass; i++) {
            double ti = resolved * g->cls[i].mass_fraction / msum;
            tgt += ti;
            act += cm[i];
            CHECK(cn[i] > 0);
            double lo = i ? -vmax[i - 1] : 0;
            CHECK_MSG(cm[i] - ti > lo - 1e-9 * resolved && cm[i] - ti < vmax[i] + 1e-9 * resolved,
                      "%s class %d: sampled %.6g target %.6g", label, i, cm[i], ti);
            maxshare = fmax(maxshare, fabs(cm[i] / M - g->cls[i].mass_fraction / msum));
        }
        for (int j = 0; j < nm; j++) {
            double F = below[j] / M;
            sF[j] += F;
            sF2[j] += F * F;
        }
        pk_sizes_free(&s);
    }
    double mean = sN / NSEED, sd = sqrt((sN2 - NSEED * mean * mean) / (NSEED - 1));
    CHECK_MSG(fabs(mean - en) < 4 * sd_th / sqrt(NSEED), "%s: mean %.1f E %.1f sd_th %.1f", label,
              mean, en, sd_th);
    CHECK(fabs(mean - en) < 4 * sd / sqrt(NSEED) + 1.0);
    CHECK_MSG(sd > 0.55 * sd_th && sd < 1.5 * sd_th, "%s: sd %.1f theory %.1f", label, sd, sd_th);
    double Fmax_dev = 0;
    for (int j = 0; j < nm; j++) {
        double Fm = sF[j] / NSEED, Fsd = sqrt(fmax(0, sF2[j] - NSEED * Fm * Fm) / (NSEED - 1));
        double Fc = (pk_grading_passing(g, mids[j]) - g->mass_below) / msum;
        CHECK_MSG(fabs(Fm - Fc) < 4 * Fsd / sqrt(NSEED) + 1e-12, "%s mid %g: %.6f vs %.6f", label,
                  mids[j], Fm, Fc);
        Fmax_dev = fmax(Fmax_dev, fabs(Fm - Fc));
    }
    printf("  %-24s N: E %.1f  sampled %.1f ± %.1f (sd; theory %.1f; %d seeds)\n"
           "  %-24s phi overshoot <= %.3f of one finest grain; max |class share - curve| %.2e; "
           "max |mass passing at class mid - curve| %.2e\n",
           label, en, mean, sd, sd_th, NSEED, "", maxover, maxshare, Fmax_dev);
}

static void test_sampling_vs_expected(void)
{
    const double V150 = 150.0 * 150 * 150;
    pk_grading g;
    CHECK(pk_grading_preset(&g, "A16") == 0 && pk_grading_truncate(&g, 2) == 0);
    run_sampling_case("A16 a=150 dmin=2", &g, 0.7 * (1 - g.mass_below) * V150, 44202);
    CHECK(pk_grading_preset(&g, "B16") == 0 && pk_grading_truncate(&g, 2) == 0);
    run_sampling_case("B16 a=150 dmin=2", &g, 0.7 * (1 - g.mass_below) * V150, 40049);
    CHECK(pk_grading_from_fuller(&g, 0.7, 16, 2) == 0);
    run_sampling_case("Fuller q=0.7 a=150", &g, 0.7 * (1 - g.mass_below) * V150, 39704);
    CHECK(pk_grading_from_fuller(&g, 0.35, 16, 2) == 0);
    run_sampling_case("Fuller q=0.35 a=150", &g, 0.7 * (1 - g.mass_below) * V150, 35831);
    CHECK(pk_grading_from_fuller(&g, 0.5, 16, 2) == 0);
    run_sampling_case("Fuller q=0.5 a=80 .70", &g, 0.70 * 512000.0, 9307);

    /* Zero target → no grains; the max_n guard. */
    pk_rng r;
    pk_rng_seed(&r, 7, 0);
    pk_sizes s;
    CHECK(pk_grading_preset(&g, "A16") == 0 && pk_grading_truncate(&g, 2) == 0);
    CHECK(pk_sample_by_measure(&g, 3, 0.0, &r, 10, &s) == 0 && s.n == 0);
    pk_sizes_free(&s);
    CHECK(pk_sample_by_measure(&g, 3, 0.553 * 150.0 * 150 * 150, &r, 1000, &s) == -1);
    CHECK(contains(pk_psd_error(), "max_n"));
    CHECK(s.n == 0 && s.d == NULL);

    /* By count: exactly n; class counts follow the expected number shares
     * (binomial, 4 σ). */
    double cnt[PK_PSD_MAX_CLASSES];
    double en = pk_grading_expected_count(&g, 3, 1.0, cnt);
    const size_t n = 20000;
    CHECK(pk_sample_by_count(&g, 3, n, &r, &s) == 0 && s.n == n);
    size_t per[PK_PSD_MAX_CLASSES] = {0};
    for (size_t k = 0; k < s.n; k++) {
        per[s.species[k]]++;
        if (k)
            CHECK(s.d[k] <= s.d[k - 1]);
    }
    for (int i = 0; i < g.nclass; i++) {
        double p = cnt[i] / en;
        CHECK(fabs((double)per[i] - n * p) < 4 * sqrt(n * p * (1 - p)));
    }
    pk_sizes_free(&s);
}

/* ---------------------------------------------------------------- test 6 */

static int cmp_dbl(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One-sample KS statistic of n draws (through pk_sample_by_count on a
 * one-class grading, i.e. the full sampling path) against the class's number
 * CDF.  Critical value at the 1 % level: 1.63/√n.
 * Note: D is invariant under the monotone map u → F⁻¹(u), so with an exact
 * inverse it only depends on the uniforms; the cases therefore use different
 * seeds.  That the CDF itself is the right law is checked against Eq. (8) and
 * quadrature in test_inverse_transform, and the "wrong law" case below shows
 * the test has power. */
static double ks_stat(const pk_size_class *c, int dim, const pk_size_class *cdf_class, int cdf_dim,
                      size_t n, uint64_t seed)
{
    pk_grading g;
    memset(&g, 0, sizeof g);
    g.nclass = 1;
    g.cls[0] = *c;
    pk_rng r;
    pk_rng_seed(&r, seed, 1);
    pk_sizes s;
    if (pk_sample_by_count(&g, dim, n, &r, &s) != 0)
        return 1.0;
    qsort(s.d, s.n, sizeof(double), cmp_dbl);
    double D = 0;
    for (size_t k = 0; k < s.n; k++) {
        double F = pk_class_number_cdf(cdf_class, cdf_dim, s.d[k]);
        D = fmax(D, fmax((double)(k + 1) / n - F, F - (double)k / n));
    }
    pk_sizes_free(&s);
    return D;
}

static void test_ks(void)
{
    const size_t n = 20000;
    const double crit = 1.63 / sqrt((double)n);
    struct {
        const char *label;
        pk_size_class c;
        int dim;
    } cases[] = {
        {"3D beta=0 [2,4]", mkclass(2, 4, 0), 3},
        {"2D beta=0 [2,4]", mkclass(2, 4, 0), 2},
        {"3D Fuller q=0.7 [2,16]", mkclass(2, 16, 0.7), 3},
        {"2D Fuller q=0.7 [2,16]", mkclass(2, 16, 0.7), 2},
        {"3D beta=0 [0.016,16]", mkclass(0.016, 16, 0), 3},
        {"2D beta=0 [0.016,16]", mkclass(0.016, 16, 0), 2},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double D = ks_stat(&cases[i].c, cases[i].dim, &cases[i].c, cases[i].dim, n, 2024 + i);
        printf("  KS %-24s n=%zu D=%.5f (crit %.5f)\n", cases[i].label, n, D, crit);
        CHECK_MSG(D < crit, "%s: D = %g", cases[i].label, D);
    }
    /* Power: the same test rejects a wrong law (3D draws vs the 2D CDF). */
    pk_size_class c = mkclass(2, 4, 0);
    double Dw = ks_stat(&c, 3, &c, 2, n, 2024);
    printf("  KS 3D draws vs 2D CDF (must fail) D=%.5f\n", Dw);
    CHECK(Dw > 3 * crit);
}

/* ---------------------------------------------------------------- test 7 */

static void test_bad_inputs(void)
{
    pk_grading g;
    const double sz[5] = {0.25, 0.5, 1, 2, 4};
    const double p_bad[5] = {5, 20, 56, 42, 100};
    CHECK(pk_grading_from_sieve(&g, sz, p_bad, 5) == -1);
    CHECK(contains(pk_psd_error(), "not non-decreasing at index 3 (42 < 56)"));
    const double p_ok[5] = {5, 20, 42, 56, 100};
    CHECK(pk_grading_from_sieve(&g, sz, p_ok, 1) == -1 && contains(pk_psd_error(), "at least 2"));
    CHECK(pk_grading_from_sieve(&g, sz, p_ok, 0) == -1);
    CHECK(pk_grading_from_sieve(&g, NULL, p_ok, 5) == -1 && contains(pk_psd_error(), "NULL"));
    CHECK(pk_grading_from_sieve(NULL, sz, p_ok, 5) == -1);
    const double sz_desc[5] = {0.25, 0.5, 2, 1, 4};
    CHECK(pk_grading_from_sieve(&g, sz_desc, p_ok, 5) == -1 &&
          contains(pk_psd_error(), "ascending at index 3"));
    const double sz_nan[5] = {0.25, NAN, 1, 2, 4};
    CHECK(pk_grading_from_sieve(&g, sz_nan, p_ok, 5) == -1 && contains(pk_psd_error(), "index 1"));
    const double sz_neg[5] = {-1, 0.5, 1, 2, 4};
    CHECK(pk_grading_from_sieve(&g, sz_neg, p_ok, 5) == -1 && contains(pk_psd_error(), "> 0"));
    const double p_nan[5] = {5, 20, NAN, 56, 100};
    CHECK(pk_grading_from_sieve(&g, sz, p_nan, 5) == -1 && contains(pk_psd_error(), "index 2"));
    const double p_end[5] = {5, 20, 42, 56, 99};
    CHECK(pk_grading_from_sieve(&g, sz, p_end, 5) == -1 && contains(pk_psd_error(), "end at 100"));
    const double p_big[5] = {5, 20, 42, 156, 100};
    CHECK(pk_grading_from_sieve(&g, sz, p_big, 5) == -1 && contains(pk_psd_error(), "[0,100]"));

    CHECK(pk_grading_from_fuller(&g, 1.0, 16, 2) == -1 && contains(pk_psd_error(), "0 < q < 1"));
    CHECK(pk_grading_from_fuller(&g, 0.0, 16, 2) == -1);
    CHECK(pk_grading_from_fuller(&g, NAN, 16, 2) == -1);
    CHECK(pk_grading_from_fuller(&g, 0.5, 16, 16) == -1 &&
          contains(pk_psd_error(), "d_floor < d_max"));
    CHECK(pk_grading_from_fuller(&g, 0.5, 16, 0) == -1);
    CHECK(pk_grading_from_fuller(&g, 0.5, INFINITY, 2) == -1);

    const double d2[2] = {1, 2}, s_neg[2] = {1, -1}, s_zero[2] = {0, 0}, d_nan[2] = {NAN, 2};
    const double s_ok[2] = {1, 1}, rho0[2] = {1, 0};
    CHECK(pk_grading_from_classes(&g, d2, s_ok, NULL, 0) == -1);
    CHECK(pk_grading_from_classes(&g, d2, s_neg, NULL, 2) == -1 &&
          contains(pk_psd_error(), "index 1"));
    CHECK(pk_grading_from_classes(&g, d2, s_zero, NULL, 2) == -1 &&
          contains(pk_psd_error(), "sum"));
    CHECK(pk_grading_from_classes(&g, d_nan, s_ok, NULL, 2) == -1 &&
          contains(pk_psd_error(), "index 0"));
    CHECK(pk_grading_from_classes(&g, d2, s_ok, rho0, 2) == -1 &&
          contains(pk_psd_error(), "density"));

    CHECK(pk_grading_preset(&g, "D16") == -1 && contains(pk_psd_error(), "unknown"));
    CHECK(pk_grading_preset(&g, NULL) == -1);
    CHECK(pk_grading_preset(&g, "A16") == 0);
    CHECK(pk_grading_truncate(&g, 16) == -1 && contains(pk_psd_error(), ">= d_max"));
    CHECK(pk_grading_truncate(&g, 20) == -1);
    CHECK(pk_grading_truncate(&g, NAN) == -1);
    CHECK(pk_grading_truncate(&g, 0) == -1);
    CHECK(pk_grading_truncate(&g, 0.1) == -1 && contains(pk_psd_error(), "not resolved"));
    CHECK(pk_grading_truncate(NULL, 2) == -1);
    CHECK(g.nclass == 6 && g.mass_below == 0.03); /* failed calls leave g unchanged */

    pk_size_class c = mkclass(2, 4, 0), bad = mkclass(4, 2, 0);
    CHECK(isnan(pk_class_sample(NULL, 3, 0.5)));
    CHECK(isnan(pk_class_sample(&c, 4, 0.5)) && contains(pk_psd_error(), "dim"));
    CHECK(isnan(pk_class_sample(&c, 3, NAN)));
    CHECK(isnan(pk_class_sample(&c, 3, 1.5)));
    CHECK(isnan(pk_class_sample(&bad, 3, 0.5)) && contains(pk_psd_error(), "d_lo <= d_hi"));
    CHECK(isnan(pk_class_number_cdf(&c, 3, NAN)));
    CHECK(isnan(pk_class_expected_count(&c, 3, -1)));
    CHECK(isnan(pk_class_expected_count(&c, 3, NAN)));
    CHECK(isnan(pk_grading_expected_count(&g, 3, NAN, NULL)));
    CHECK(isnan(pk_grading_passing(NULL, 1)));
    CHECK(isnan(pk_grading_passing(&g, NAN)));

    pk_rng r;
    pk_rng_seed(&r, 1, 0);
    pk_sizes s;
    CHECK(pk_sample_by_measure(&g, 3, 1e4, NULL, 100, &s) == -1 && contains(pk_psd_error(), "rng"));
    CHECK(pk_sample_by_measure(&g, 3, -1, &r, 100, &s) == -1);
    CHECK(pk_sample_by_measure(&g, 3, NAN, &r, 100, &s) == -1);
    CHECK(pk_sample_by_measure(&g, 1, 1e4, &r, 100, &s) == -1);
    CHECK(pk_sample_by_measure(&g, 3, 1e4, &r, 100, NULL) == -1);
    CHECK(pk_sample_by_count(NULL, 3, 10, &r, &s) == -1);
    CHECK(pk_sample_discrete(&g, 5, 10, &s) == -1);
    CHECK(isnan(pk_sizes_measure(NULL, 3)));

    /* Hand-made gradings are validated. */
    pk_grading h = g;
    h.nclass = 0;
    CHECK(pk_grading_check(&h) == -1 && contains(pk_psd_error(), "classes"));
    CHECK(pk_discrete_nop_min(&h, 2) == 0);
    h.nclass = PK_PSD_MAX_CLASSES + 1;
    CHECK(pk_grading_check(&h) == -1);
    h = g;
    h.cls[2].d_lo = 100;
    CHECK(pk_grading_check(&h) == -1 && contains(pk_psd_error(), "class 2"));
    h = g;
    h.cls[0].mass_fraction = 0.9;
    CHECK(pk_grading_check(&h) == -1 && contains(pk_psd_error(), "> 1"));
    size_t cnt[PK_PSD_MAX_CLASSES + 1];
    cnt[0] = 99;
    pk_discrete_counts(&h, 2, 100, cnt);
    CHECK(cnt[0] == 0);
    h = g;
    h.cls[1].beta = NAN;
    CHECK(isnan(pk_grading_expected_count(&h, 3, 1, NULL)));
}

/* ---------------------------------------------------------------- test 8 */

/* Truncation: exact mass bookkeeping (round-off only: 1e-12), the curve is
 * unchanged above d_min and reports the cut mass below it (Eq. 14). */
static void test_truncation(void)
{
    const char *names[4] = {"A16", "B16", "C32", "A8"};
    const double dmins[7] = {0.3, 0.5, 0.7, 1, 2, 3, 5.5};
    for (int p = 0; p < 5; p++)
        for (int k = 0; k < 7; k++) {
            pk_grading g, t;
            if (p < 4)
                CHECK(pk_grading_preset(&g, names[p]) == 0);
            else
                CHECK(pk_grading_from_fuller(&g, 0.45, 16, 0.25) == 0);
            t = g;
            CHECK(pk_grading_truncate(&t, dmins[k]) == 0);
            double sum = t.mass_below;
            for (int i = 0; i < t.nclass; i++) {
                sum += t.cls[i].mass_fraction;
                CHECK(t.cls[i].d_lo >= dmins[k]);
            }
            CHECK_NEAR(sum, 1.0, 1e-12);
            CHECK_NEAR(t.mass_below, pk_grading_passing(&g, dmins[k]), 1e-12);
            CHECK_NEAR(t.cls[t.nclass - 1].d_lo, dmins[k], 0); /* finest class starts at d_min */
            for (double d = 0.3; d < 40; d *= 1.17) {
                double want = d >= dmins[k] ? pk_grading_passing(&g, d) : t.mass_below;
                CHECK_NEAR(pk_grading_passing(&t, d), want, 1e-12);
            }
            /* idempotent */
            pk_grading t2 = t;
            CHECK(pk_grading_truncate(&t2, dmins[k]) == 0);
            CHECK(t2.nclass == t.nclass && t2.mass_below == t.mass_below);
        }
    /* Discrete classes: all-or-nothing by d_rep. */
    pk_grading g;
    CHECK(pk_grading_from_classes(&g, a32_d, a32_v, NULL, 6) == 0);
    CHECK(pk_grading_truncate(&g, 2) == 0);
    CHECK(g.nclass == 5 && g.cls[4].d_rep == 2);
    CHECK_NEAR(g.mass_below, 0.14, 1e-15);
}

int main(void)
{
    RUN(test_inverse_transform);
    RUN(test_meier_tables);
    RUN(test_din);
    RUN(test_fuller);
    RUN(test_sampling_vs_expected);
    RUN(test_ks);
    RUN(test_bad_inputs);
    RUN(test_truncation);
    return check_summary();
}
