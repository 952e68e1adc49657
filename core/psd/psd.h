/* psd.h — grading (sieve) curves → particle sizes: the "take" phase.
 *
 * Sources: Titscher & Unger §2–3 (Eqs. 1–17, Algorithm 1), Meier, Kuhl &
 * Steinmann Eqs. 12–13, DIN 1045-2 curves.
 *
 * Everything works in solid *measure* (area in 2D, volume in 3D): with one
 * grain density, mass fractions equal volume fractions and ρ cancels.
 * "Mass fraction" below always means that measure fraction.
 *
 * A grading is a list of size classes, coarse → fine.  Inside a class the
 * mass CDF follows d^β normalised on [d_lo, d_hi]:
 *   β = 0  → linear in ln d (Titscher Eq. 2; used for sieve curves),
 *   β = q  → exactly Fuller's curve P = (d/d_max)^q (Eq. 11) inside the class.
 * A *discrete* class (Meier) has one diameter d_rep for all its grains. */
#ifndef PK_PSD_H
#define PK_PSD_H

#include <stddef.h>
#include <stdint.h>

#include "core/base/rng.h"

#define PK_PSD_MAX_CLASSES 256

typedef struct pk_size_class {
    double d_lo, d_hi;    /* class bounds, d_lo < d_hi (continuous mode) */
    double d_rep;         /* representative diameter (discrete mode): Meier's lower sieve */
    double mass_fraction; /* share of the *whole* curve's mass, 0..1 */
    double beta;          /* in-class mass CDF exponent (0 = log-linear) */
} pk_size_class;

typedef struct pk_grading {
    int nclass;
    pk_size_class cls[PK_PSD_MAX_CLASSES]; /* coarse → fine */
    double mass_below; /* fraction of the whole curve finer than the finest class (not modelled) */
} pk_grading;

/* Error text for the last failing call of this module (static, thread-local
 * storage; not cleared by successful calls).  Conventions on bad input (NULL,
 * NaN, dim not 2/3, invalid classes ...): int functions return -1, double
 * functions return NaN, pk_discrete_nop_min returns 0, void functions fill
 * their output with zeros (when its length is known); all set this text. */
const char *pk_psd_error(void);

/* Validate a grading (e.g. one filled in by hand): 1..PK_PSD_MAX_CLASSES
 * classes, finite 0 < d_lo <= d_hi, d_rep > 0, finite β, mass fractions in
 * [0,1], Σ mass_fraction + mass_below <= 1.  0 if valid, else -1.  Every
 * function taking a pk_grading runs this check first. */
int pk_grading_check(const pk_grading *g);

/* ---- building gradings (return 0 on success, -1 with pk_psd_error()) ---- */

/* Sieve curve: sizes ascending, passing in percent (0..100), non-decreasing,
 * last value 100.  Classes between consecutive sieves, β = 0.  The material
 * passing the smallest sieve becomes mass_below.  Also sets d_rep = d_lo. */
int pk_grading_from_sieve(pk_grading *g, const double *sizes, const double *passing_percent, int n);

/* Discrete classes (Meier Table I/II): one diameter each with a volume share
 * (any positive scale; normalised).  With density != NULL the shares are mass
 * shares and volume_i ∝ share_i / density_i.  Classes are re-sorted coarse →
 * fine; d_lo = d_hi = d_rep = d (continuous sampling of such a class returns d). */
int pk_grading_from_classes(pk_grading *g, const double *d, const double *share,
                            const double *density, int n);

/* Fuller curve P(d) = (d/d_max)^q on [d_floor, d_max] as one exact class
 * (β = q); mass_below = (d_floor/d_max)^q.  0 < q < 1, 0 < d_floor < d_max. */
int pk_grading_from_fuller(pk_grading *g, double q, double d_max, double d_floor);

/* DIN 1045-2 presets "A8","B8","C8","A16","B16","C16","A32","B32","C32"
 * (sieve curves, % passing at 0.25 … 31.5 mm). */
int pk_grading_preset(pk_grading *g, const char *name);

/* Cumulative mass fraction passing d, F_m(d) (0..1), from the class laws. */
double pk_grading_passing(const pk_grading *g, double d);

/* Keep only material with d >= d_min (a class that straddles d_min is cut
 * with its own in-class law); cut material moves to mass_below.  Eq. (14).
 * Then φ_eff = φ_M·(1 − mass_below) (Eqs. 16–17).  A discrete class is kept
 * whole if d_rep >= d_min, else moved whole.  Errors: d_min >= d_max (nothing
 * left), or d_min below the finest modelled size while mass_below > 0 (that
 * material is not resolved, e.g. < 0.25 mm for the DIN presets).
 * pk_grading_passing reports mass_below for every 0 < d below the finest class. */
int pk_grading_truncate(pk_grading *g, double d_min);

/* ---- continuous in-class sampling (Titscher) ---- */

/* Number CDF of one class in dimension dim (2: grain measure ∝ d², 3: ∝ d³);
 * Eq. (8) for dim = 3, β = 0. */
double pk_class_number_cdf(const pk_size_class *c, int dim, double d);
/* Inverse of the above, Eq. (10) for dim = 3, β = 0. */
double pk_class_sample(const pk_size_class *c, int dim, double u);
/* Expected number of grains of a class holding solid measure `measure`
 * (closed form of Eq. 6 generalised). */
double pk_class_expected_count(const pk_size_class *c, int dim, double measure);

/* Expected total count when the whole curve (before truncation) has solid
 * measure `total_measure` = φ_M·V.  counts[] (may be NULL) receives per-class values. */
double pk_grading_expected_count(const pk_grading *g, int dim, double total_measure,
                                 double *counts);

/* Sizes drawn for a packing. */
typedef struct pk_sizes {
    size_t n;
    double *d;        /* diameters, sorted descending (largest first) */
    int32_t *species; /* class index of each grain */
} pk_sizes;

void pk_sizes_free(pk_sizes *s);

/* Algorithm 1 (take phase) with cumulative targets, coarse → fine: draw until
 * the resolved solid measure reaches `resolved_measure` (= φ_eff·V) split by
 * class mass; the overshoot of each class is taken off the next.
 * max_n bounds memory (returns -1 if exceeded). */
int pk_sample_by_measure(const pk_grading *g, int dim, double resolved_measure, pk_rng *rng,
                         size_t max_n, pk_sizes *out);

/* Exactly n grains: class chosen by expected number share, size by Eq. (10). */
int pk_sample_by_count(const pk_grading *g, int dim, size_t n, pk_rng *rng, pk_sizes *out);

/* ---- discrete classes (Meier) ---- */

/* Particle share per class, Meier Eq. (12) generalised: ∝ share_i / d_rep^dim. */
void pk_discrete_number_shares(const pk_grading *g, int dim, double *share);
/* Minimum count so that every class with mass gets one grain, Eq. (13), ceiling. */
size_t pk_discrete_nop_min(const pk_grading *g, int dim);
/* Largest-remainder (Hamilton) apportionment of nop over the classes:
 * reproduces Meier's Tables I and II exactly. */
void pk_discrete_counts(const pk_grading *g, int dim, size_t nop, size_t *counts);
/* Grains with d = d_rep: counts from pk_discrete_counts (nop given), sorted descending. */
int pk_sample_discrete(const pk_grading *g, int dim, size_t nop, pk_sizes *out);

/* Measure of the grains in a pk_sizes set (Σ area or volume). */
double pk_sizes_measure(const pk_sizes *s, int dim);

#endif
