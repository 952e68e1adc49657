/* particles.h — the one particle array every placer and solver shares.
 * RSA, EDMD, tet filling and DEM all read and write this struct, and the
 * result writer takes it as is.  Positions are stored with stride 3 even in
 * 2D (z = 0) so that one code path serves both dimensions. */
#ifndef PK_PARTICLES_H
#define PK_PARTICLES_H

#include <stddef.h>
#include <stdint.h>

typedef struct pk_particles {
    int dim;          /* 2 or 3 */
    size_t n;         /* particles in use */
    size_t cap;       /* allocated */
    double *x;        /* [cap][3] centres */
    double *r;        /* [cap] radii */
    int32_t *species; /* [cap] size-class index (0 = coarsest) */
} pk_particles;

/* 0 on success, -1 on allocation failure.  Starts empty with capacity cap. */
int pk_particles_init(pk_particles *p, int dim, size_t cap);
void pk_particles_free(pk_particles *p);
/* Grow capacity to at least cap (keeps content). */
int pk_particles_reserve(pk_particles *p, size_t cap);
/* Append one particle; returns its index or (size_t)-1 on allocation failure. */
size_t pk_particles_push(pk_particles *p, const double *x, double r, int32_t species);

/* Sum of particle measures (areas in 2D, volumes in 3D). */
double pk_particles_solid_measure(const pk_particles *p);

#endif
