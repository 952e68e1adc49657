/* psd.c — grading (sieve) curves → particle sizes (Titscher §2–3, Algorithm 1).
 * Contract: core/psd/psd.h; folder guide core/psd/README.md.
 *
 * One in-class law for everything: the mass CDF inside a class is ∝ d^β on
 * [a, b] (β = 0: ln d, Titscher Eq. 2).  With grain measure c·d^dim the
 * number pdf is ∝ d^(e−1), e = β − dim.  All closed forms reduce to
 *
 *     I_s(a, x) = ∫_a^x t^(s−1) dt = a^s · E(s, ln(x/a)),
 *     E(s, L)   = expm1(s·L)/s   (→ L for s = 0),
 *
 * so β = 0, β ≠ 0, dim 2 and dim 3 share one code path, and expm1/log1p keep
 * it accurate for size ratios of 1:1000 and more. */
#include "psd.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------ errors */

static _Thread_local char psd_err[256] = "no error";

#if defined(__GNUC__)
__attribute__((format(printf, 1, 2)))
#endif
static void
set_err(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(psd_err, sizeof psd_err, fmt, ap);
    va_end(ap);
}

const char *pk_psd_error(void) { return psd_err; }

/* ------------------------------------------------------------ basic pieces */

/* Grain measure c·d^dim: π/4·d² (disk area) or π/6·d³ (sphere volume). */
#define PK_PI 3.14159265358979323846
static double grain_coef(int dim) { return dim == 2 ? PK_PI / 4.0 : PK_PI / 6.0; }

static double grain_measure(int dim, double d) { return grain_coef(dim) * pow(d, dim); }

/* E(s, L) = expm1(s·L)/s, continuous at s = 0. */
static double ex1(double s, double L)
{
    double x = s * L;
    return x == 0.0 ? L : expm1(x) / s;
}

/* Inverse of E in its second argument: E(s, x) = y  ⇔  x = log1p(s·y)/s. */
static double ex1_inv(double s, double y)
{
    double x = s * y;
    return x == 0.0 ? y : log1p(x) / s;
}

/* CDF on [a, b] of the density ∝ t^(s−1).  Evaluated from the nearer end so
 * that both tails keep full precision. */
static double law_cdf(double s, double a, double b, double d)
{
    if (d <= a)
        return 0.0;
    if (d >= b)
        return 1.0;
    double L = log(b / a);
    double f = ex1(s, log(d / a)) / ex1(s, L);
    if (f > 0.5)
        f = 1.0 - ex1(-s, log(b / d)) / ex1(-s, L);
    return f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
}

/* Inverse of law_cdf (inverse-transform sampling, Titscher Eq. 10
 * generalised), with the per-class constants precomputed for the draw loops.
 * u <= 1/2 is inverted from d_lo, u > 1/2 from d_hi, so neither tail loses
 * relative precision (1 − u is exact for u in [1/2, 1]). */
typedef struct {
    double a, b, s, e_lo, e_hi;
} law_sampler;

static law_sampler law_prepare(double s, double a, double b)
{
    double L = log(b / a);
    law_sampler w = {a, b, s, ex1(s, L), ex1(-s, L)};
    return w;
}

static double law_draw(const law_sampler *w, double u)
{
    double d;
    if (w->b <= w->a)
        return w->a; /* discrete class */
    if (u <= 0.5)
        d = w->a * exp(ex1_inv(w->s, u * w->e_lo));
    else
        d = w->b * exp(-ex1_inv(-w->s, (1.0 - u) * w->e_hi));
    return d < w->a ? w->a : (d > w->b ? w->b : d);
}

static int dim_ok(int dim)
{
    if (dim != 2 && dim != 3) {
        set_err("dim must be 2 or 3 (got %d)", dim);
        return 0;
    }
    return 1;
}

static int class_ok(const pk_size_class *c, int idx)
{
    if (!c) {
        set_err("size class is NULL");
        return 0;
    }
    if (!isfinite(c->d_lo) || !isfinite(c->d_hi) || !(c->d_lo > 0.0) || !(c->d_hi >= c->d_lo)) {
        set_err("class %d: need finite 0 < d_lo <= d_hi (got %g, %g)", idx, c->d_lo, c->d_hi);
        return 0;
    }
    if (!isfinite(c->beta)) {
        set_err("class %d: beta is not finite", idx);
        return 0;
    }
    if (!isfinite(c->mass_fraction) || c->mass_fraction < 0.0 || c->mass_fraction > 1.0 + 1e-9) {
        set_err("class %d: mass_fraction %g outside [0,1]", idx, c->mass_fraction);
        return 0;
    }
    if (!isfinite(c->d_rep) || !(c->d_rep > 0.0)) {
        set_err("class %d: d_rep %g must be finite and > 0", idx, c->d_rep);
        return 0;
    }
    return 1;
}

int pk_grading_check(const pk_grading *g)
{
    if (!g) {
        set_err("grading is NULL");
        return -1;
    }
    if (g->nclass < 1 || g->nclass > PK_PSD_MAX_CLASSES) {
        set_err("grading has %d classes (need 1..%d)", g->nclass, PK_PSD_MAX_CLASSES);
        return -1;
    }
    if (!isfinite(g->mass_below) || g->mass_below < 0.0 || g->mass_below > 1.0) {
        set_err("mass_below %g outside [0,1]", g->mass_below);
        return -1;
    }
    double sum = g->mass_below;
    for (int i = 0; i < g->nclass; i++) {
        if (!class_ok(&g->cls[i], i))
            return -1;
        sum += g->cls[i].mass_fraction;
    }
    if (sum > 1.0 + 1e-9) {
        set_err("class masses plus mass_below sum to %.12g > 1", sum);
        return -1;
    }
    return 0;
}

/* ------------------------------------------------------- building gradings */

int pk_grading_from_sieve(pk_grading *g, const double *sizes, const double *passing_percent, int n)
{
    if (!g || !sizes || !passing_percent) {
        set_err("sieve curve: NULL argument");
        return -1;
    }
    if (n < 2) {
        set_err("sieve curve needs at least 2 sieves (got %d)", n);
        return -1;
    }
    if (n - 1 > PK_PSD_MAX_CLASSES) {
        set_err("sieve curve has %d sieves; at most %d are supported", n, PK_PSD_MAX_CLASSES + 1);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        if (!isfinite(sizes[i]) || !(sizes[i] > 0.0)) {
            set_err("sieve size at index %d must be finite and > 0 (got %g)", i, sizes[i]);
            return -1;
        }
        if (i > 0 && !(sizes[i] > sizes[i - 1])) {
            set_err("sieve sizes not strictly ascending at index %d (%g <= %g)", i, sizes[i],
                    sizes[i - 1]);
            return -1;
        }
        double p = passing_percent[i];
        if (!isfinite(p) || p < 0.0 || p > 100.0) {
            set_err("sieve passing at index %d must be finite and in [0,100] (got %g)", i, p);
            return -1;
        }
        if (i > 0 && p < passing_percent[i - 1]) {
            set_err("sieve curve not non-decreasing at index %d (%g < %g)", i, p,
                    passing_percent[i - 1]);
            return -1;
        }
    }
    if (fabs(passing_percent[n - 1] - 100.0) > 1e-9) {
        set_err("sieve curve must end at 100 %% passing (index %d is %g)", n - 1,
                passing_percent[n - 1]);
        return -1;
    }
    memset(g, 0, sizeof *g);
    g->nclass = n - 1;
    g->mass_below = passing_percent[0] / 100.0;
    for (int k = 0; k < n - 1; k++) { /* class k = coarse → fine */
        int hi = n - 1 - k, lo = hi - 1;
        double phi = hi == n - 1 ? 100.0 : passing_percent[hi];
        pk_size_class *c = &g->cls[k];
        c->d_lo = sizes[lo];
        c->d_hi = sizes[hi];
        c->d_rep = sizes[lo];
        c->mass_fraction = (phi - passing_percent[lo]) / 100.0;
        c->beta = 0.0;
    }
    return 0;
}

typedef struct {
    double d, v;
} dv_pair;

static int cmp_dv_desc(const void *pa, const void *pb)
{
    const dv_pair *a = pa, *b = pb;
    return (a->d < b->d) - (a->d > b->d);
}

int pk_grading_from_classes(pk_grading *g, const double *d, const double *share,
                            const double *density, int n)
{
    if (!g || !d || !share) {
        set_err("discrete classes: NULL argument");
        return -1;
    }
    if (n < 1 || n > PK_PSD_MAX_CLASSES) {
        set_err("discrete classes: need 1..%d classes (got %d)", PK_PSD_MAX_CLASSES, n);
        return -1;
    }
    dv_pair tmp[PK_PSD_MAX_CLASSES];
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(d[i]) || !(d[i] > 0.0)) {
            set_err("class diameter at index %d must be finite and > 0 (got %g)", i, d[i]);
            return -1;
        }
        if (!isfinite(share[i]) || share[i] < 0.0) {
            set_err("class share at index %d must be finite and >= 0 (got %g)", i, share[i]);
            return -1;
        }
        double v = share[i];
        if (density) {
            if (!isfinite(density[i]) || !(density[i] > 0.0)) {
                set_err("class density at index %d must be finite and > 0 (got %g)", i, density[i]);
                return -1;
            }
            v /= density[i];
        }
        tmp[i].d = d[i];
        tmp[i].v = v;
        sum += v;
    }
    if (!(sum > 0.0) || !isfinite(sum)) {
        set_err("discrete classes: shares sum to %g (need a finite positive total)", sum);
        return -1;
    }
    qsort(tmp, (size_t)n, sizeof tmp[0], cmp_dv_desc);
    memset(g, 0, sizeof *g);
    g->nclass = n;
    g->mass_below = 0.0;
    for (int i = 0; i < n; i++) {
        pk_size_class *c = &g->cls[i];
        c->d_lo = c->d_hi = c->d_rep = tmp[i].d;
        c->mass_fraction = tmp[i].v / sum;
        c->beta = 0.0;
    }
    return 0;
}

int pk_grading_from_fuller(pk_grading *g, double q, double d_max, double d_floor)
{
    if (!g) {
        set_err("Fuller curve: NULL grading");
        return -1;
    }
    if (!isfinite(q) || !(q > 0.0) || !(q < 1.0)) {
        set_err("Fuller exponent q must satisfy 0 < q < 1 (got %g)", q);
        return -1;
    }
    if (!isfinite(d_max) || !isfinite(d_floor) || !(d_floor > 0.0) || !(d_floor < d_max)) {
        set_err("Fuller curve needs finite 0 < d_floor < d_max (got d_floor %g, d_max %g)", d_floor,
                d_max);
        return -1;
    }
    memset(g, 0, sizeof *g);
    double lr = log(d_floor / d_max); /* < 0 */
    g->nclass = 1;
    g->mass_below = exp(q * lr);
    g->cls[0].d_lo = d_floor;
    g->cls[0].d_hi = d_max;
    g->cls[0].d_rep = d_floor;
    g->cls[0].mass_fraction = -expm1(q * lr);
    g->cls[0].beta = q;
    return 0;
}

/* DIN 1045-2 grading curves (% passing), sieves 0.25 … 31.5 mm. */
static const double din_sieves[8] = {0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 31.5};
static const struct {
    const char *name;
    int n;
    double p[8];
} din_presets[] = {
    {"A8", 6, {5, 14, 21, 36, 61, 100}},           {"B8", 6, {11, 26, 42, 57, 74, 100}},
    {"C8", 6, {21, 39, 57, 71, 85, 100}},          {"A16", 7, {3, 8, 12, 21, 36, 60, 100}},
    {"B16", 7, {8, 20, 32, 42, 56, 76, 100}},      {"C16", 7, {18, 34, 49, 62, 74, 88, 100}},
    {"A32", 8, {2, 5, 8, 14, 23, 38, 62, 100}},    {"B32", 8, {8, 18, 28, 37, 47, 62, 80, 100}},
    {"C32", 8, {15, 29, 42, 53, 65, 77, 89, 100}},
};

static int name_eq_ci(const char *a, const char *b)
{
    for (; *a && *b; a++, b++) {
        char x = *a, y = *b;
        if (x >= 'a' && x <= 'z')
            x = (char)(x - 'a' + 'A');
        if (y >= 'a' && y <= 'z')
            y = (char)(y - 'a' + 'A');
        if (x != y)
            return 0;
    }
    return *a == *b;
}

int pk_grading_preset(pk_grading *g, const char *name)
{
    if (!g || !name) {
        set_err("preset: NULL argument");
        return -1;
    }
    for (size_t i = 0; i < sizeof din_presets / sizeof din_presets[0]; i++)
        if (name_eq_ci(name, din_presets[i].name))
            return pk_grading_from_sieve(g, din_sieves, din_presets[i].p, din_presets[i].n);
    set_err("unknown grading preset \"%.40s\" (known: A8 B8 C8 A16 B16 C16 A32 B32 C32)", name);
    return -1;
}

/* In-class mass CDF (0..1).  A discrete class (d_lo == d_hi) is a step at d_lo. */
static double class_mass_cdf(const pk_size_class *c, double d)
{
    if (c->d_hi <= c->d_lo)
        return d >= c->d_lo ? 1.0 : 0.0;
    return law_cdf(c->beta, c->d_lo, c->d_hi, d);
}

double pk_grading_passing(const pk_grading *g, double d)
{
    if (pk_grading_check(g) != 0)
        return NAN;
    if (isnan(d)) {
        set_err("passing: d is NaN");
        return NAN;
    }
    if (d <= 0.0)
        return 0.0;
    double f = g->mass_below;
    for (int i = 0; i < g->nclass; i++)
        f += g->cls[i].mass_fraction * class_mass_cdf(&g->cls[i], d);
    return f > 1.0 ? 1.0 : f;
}

int pk_grading_truncate(pk_grading *g, double d_min)
{
    if (pk_grading_check(g) != 0)
        return -1;
    if (!isfinite(d_min) || !(d_min > 0.0)) {
        set_err("truncate: d_min must be finite and > 0 (got %g)", d_min);
        return -1;
    }
    double top = 0.0, bottom = INFINITY;
    for (int i = 0; i < g->nclass; i++) {
        if (g->cls[i].mass_fraction <= 0.0)
            continue;
        top = fmax(top, g->cls[i].d_hi);
        bottom = fmin(bottom, g->cls[i].d_lo);
    }
    if (top == 0.0) {
        set_err("truncate: grading holds no class mass");
        return -1;
    }
    if (d_min < bottom && g->mass_below > 0.0) {
        set_err("truncate: d_min %g is below the finest modelled size %g (the %.4g %% "
                "finer than that is not resolved)",
                d_min, bottom, 100.0 * g->mass_below);
        return -1;
    }
    if (d_min <= bottom)
        return 0; /* nothing modelled lies below d_min */
    int discrete_top = 0;
    for (int i = 0; i < g->nclass; i++)
        if (g->cls[i].mass_fraction > 0.0 && g->cls[i].d_hi == top &&
            g->cls[i].d_lo == g->cls[i].d_hi)
            discrete_top = 1;
    if (discrete_top ? d_min > top : d_min >= top) {
        set_err("truncate: d_min %g >= d_max %g leaves no material", d_min, top);
        return -1;
    }
    pk_grading out = *g;
    out.nclass = 0;
    for (int i = 0; i < g->nclass; i++) {
        pk_size_class c = g->cls[i];
        if (c.d_lo == c.d_hi) { /* discrete class: all or nothing */
            if (c.d_lo < d_min) {
                out.mass_below += c.mass_fraction;
                continue;
            }
        } else if (c.d_hi <= d_min) { /* entirely below: Eq. (14) */
            out.mass_below += c.mass_fraction;
            continue;
        } else if (c.d_lo < d_min) { /* straddles: cut with its own law */
            double cut = c.mass_fraction * law_cdf(c.beta, c.d_lo, c.d_hi, d_min);
            out.mass_below += cut;
            c.mass_fraction -= cut;
            c.d_lo = d_min;
            c.d_rep = d_min;
        }
        out.cls[out.nclass++] = c;
    }
    if (out.mass_below > 1.0)
        out.mass_below = 1.0;
    *g = out;
    return 0;
}

/* ---------------------------------------------------- in-class sampling */

static int class_args_ok(const pk_size_class *c, int dim) { return dim_ok(dim) && class_ok(c, 0); }

double pk_class_number_cdf(const pk_size_class *c, int dim, double d)
{
    if (!class_args_ok(c, dim))
        return NAN;
    if (isnan(d)) {
        set_err("number CDF: d is NaN");
        return NAN;
    }
    if (c->d_hi <= c->d_lo)
        return d >= c->d_lo ? 1.0 : 0.0;
    return law_cdf(c->beta - dim, c->d_lo, c->d_hi, d);
}

double pk_class_sample(const pk_size_class *c, int dim, double u)
{
    if (!class_args_ok(c, dim))
        return NAN;
    if (!(u >= 0.0 && u <= 1.0)) {
        set_err("class sample: u = %g outside [0,1]", u);
        return NAN;
    }
    law_sampler w = law_prepare(c->beta - dim, c->d_lo, c->d_hi);
    return law_draw(&w, u);
}

/* Expected grains per unit measure: N/M = a^−dim · E(e, L) / (c · E(β, L)). */
static double count_per_measure(const pk_size_class *c, int dim)
{
    double a = c->d_lo;
    if (c->d_hi <= c->d_lo)
        return 1.0 / grain_measure(dim, a);
    double L = log(c->d_hi / a);
    return ex1(c->beta - dim, L) / (ex1(c->beta, L) * grain_measure(dim, a));
}

double pk_class_expected_count(const pk_size_class *c, int dim, double measure)
{
    if (!class_args_ok(c, dim))
        return NAN;
    if (!isfinite(measure) || measure < 0.0) {
        set_err("expected count: measure must be finite and >= 0 (got %g)", measure);
        return NAN;
    }
    return measure * count_per_measure(c, dim);
}

double pk_grading_expected_count(const pk_grading *g, int dim, double total_measure, double *counts)
{
    if (pk_grading_check(g) != 0 || !dim_ok(dim))
        return NAN;
    if (!isfinite(total_measure) || total_measure < 0.0) {
        set_err("expected count: total measure must be finite and >= 0 (got %g)", total_measure);
        return NAN;
    }
    double n = 0.0;
    for (int i = 0; i < g->nclass; i++) {
        double ni = total_measure * g->cls[i].mass_fraction * count_per_measure(&g->cls[i], dim);
        if (counts)
            counts[i] = ni;
        n += ni;
    }
    return n;
}

/* ------------------------------------------------------------ size sets */

void pk_sizes_free(pk_sizes *s)
{
    if (!s)
        return;
    free(s->d);
    free(s->species);
    s->d = NULL;
    s->species = NULL;
    s->n = 0;
}

typedef struct {
    double d;
    int32_t sp;
} grain;

static int cmp_grain_desc(const void *pa, const void *pb)
{
    const grain *a = pa, *b = pb;
    if (a->d != b->d)
        return (a->d < b->d) - (a->d > b->d);
    return (a->sp > b->sp) - (a->sp < b->sp);
}

typedef struct {
    grain *g;
    size_t n, cap;
} grain_buf;

static int gb_push(grain_buf *b, double d, int32_t sp)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        if (cap > SIZE_MAX / sizeof(grain))
            return -1;
        grain *p = realloc(b->g, cap * sizeof(grain));
        if (!p)
            return -1;
        b->g = p;
        b->cap = cap;
    }
    b->g[b->n].d = d;
    b->g[b->n].sp = sp;
    b->n++;
    return 0;
}

/* Sort descending and hand the buffer over as a pk_sizes (frees b). */
static int gb_finish(grain_buf *b, pk_sizes *out)
{
    out->n = 0;
    out->d = NULL;
    out->species = NULL;
    if (b->n) {
        qsort(b->g, b->n, sizeof(grain), cmp_grain_desc);
        out->d = malloc(b->n * sizeof(double));
        out->species = malloc(b->n * sizeof(int32_t));
        if (!out->d || !out->species) {
            pk_sizes_free(out);
            free(b->g);
            set_err("out of memory for %zu grains", b->n);
            return -1;
        }
        for (size_t k = 0; k < b->n; k++) {
            out->d[k] = b->g[k].d;
            out->species[k] = b->g[k].sp;
        }
        out->n = b->n;
    }
    free(b->g);
    b->g = NULL;
    return 0;
}

static void sizes_clear(pk_sizes *out)
{
    if (out) {
        out->n = 0;
        out->d = NULL;
        out->species = NULL;
    }
}

int pk_sample_by_measure(const pk_grading *g, int dim, double resolved_measure, pk_rng *rng,
                         size_t max_n, pk_sizes *out)
{
    if (!out) {
        set_err("sample by measure: out is NULL");
        return -1;
    }
    sizes_clear(out);
    if (pk_grading_check(g) != 0 || !dim_ok(dim))
        return -1;
    if (!rng) {
        set_err("sample by measure: rng is NULL");
        return -1;
    }
    if (!isfinite(resolved_measure) || resolved_measure < 0.0) {
        set_err("sample by measure: resolved measure must be finite and >= 0 (got %g)",
                resolved_measure);
        return -1;
    }
    double msum = 0.0;
    for (int i = 0; i < g->nclass; i++)
        msum += g->cls[i].mass_fraction;
    if (!(msum > 0.0)) {
        set_err("sample by measure: grading holds no class mass");
        return -1;
    }
    grain_buf b = {0};
    double target = 0.0, actual = 0.0, coef = grain_coef(dim);
    for (int i = 0; i < g->nclass; i++) { /* classes are coarse → fine */
        const pk_size_class *c = &g->cls[i];
        /* Cumulative target: this class's overshoot is taken off the next. */
        target += resolved_measure * (c->mass_fraction / msum);
        if (i == g->nclass - 1)
            target = resolved_measure; /* no round-off residue in the total */
        if (c->mass_fraction <= 0.0)
            continue;
        law_sampler w = law_prepare(c->beta - dim, c->d_lo, c->d_hi);
        while (actual < target) {
            if (b.n >= max_n) {
                free(b.g);
                set_err("sample by measure: more than max_n = %zu grains needed "
                        "(expected about %.0f)",
                        max_n,
                        resolved_measure / msum * pk_grading_expected_count(g, dim, 1.0, NULL));
                return -1;
            }
            double d = law_draw(&w, pk_rng_uniform(rng));
            if (gb_push(&b, d, (int32_t)i) != 0) {
                free(b.g);
                set_err("sample by measure: out of memory after %zu grains", b.n);
                return -1;
            }
            actual += coef * (dim == 2 ? d * d : d * d * d);
        }
    }
    return gb_finish(&b, out);
}

int pk_sample_by_count(const pk_grading *g, int dim, size_t n, pk_rng *rng, pk_sizes *out)
{
    if (!out) {
        set_err("sample by count: out is NULL");
        return -1;
    }
    sizes_clear(out);
    if (pk_grading_check(g) != 0 || !dim_ok(dim))
        return -1;
    if (!rng) {
        set_err("sample by count: rng is NULL");
        return -1;
    }
    double cum[PK_PSD_MAX_CLASSES], tot = 0.0;
    law_sampler w[PK_PSD_MAX_CLASSES];
    for (int i = 0; i < g->nclass; i++) {
        tot += g->cls[i].mass_fraction * count_per_measure(&g->cls[i], dim);
        cum[i] = tot;
        w[i] = law_prepare(g->cls[i].beta - dim, g->cls[i].d_lo, g->cls[i].d_hi);
    }
    if (!(tot > 0.0) || !isfinite(tot)) {
        set_err("sample by count: grading holds no class mass");
        return -1;
    }
    if (n > SIZE_MAX / sizeof(grain)) {
        set_err("sample by count: n = %zu is too large", n);
        return -1;
    }
    grain_buf b = {0};
    if (n) {
        b.g = malloc(n * sizeof(grain));
        if (!b.g) {
            set_err("sample by count: out of memory for %zu grains", n);
            return -1;
        }
        b.cap = n;
    }
    for (size_t k = 0; k < n; k++) {
        double x = pk_rng_uniform(rng) * tot;
        int i = 0;
        while (i < g->nclass - 1 && !(x < cum[i]))
            i++;
        gb_push(&b, law_draw(&w[i], pk_rng_uniform(rng)), (int32_t)i); /* reserved: cannot fail */
    }
    return gb_finish(&b, out);
}

/* -------------------------------------------------------- discrete (Meier) */

static int discrete_args_ok(const pk_grading *g, int dim)
{
    return pk_grading_check(g) == 0 && dim_ok(dim);
}

void pk_discrete_number_shares(const pk_grading *g, int dim, double *share)
{
    if (!share) {
        set_err("discrete shares: share is NULL");
        return;
    }
    if (!discrete_args_ok(g, dim)) {
        if (g && g->nclass > 0 && g->nclass <= PK_PSD_MAX_CLASSES)
            for (int i = 0; i < g->nclass; i++)
                share[i] = 0.0;
        return;
    }
    double tot = 0.0;
    for (int i = 0; i < g->nclass; i++) {
        share[i] = g->cls[i].mass_fraction / pow(g->cls[i].d_rep, dim);
        tot += share[i];
    }
    for (int i = 0; i < g->nclass; i++)
        share[i] = tot > 0.0 ? share[i] / tot : 0.0;
    if (!(tot > 0.0))
        set_err("discrete shares: grading holds no class mass");
}

size_t pk_discrete_nop_min(const pk_grading *g, int dim)
{
    if (!discrete_args_ok(g, dim))
        return 0;
    double s[PK_PSD_MAX_CLASSES], mn = INFINITY;
    pk_discrete_number_shares(g, dim, s);
    for (int i = 0; i < g->nclass; i++)
        if (s[i] > 0.0 && s[i] < mn)
            mn = s[i];
    if (!isfinite(mn)) {
        set_err("nop_min: grading holds no class mass");
        return 0;
    }
    double x = 1.0 / mn;
    if (!(x < 1e18)) {
        set_err("nop_min: smallest particle share %g is too small", mn);
        return 0;
    }
    /* Ceiling (Eq. 13), forgiving one part in 1e12 of round-off above an integer. */
    return (size_t)ceil(x * (1.0 - 1e-12));
}

void pk_discrete_counts(const pk_grading *g, int dim, size_t nop, size_t *counts)
{
    if (!counts) {
        set_err("discrete counts: counts is NULL");
        return;
    }
    if (!discrete_args_ok(g, dim)) {
        if (g && g->nclass > 0 && g->nclass <= PK_PSD_MAX_CLASSES)
            for (int i = 0; i < g->nclass; i++)
                counts[i] = 0;
        return;
    }
    double s[PK_PSD_MAX_CLASSES], rem[PK_PSD_MAX_CLASSES];
    pk_discrete_number_shares(g, dim, s);
    size_t given = 0;
    for (int i = 0; i < g->nclass; i++) {
        double quota = (double)nop * s[i];
        double fl = floor(quota);
        counts[i] = (size_t)fl;
        rem[i] = s[i] > 0.0 ? quota - fl : -1.0; /* empty classes never get a seat */
        given += counts[i];
    }
    /* Hamilton: the seats left go to the largest remainders (ties: coarser first). */
    while (given < nop) {
        int best = -1;
        for (int i = 0; i < g->nclass; i++)
            if (rem[i] >= 0.0 && (best < 0 || rem[i] > rem[best]))
                best = i;
        if (best < 0)
            break; /* no class with mass */
        counts[best]++;
        rem[best] = -1.0;
        given++;
    }
}

int pk_sample_discrete(const pk_grading *g, int dim, size_t nop, pk_sizes *out)
{
    if (!out) {
        set_err("sample discrete: out is NULL");
        return -1;
    }
    sizes_clear(out);
    if (!discrete_args_ok(g, dim))
        return -1;
    double msum = 0.0;
    for (int i = 0; i < g->nclass; i++)
        msum += g->cls[i].mass_fraction;
    if (!(msum > 0.0)) {
        set_err("sample discrete: grading holds no class mass");
        return -1;
    }
    if (nop > SIZE_MAX / sizeof(grain)) {
        set_err("sample discrete: nop = %zu is too large", nop);
        return -1;
    }
    size_t cnt[PK_PSD_MAX_CLASSES];
    pk_discrete_counts(g, dim, nop, cnt);
    grain_buf b = {0};
    if (nop) {
        b.g = malloc(nop * sizeof(grain));
        if (!b.g) {
            set_err("sample discrete: out of memory for %zu grains", nop);
            return -1;
        }
        b.cap = nop;
    }
    for (int i = 0; i < g->nclass; i++)
        for (size_t k = 0; k < cnt[i]; k++)
            gb_push(&b, g->cls[i].d_rep, (int32_t)i); /* total == nop: cannot fail */
    return gb_finish(&b, out);
}

double pk_sizes_measure(const pk_sizes *s, int dim)
{
    if (!s || !dim_ok(dim)) {
        if (!s)
            set_err("sizes measure: NULL set");
        return NAN;
    }
    if (s->n && !s->d) {
        set_err("sizes measure: n = %zu but d is NULL", s->n);
        return NAN;
    }
    double m = 0.0;
    for (size_t k = 0; k < s->n; k++)
        m += grain_measure(dim, s->d[k]);
    return m;
}
