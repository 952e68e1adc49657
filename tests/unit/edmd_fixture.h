/* edmd_fixture.h — set-up shared by the EDMD unit tests. */
#ifndef EDMD_FIXTURE_H
#define EDMD_FIXTURE_H

#include <math.h>
#include <string.h>

#include "core/space/box.h"
#include "core/space/particles.h"

/* The periodic cube (square in 2D) in which the grains of p fill phi. */
static inline pk_box edmd_fixture_periodic_box(const pk_particles *p, double phi)
{
    pk_box b;
    memset(&b, 0, sizeof b);
    b.dim = p->dim;
    double vol = 0;
    for (size_t i = 0; i < p->n; i++)
        vol += pk_ball_measure(p->dim, p->r[i]);
    for (int k = 0; k < b.dim; k++) {
        b.L[k] = pow(vol / phi, 1.0 / b.dim);
        b.periodic[k] = 1;
    }
    return b;
}

#endif
