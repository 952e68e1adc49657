/* dem_kblocks.h — the contact stiffness K = ∂²Φ_n/∂x∂x (4.11)–(4.14) as a
 * compact list of blocks for repeated products K·v on one mask (the Lanczos
 * estimate of λ_min in dynamic relaxation runs 40 of them per refresh):
 * only the contacts that touch a masked grain, each with its coefficients
 * k_ij·d = a d − b (l·d) l (pk_dem_kblock_coef) computed once.  The
 * products equal pk_dem_kv's bit for bit (same operations, same order). */
#ifndef PK_DEM_KBLOCKS_H
#define PK_DEM_KBLOCKS_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"

typedef struct pk_dem_kblocks {
    size_t n;
    int32_t *i, *j;
    uint8_t *side; /* bit 0: i in the mask, bit 1: j in the mask */
    double *l;     /* [n][3] branch vectors */
    double *a, *b;
} pk_dem_kblocks;

/* From the contacts of the last pk_dem_eval on c.  0 / -1 (memory). */
int pk_dem_kblocks_build(pk_dem_kblocks *kb, const pk_dem_pairs *c, double E, const uint8_t *mask);

/* out = K v on the masked particles (v read there only, out 0 elsewhere),
 * = pk_dem_kv(c, dim, np, E, mask, v, out) at the build. */
void pk_dem_kblocks_kv(const pk_dem_kblocks *kb, int dim, size_t np, const double *v, double *out);

void pk_dem_kblocks_free(pk_dem_kblocks *kb);

#endif
