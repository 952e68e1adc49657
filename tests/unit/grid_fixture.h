/* grid_fixture.h — the Fuller-like scene of the grid tests (static helper;
 * include once per test binary): many fines and few coarse grains, counts
 * ∝ d^-2.5 over 1:16 as in the Fuller-like EDMD case, so the coarse levels
 * of a pk_ugrid are covered (grid_uniform.h). */
#ifndef PK_GRID_FIXTURE_H
#define PK_GRID_FIXTURE_H

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "core/space/box.h"
#include "core/space/particles.h"
#include "core/base/rng.h"

/* Box of edges 24, 26, 28 (3D) or 14, 16 (2D) with the given periodicity
 * and 700 (3D) or 300 (2D) grains at uniform positions, radii by the inverse
 * CDF of d^-2.5 on [1, 16] (0.25 .. 4); the same seed gives the same scene.
 * rng is left after the scene's draws. */
static inline void fuller_scene(int dim, const bool periodic[3], uint64_t seed, pk_box *b,
                                pk_particles *p, pk_rng *rng)
{
    memset(b, 0, sizeof *b);
    b->dim = dim;
    for (int k = 0; k < dim; k++) {
        b->L[k] = (dim == 3 ? 24.0 : 14.0) + 2 * k;
        b->periodic[k] = periodic[k];
    }
    const size_t n = dim == 3 ? 700 : 300;
    pk_particles_init(p, dim, n);
    pk_rng_seed(rng, seed, 9);
    for (size_t i = 0; i < n; i++) {
        double x[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++)
            x[k] = pk_rng_range(rng, 0, b->L[k]);
        double u = pk_rng_range(rng, 0, 1);
        pk_particles_push(p, x, 0.125 * pow(1 - u * (1 - pow(16, -1.5)), -1 / 1.5), 0);
    }
}

#endif
