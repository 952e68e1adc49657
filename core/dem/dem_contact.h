/* dem_contact.h — soft frictionless contacts between disks/spheres (Meier 2009
 * §4.2, (4.1)–(4.16)): overlap ε = r_i + r_j − |l| (4.1), contact iff ε ≥ 0
 * (4.2), potential Φ = E/2 ε² (4.3), force on i f_ij = −E ε n_ij (4.8),
 * off-diagonal stiffness block k_ij = E/|l| [ε 1 − (r_i+r_j) n⊗n] (4.12)
 * with k_ii = −Σ_j k_ij (4.14).  The same formulas serve 2D and 3D.
 *
 * Geometry: spatial centres x (stride 3) under a macroscopic F̄.  On a
 * periodic RVE the branch vector is the minimum image taken in the reference
 * frame, l = F̄·minimg(F̄⁻¹(x_j − x_i)), i.e. the lattice vectors are F̄L
 * (the simpler equivalent of (4.28)–(4.34)).  Candidate pairs (a Verlet list
 * with a skin) come from the shared pk_grid built on reference coordinates;
 * each keeps the lattice image it had at the build (pk_dem_pairs.sh).
 *
 * Implemented by dem_pairs.c (geometry, candidate list, images), dem_eval.c
 * (the evaluation: dem_eval_loops.c serial and in lanes, dem_eval_par.c
 * threaded) and dem_kv.c (K·v, Gershgorin bound); core/dem/README.md. */
#ifndef PK_DEM_CONTACT_H
#define PK_DEM_CONTACT_H

#include <stddef.h>
#include <stdint.h>

#include "core/base/par.h"

typedef struct pk_dem_geom {
    int dim;
    int periodic; /* 1 = minimum image across the reference box L */
    double L[3];  /* reference box edges (periodic only) */
    double F[9], Finv[9];
} pk_dem_geom;

/* Set F (row-major 3×3; 2D uses the upper 2×2 block with F[8] = 1) and its
 * inverse.  Returns det F (0 = singular, geometry unchanged). */
double pk_dem_geom_set_F(pk_dem_geom *g, const double F[9]);

/* Branch vector l = x_j − x_i (minimum image under F̄L when periodic). */
void pk_dem_branch(const pk_dem_geom *g, const double *xi, const double *xj, double l[3]);

typedef struct pk_dem_pairs {
    size_t n, cap;
    int32_t *i, *j; /* candidate pairs, i < j */
    double *l;      /* [n][3] branch vector x_j − x_i (min image) */
    double *len;    /* |l| */
    double *eps;    /* overlap; contact iff eps >= 0 */
    double *xb;     /* [np][3] positions at the last build (skin test) */
    size_t np;
    double skin;
    /* Pair-specific stiffness (E_n,ij of (4.3)): when kclass != NULL, pair
     * (i, j) has E_n,ij = kmat[kclass[i]·nclass + kclass[j]] and the build
     * fills kf[p] = E_n,ij / kref, the factor on the E the evaluators are
     * given; otherwise every pair has E.  Set with pk_dem_pairs_stiffness
     * before the first build; the arrays stay the caller's. */
    const int32_t *kclass;
    const double *kmat;
    size_t nclass;
    double kref;
    double *kf; /* [n] per-candidate factor, NULL when uniform */
    /* The periodic image of each candidate, fixed at the build: while the
     * grains stay within skin/2 of their build positions and F̄ is the same,
     * a candidate's minimum image cannot change (pk_dem_pairs_build), so the
     * evaluation takes l = x_j − x_i + sh[p] with the lattice shift
     * sh = −F̄(L∘k) in the current frame ([n][3]) instead of F̄⁻¹, rounding
     * and F̄ per pair.  sh_F, sh_L, sh_dim, sh_periodic: the geometry the
     * shifts were formed under; pk_dem_eval forms them afresh at its x when
     * it is given another (a new F̄ on the same list), never uses stale ones. */
    double *sh;
    double sh_F[9], sh_L[3];
    int sh_dim, sh_periodic, sh_ok;
    /* Parallel evaluation: with par != NULL (the caller's pool, core/base/par.h;
     * not freed here, and cleared with the rest by pk_dem_pairs_free)
     * pk_dem_eval and pk_dem_eval_forces share the work of a call with f
     * between the pool's threads (lists of pk_dem_par_min_pairs candidates
     * or more, in pk_dem_pairs_build's order), and give the serial results
     * bit for bit — f, the count, l, |l|, ε, energy, S — for any number of
     * threads (dem_eval_par.c).  The fields below are its own: */
    pk_par *par;
    double *fa;   /* [n][dim] force on i of each candidate, 0 when not in contact */
    int32_t *ord; /* per part P of the grains, its grains k with candidates
                            j = k by their number: ord[bofs[P] .. bofs[P+1]) */
    int32_t *bofs;
    int32_t *jofs, *jq; /* ord[m]'s candidates with j = ord[m], pair order:
                            jq[jofs[m] .. jofs[m+1]) */
    int32_t *iofs;      /* k's own run of candidates: [iofs[k], iofs[k+1]) */
    size_t csr_n, csr_np, csr_pcap, csr_gcap;
    int csr_state, csr_dim, csr_parts; /* state 0 to build, 1 built, −1 the list is
                                          not in build order: serial */
} pk_dem_pairs;

void pk_dem_pairs_free(pk_dem_pairs *c);

/* Pair-specific stiffness by class (see above); kclass == NULL = uniform. */
void pk_dem_pairs_stiffness(pk_dem_pairs *c, const int32_t *kclass, const double *kmat,
                            size_t nclass, double kref);

/* E_n of candidate pair p when the evaluators are given E. */
static inline double pk_dem_pair_E(const pk_dem_pairs *c, size_t p, double E)
{
    return c->kf ? E * c->kf[p] : E;
}

/* Rebuild the candidate list: every pair whose spatial distance can be below
 * r_i + r_j + skin, with its periodic image (sh).  -1 on allocation failure,
 * -2 when a periodic box is too small for the deformed contact range (an
 * image pair could be missed).  The list (and its images) serve evaluations
 * at positions within skin/2 of x (pk_dem_pairs_stale). */
int pk_dem_pairs_build(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                       size_t np, double skin);

/* 1 when some centre moved more than skin/2 since the last build. */
int pk_dem_pairs_stale(const pk_dem_pairs *c, const double *x, int dim);

/* Evaluate every candidate pair at x: fills l, len, eps.  When f != NULL it
 * is overwritten with the particle forces f_i = Σ_j f_ij (4.10); *energy
 * (may be NULL) gets Φ_n (4.7); S (may be NULL, 9 entries) gets the contact
 * sum Σ_c f_ij ⊗ l_ij (each contact once).  Returns the number of contacts. */
size_t pk_dem_eval(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                   size_t np, double E, double *f, double *energy, double S[9]);

/* The forces alone, f and the contact count as pk_dem_eval(.., f, NULL,
 * NULL) bit for bit, but c->l, len, eps may be left as they were (the 2D
 * periodic AVX2 path keeps each block's geometry in L1 buffers instead of
 * writing ~40 B per candidate to the pair arrays): the relaxation
 * iterations' evaluation.  Call pk_dem_eval at x before reading them (the
 * values are a function of x: the same bits as if they had been stored). */
size_t pk_dem_eval_forces(pk_dem_pairs *c, const pk_dem_geom *g, const double *x, const double *r,
                          size_t np, double E, double *f);
/* 1: pk_dem_eval_forces stores the geometry as pk_dem_eval does (tests:
 * the relaxations must give the same bits either way). */
extern int pk_dem_forces_store;
/* The parallel evaluation takes lists of at least this many candidates
 * (default 4096, ~1500 grains: 2 threads gave 1.2x at 4500 candidates and
 * less below, where the hand-over weighs more); tests set 0. */
extern size_t pk_dem_par_min_pairs;

/* The 2D evaluation takes the geometry of four candidates at once with AVX2
 * when the CPU has it (bit-identical to the scalar loop); set
 * pk_dem_scalar_only = 1 to force the scalar loop (tests).  1 when the
 * lanes are in use. */
extern int pk_dem_scalar_only;
int pk_dem_lanes_available(void);

/* The coefficients of a contact's stiffness block (4.12)₁ in the form
 * k_ij·d = a d − b (l·d) l (l = |l| n): a = Eε/|l|, b = ER/|l|³ with
 * R = ε + |l| — two divisions per block. */
static inline void pk_dem_kblock_coef(double E, double len, double eps, double *a, double *b)
{
    double c = E / len;
    *a = c * eps;
    *b = c * (eps + len) / (len * len);
}

/* out = K v on the particles with mask[i] != 0 (the others are held: v = 0
 * there, out = 0 there).  K = ∂²Φ_n/∂x∂x from the last pk_dem_eval. */
void pk_dem_kv(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask,
               const double *v, double *out);

/* Gershgorin bound of the largest eigenvalue of K restricted to mask. */
double pk_dem_gershgorin(const pk_dem_pairs *c, int dim, size_t np, double E, const uint8_t *mask);

#endif
