/* edmd.h — event-driven growth packing (Lubachevsky–Stillinger; Titscher & Unger §5).
 *
 * Hard disks/spheres fly freely and grow linearly, ρ_i(t) = a_i + g_i t
 * (simulated radius, shell Δd/2 included); collisions follow one of the
 * pk_edmd_rule rules below (all momentum-conserving except Meier's Eq. 9),
 * walls reflect in the co-moving sense.  Engine: delayed
 * states (each particle stores its position at its own last update time),
 * one pending event per particle (and its runner-up, taken without a new
 * prediction when the first is invalidated; Donev) in a calendar queue of
 * time slots (Paul 2007: O(1) per event) with validity counters, pair times of four neighbours at once (AVX2 when the
 * CPU has it, bit-identical to the scalar loop),
 * Donev-style per-particle neighbour lists (bounding spheres filed in the
 * dense cell levels of core/space/grid_uniform.h; skins shrink with the pressure
 * near jamming), periodic re-basing of the clock.
 *
 * The true radius output is R_i(t) = ρ_i(t) − h(t), h the shell; every
 * surface gap of the result is therefore ≥ Δd (2h) and every wall clearance
 * ≥ Δd/2. */
#ifndef PK_EDMD_H
#define PK_EDMD_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"
#include "core/base/progress.h"
#include "core/base/stop_reason.h"
#include "core/rsa/rsa.h" /* pk_rsa_stats of the RSA start */

typedef enum pk_edmd_growth {
    /* d_i(t) = d_i·s(t), s' = γ, d_i the FINAL diameter: size ratios exact (Meier,
     * Titscher §6.2; Titscher's γ of Eq. 30 is relative to δ·d_i, i.e. ours/δ) */
    PK_EDMD_GROW_RELATIVE = 0,
    PK_EDMD_GROW_SHELL /* true radii fixed, the Δd/2 shell grows at γ·d̄/2 (Titscher §6.3/6.4) */
} pk_edmd_growth;

typedef enum pk_edmd_until {
    PK_EDMD_UNTIL_TARGET = 0, /* stop exactly at the target (φ, sizes or Δd) */
    PK_EDMD_UNTIL_JAMMED      /* grow on until a jamming criterion holds */
} pk_edmd_until;

/* Pair collision rules.  w = normal separation speed of the centres,
 * G = g_i + g_j the growth of the contact distance; at contact the gap
 * closes (w ≤ G).  Every rule leaves the gap opening afterwards. */
typedef enum pk_edmd_rule {
    /* Elastic in the frame of the growing surfaces (Lubachevsky–Stillinger,
     * Donev): the gap rate is reversed, w' = 2G − w (+ε_v).  Every
     * collision separates the pair at the speed it approached, so near
     * jamming no pair is left touching: the reduced pressure rises to
     * 10^12 instead of collapsing into event storms. */
    PK_EDMD_RULE_ELASTIC = 0,
    /* Elastic reversal, then the smallest lift w' = max(−w, G + ε_v): a
     * pair approaching slower than G leaves at ε_v (restitution 0 in the
     * growing frame; clusters of such pairs collide at vanishing intervals
     * near jamming).  A user's choice: its cost, docs/perf/edmd.md. */
    PK_EDMD_RULE_LIFT,
    /* Meier–Kuhl–Steinmann 2007 Eq. (9) (dissertation Eq. 3.9): equal-mass
     * swap of the normal speeds, then i loses g_i and j gains g_j, so the
     * pair gains g_i + g_j at every collision (w' = |w| + G); momentum is
     * not conserved when g_i ≠ g_j. */
    PK_EDMD_RULE_MEIER
} pk_edmd_rule;

typedef struct pk_edmd_params {
    pk_edmd_growth growth;
    pk_edmd_until until;
    int start_zero;     /* 1: radii from 0 at random positions (Meier); 0: positions given */
    double delta;       /* start size fraction δ (relative growth from given positions) */
    double phi_target;  /* >0: relative growth stops when φ(true radii) = this */
    double delta_d;     /* minimum surface gap Δd (shell Δd/2); SHELL+TARGET grows it to this */
    double growth_rate; /* γ: d(diameter)/dt of a mean grain over the rms speed per axis */
    double p_max;       /* reduced pressure criterion (e.g. 1e12) */
    double jam_rate_factor; /* until jammed: the growth rate × this once p > 10^3 (1 = constant) */
    double dphi_crit;       /* Meier Eq. 3.11: Δφ over c events below this => jammed (0 = off) */
    uint64_t dphi_events;   /* c (0 = number of grains) */
    double stall_growth;    /* stall: relative size growth γ·Δt over the window below this;
                                * NAN = the default: 1e-12, and until jammed also below
                                * 1e-2·γ/p of the window's pressure p (a packing at p grows
                                * ~γ/p per window: the stall never preempts the pressure stop) */
    uint64_t stall_events;  /* window of the stall detector (Titscher: 1000; at least N) */
    pk_edmd_rule rule;      /* pair collision rule */
    int rescale;            /* 1: hold the kinetic energy near its start value */
    double rescale_tol;     /* rescale when K leaves [K0/(1+tol), K0(1+tol)] */
    double skin;            /* neighbour-list skin as a fraction of a radius */
    int equal_masses;       /* 1: m_i = 1 (Meier); 0: m_i ∝ final volume */
    uint64_t max_events;    /* 0 = unlimited */
    uint64_t seed;          /* velocities: stream 2; zero-start positions: stream 3 */
    struct pk_edmd_checkpoint
        *checkpoint; /* snapshots / resume (core/edmd/edmd_checkpoint.h); NULL = none */
} pk_edmd_params;

/* Defaults documented in docs/job-format.md. */
void pk_edmd_params_default(pk_edmd_params *prm);

typedef enum pk_edmd_criterion {
    PK_EDMD_CRIT_NONE = 0,
    PK_EDMD_CRIT_TARGET,
    PK_EDMD_CRIT_PRESSURE,
    PK_EDMD_CRIT_DELTA_PHI,
    PK_EDMD_CRIT_STALL,
    PK_EDMD_CRIT_MAX_EVENTS,
    PK_EDMD_CRIT_CANCEL,
    PK_EDMD_CRIT_WALL_TIME,
    PK_EDMD_CRIT_ERROR
} pk_edmd_criterion;
const char *pk_edmd_criterion_name(pk_edmd_criterion c);

#define PK_EDMD_HIST_MAX 512

typedef struct pk_edmd_stats {
    pk_stop_reason reason;
    pk_edmd_criterion criterion;
    double phi;              /* φ of the true radii at the stop */
    double phi_sim;          /* φ of the simulated (shell) radii */
    double pressure;         /* reduced pressure PV/NkT of the last window */
    double phi_jam_estimate; /* φ/(1 − d/p) */
    double delta_d;          /* gap guaranteed at the stop (2 h) */
    double t_stop, t_end;    /* simulated times (unit d̄/u) */
    double seconds;
    uint64_t events, pair, wall, nlist, invalid, rescales, rebases, overlaps;
    uint64_t growth_changes; /* growth-rate reductions of the jamming schedule */
    uint64_t resorts;        /* renumberings along the Z-order (large N) */
    uint64_t second;         /* invalid events replaced by their runner-up (no prediction) */
    double max_overlap_rel;  /* largest overlap seen by the predictor, relative to R */
    double kinetic_ratio;    /* K/K0 at the stop (grows without rescaling) */
    size_t nhist;            /* φ(t) history: events, time, φ, p */
    double hist_events[PK_EDMD_HIST_MAX], hist_t[PK_EDMD_HIST_MAX];
    double hist_phi[PK_EDMD_HIST_MAX], hist_p[PK_EDMD_HIST_MAX];
} pk_edmd_stats;

/* Run the packing.  p holds n grains with their TARGET true radii (and
 * positions unless prm->start_zero); on return it holds the final positions
 * (wrapped) and true radii.  0 when the run ended cleanly (st->reason),
 * -1 on bad input or allocation failure. */
int pk_edmd_run(const pk_box *b, pk_particles *p, const pk_edmd_params *prm, pk_monitor *mon,
                pk_edmd_stats *st);

/* Start configuration by RSA at reduced size δ·d with gap Δd (Titscher
 * §6.2/§6.3; Kansal): appends to p the grains with their TARGET radii d/2 at
 * the RSA positions.  Returns 0 and the RSA stats; rs->placed < n when RSA
 * could not place all of them. */
int pk_edmd_start_rsa(const pk_box *b, const double *d, const int32_t *species, size_t n,
                      double delta, double delta_d, uint64_t seed, pk_monitor *mon, pk_particles *p,
                      pk_rsa_stats *rs);

/* The default RSA start of relative growth (Titscher §6.2, Kansal): RSA
 * fills PK_EDMD_START_PHI of the box, well below its saturation (3D equal
 * spheres 0.384, 2D disks 0.547), so it places every grain in a fraction of
 * the EDMD run's time, and the dilute flights of a start from zero radii —
 * a list rebuild every ~3 events — are skipped (bench/edmd …_rsa030: the
 * jammed packing in 24–32 % less time, at the same or a higher φ). */
#define PK_EDMD_START_PHI 0.30
#define PK_EDMD_START_DELTA_MAX 0.9 /* Titscher §6.2's δ: never closer to the target */

/* δ of that start: the largest δ <= PK_EDMD_START_DELTA_MAX at which the
 * start's spheres (radius δ·d_i/2 + Δd/2, the shell included) fill at most
 * phi_start of the box measure (area in 2D, volume in 3D).  The filled
 * measure is a polynomial in δ (moments of d), solved by bisection.
 * Returns 0 when even δ → 0 overfills (the shells alone exceed phi_start). */
double pk_edmd_start_delta(int dim, const double *d, size_t n, double delta_d, double box_measure,
                           double phi_start);

#endif
