/* tetfill_tangent_internal.h — what tests/unit/test_tetfill_tangent.c checks
 * inside the tangent-sphere solver (tetfill_tangent.c); not part of the
 * folder's entry points. */
#ifndef PK_TETFILL_TANGENT_INTERNAL_H
#define PK_TETFILL_TANGENT_INTERNAL_H

/* det A of Eq. 6 for the tetrahedron c[0..3]. */
double pk_tangent_det(const double c[4][3]);

#endif
