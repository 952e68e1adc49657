/* edmd_rigidity.h — is the backbone of a hard-sphere packing rigid?
 *
 * Two tests on the non-rattlers of a contact network (edmd_contacts.h):
 *  - the Maxwell count: a jammed backbone of N_b grains needs at least
 *    dim·N_b − T + 1 contacts (wall contacts included), T the trivial modes
 *    (one translation per periodic axis); periodic 2D: 2(N_b − 1) + 1
 *    (O'Hern et al. 2003, the isostatic count N_c = d(N' − 1) + 1);
 *  - first-order rigidity: the stiffness K = Σ_c n_c n_cᵀ of unit normal
 *    springs on the contacts (walls fixed) is positive definite once the T
 *    translations are pinned, i.e. no motion of the backbone other than a
 *    rigid translation leaves every contact distance unchanged to first
 *    order (Donev, Torquato et al. 2004: collective jamming).  A backbone
 *    that passes is jammed in its box; one that fails has floppy modes
 *    (e.g. fines wedged between grains that are themselves free to move).
 * The sparse factorisation comes from api/ (core/base/sparse.h). */
#ifndef PK_EDMD_RIGIDITY_H
#define PK_EDMD_RIGIDITY_H

#include <stddef.h>

#include "core/base/sparse.h"
#include "core/space/box.h"
#include "core/space/particles.h"
#include "edmd_contacts.h"

typedef struct pk_rigidity {
    size_t backbone;    /* grains tested (non-rattlers) */
    size_t contacts;    /* their contacts, wall contacts included */
    size_t maxwell_min; /* dim·N_b − trivial + 1 (0 when there is no backbone) */
    int trivial;        /* translations along periodic axes */
    int tested;         /* 1: the stiffness was factorised (the count held) */
    size_t floppy;      /* zero (or negative) pivots: modes beyond the trivial ones */
    int rigid;          /* 1: the count holds and the stiffness is positive definite */
} pk_rigidity;

/* 0 on success (rg filled), -1 on allocation or solver failure. */
int pk_rigidity_test(const pk_box *b, const pk_particles *p, const pk_contact_network *net,
                     const pk_contact_stats *cs, const pk_sparse_solver *solver, pk_rigidity *rg);

/* Certify a finished packing: the contact network at tolerance tol0 (the
 * pressure's, pk_contact_tolerance) and, while its backbone is not rigid, at
 * ten times it, up to PK_JAM_TOL_MAX.  A packing compressed to p = 10¹² can
 * keep a few contacts that the growth has not yet closed (3D mono N = 10³:
 * 2848 of the 2881 contacts at gaps < 10⁻⁸, rigid with 2889 at < 10⁻⁴): rigid
 * at tol it is jammed to within a gap of tol·(r_i + r_j), far below any
 * elastic overlap a DEM model of the grains would carry.  *tol_used: the
 * tolerance of the verdict (rigid: the first that held; else tol0, whose
 * figures are reported).  delta_d, wall_gap: as pk_contact_network_compute.
 * 0 or -1 (allocation or solver failure). */
#define PK_JAM_TOL_MAX 1e-4
int pk_jam_certify(const pk_box *b, const pk_particles *p, double delta_d, double wall_gap,
                   double tol0, const pk_sparse_solver *solver, pk_contact_stats *cs,
                   pk_rigidity *rg, double *tol_used);

#endif
