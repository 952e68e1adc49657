/* dem_rattler.h — rattler removal (Meier 2009 §4.3.5, Table 4.3 generalised
 * to 2D and 3D).  A free grain is jammed iff the directions of its contacts
 * with jammed or prescribed neighbours positively span R^dim, i.e. no closed
 * half-plane / hemisphere holds them all (Remark 4.6; in 2D its largest-gap form, which also covers the 180° and 4×90° special cases).
 * Removal is iterated to the fixed point: a rattler's contacts no longer
 * count for its neighbours. */
#ifndef PK_DEM_RATTLER_H
#define PK_DEM_RATTLER_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"

/* 1 if unit vectors n[k] (stride 3, k < m) positively span R^dim (tol on
 * the hemisphere test, e.g. 1e-9). */
int pk_dem_positively_spanning(const double *n, size_t m, int dim, double tol);

/* rattler[i] = 1 for free grains (is_free[i] != 0) that are not jammed under
 * the contacts of the last pk_dem_eval; 0 otherwise.  Returns the number of
 * rattlers, or (size_t)-1 on allocation failure. */
size_t pk_dem_rattlers(const pk_dem_pairs *c, int dim, size_t np, const uint8_t *is_free,
                       uint8_t *rattler);

#endif
