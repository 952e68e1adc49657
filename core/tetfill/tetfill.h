/* tetfill.h — fill a tetrahedral mesh with spheres: Jerier et al. (2010)
 * geometric method (Jerier et al. 2010 §2).
 *
 * Steps, in the paper's order (§2.2, Fig. 1):
 *   2–3  spheres on the mid-edges (r = ℓ/8) and nodes (r = ℓ_s, the shortest
 *        adjacent edge, as the paper prints it; the spec's "garble, use ℓ_s/4"
 *        overlooks that the clamp below makes r = ℓ_s a random radius in the
 *        range, no overlap), radii clamped to the range (over r_max: uniform in
 *        the range; under r_min: r_min), then radii of overlapping pairs reduced
 *        until every overlap is within ε·r_min; spheres under r_min removed;
 *   7a   spheres crossing the boundary by more than ε·r_min removed (done
 *        here, before 4–6, because every later candidate is tested against
 *        the boundary faces anyway; `trim_after_loci` keeps the paper's
 *        order: steps 4–6 then see no boundary — candidates need only a
 *        centre in the bounding box — and the state "after steps 1–6" the
 *        paper describes, N ≈ 10 N_t, still holds the spheres 7a removes);
 *   4–6  the geometric procedure (tetfill_tangent.h) at loci: face
 *        barycentres, tet barycentres, and the points between barycentre and
 *        nodes (weight `vertex_weight`, paper: midway = 0.5);
 *   7b   densification ("in search of void spaces"): passes over the active
 *        tets, one random locus in the empty space per tet per pass; a tet
 *        retires after 16 visits in a row that add nothing, so the work is
 *        linear (<= spheres added + 16·tets visits) and the passes end by
 *        themselves at saturation ("until no more sphere can be added"), or
 *        after two passes that add nothing, `max_passes`, or the stop target.
 *        (The paper locates the voids with a Delaunay triangulation of the
 *        centres; packd uses random loci per mesh tet instead — same solve,
 *        same acceptance — which keeps the cost linear and needs no
 *        triangulation; docs/tetfill.md weighs the difference.  The
 *        three-sphere fallback below is not tried in 7b.)
 *
 * Each locus: the `neighbours` spheres nearest by surface distance (a
 * core/space/grid.h query), plus the boundary planes in reach as virtual spheres
 * of radius 100·ℓ_mean tangent to the outside of the face (Fig. 2), are
 * combined four at a time in lexicographic order (at most `max_combos`).  A
 * root is accepted if r ∈ [r_min, r_max], its centre lies in the mesh, and,
 * after reducing the radius so that no overlap with a sphere or a boundary
 * face exceeds ε·r_min ("in last resort", §2.1), still r >= r_min and it
 * touches at least z_min spheres or boundary faces (gap <= τ,
 * τ = max(ε r_min, 1e-9 r_min); with the contact rule
 * "touching", gap <= 0 as in Jerier's own code, see below).
 *
 * packd addition (not in the paper): when the four-sphere root exceeds r_max
 * (a hole bigger than the range allows — with ℓ ≈ 8 r̄ this is the rule, not
 * the exception, for R <= 3) and z_min <= 3, a sphere of radius r_max tangent
 * to three of the four is tried (trilateration), the "radius decreased in
 * last resort" of §2.1 done so that it keeps three contacts.
 *
 * The mesh must be checked
 * (pk_mesh_check) and translated so that its bounding box starts at 0. */
#ifndef PK_TETFILL_H
#define PK_TETFILL_H

#include <stddef.h>
#include <stdint.h>

#include "core/mesh/mesh.h"
#include "core/space/particles.h"
#include "core/base/progress.h"
#include "core/base/stop_reason.h"
#include "tetfill_stats.h"

/* What counts as a contact in the z_min test of a candidate.
 *   TANGENT  gap <= τ: every tangency the solve constructs (default);
 *   TOUCHING gap <= 0, no tolerance: Jerier's own code (YADE SpherePadder,
 *            place_fifth_sphere: distance <= 0).  A solved tangency lands on
 *            either side of 0 by round-off, so a candidate needs z_min of
 *            its tangencies to round to the overlapping side: about 30 %
 *            fewer spheres, and z (gap <= 0) ≈ 5 after steps 1–6 — the state
 *            Jerier reports (docs/tetfill.md). */
typedef enum pk_tetfill_contact_rule {
    PK_TETFILL_CONTACT_TANGENT = 0,
    PK_TETFILL_CONTACT_TOUCHING = 1
} pk_tetfill_contact_rule;

typedef struct pk_tetfill_params {
    double r_min, r_max;
    double eps;                           /* maximum overlap rate ε: δ_max = ε r_min */
    int z_min;                            /* minimum contacts of an inserted sphere (2, 3, 4) */
    pk_tetfill_contact_rule contact_rule; /* the contact of the z_min test */
    double phi_target;                    /* stop at this solid fraction (0 = none) */
    size_t n_target;                      /* stop at this many spheres (0 = none) */
    uint64_t seed;                        /* loci order and random radii: streams 0, 1 */
    double vertex_weight;                 /* step 6 locus = centroid + w (node − centroid) */
    int skip_tet_loci;                    /* skip steps 5–6 (Jerier's loose packings) */
    int trim_after_loci;                  /* the paper's order: 7a after 4–6 (see above) */
    int densify;                          /* run step 7b */
    int neighbours;                       /* nearest spheres combined per locus (4..12) */
    int max_combos;                       /* four-sphere sets tried per locus */
    int max_passes;                       /* densification passes */
    size_t max_spheres;                   /* hard limit (0 = none) */
} pk_tetfill_params;

/* Defaults: ε = 1e-4 (YADE), z_min = 3, contact rule tangent, w = 0.5,
 * neighbours 8, 30 combos, 1000 passes (7b ends at saturation well before),
 * densify on. */
void pk_tetfill_defaults(pk_tetfill_params *prm);

typedef struct pk_tetfill_stats {
    pk_stop_reason reason;
    size_t n_direct;            /* after steps 2–3 and overlap reduction */
    size_t n_trimmed;           /* removed at the boundary (7a) */
    size_t n_geometric;         /* after steps 4–6 (before 7a with trim_after_loci) */
    double phi_geometric;       /* solid fraction after steps 4–6 */
    pk_tetfill_coord geometric; /* coordination after steps 1–6 (before 7b) */
    size_t n_final;
    double phi; /* final solid fraction (Σ V_i / V_mesh) */
    size_t loci, solves, singular, accepted, accepted_three;
    int passes;
    double seconds, seconds_geometric;
} pk_tetfill_stats;

/* Fill m (checked, box at 0) into p (initialised, dim 3, appended to).
 * 0 when the run ended (reason in st), -1 on invalid parameters or memory. */
int pk_tetfill(const pk_mesh *m, const pk_tetfill_params *prm, pk_monitor *mon, pk_particles *p,
               pk_tetfill_stats *st);

#endif
