/* particles.c — the shared particle array (positions, radii, species).
 * Contract: core/space/particles.h. */
#include "particles.h"

#include <stdlib.h>
#include <string.h>

#include "core/base/grow.h"

#include "box.h"

int pk_particles_init(pk_particles *p, int dim, size_t cap)
{
    memset(p, 0, sizeof *p);
    p->dim = dim;
    return pk_particles_reserve(p, cap ? cap : 16);
}

void pk_particles_free(pk_particles *p)
{
    free(p->x);
    free(p->r);
    free(p->species);
    memset(p, 0, sizeof *p);
}

int pk_particles_reserve(pk_particles *p, size_t cap)
{
    if (cap <= p->cap)
        return 0;
    const pk_grow_item arrays[] = {PK_GROW_ITEM(p->x, 3), PK_GROW_ITEM(p->r, 1),
                                   PK_GROW_ITEM(p->species, 1)};
    if (pk_grow(arrays, 3, cap) != 0)
        return -1;
    p->cap = cap;
    return 0;
}

size_t pk_particles_push(pk_particles *p, const double *x, double r, int32_t species)
{
    if (p->n == p->cap && pk_particles_reserve(p, p->cap * 2) != 0)
        return (size_t)-1;
    size_t i = p->n++;
    p->x[3 * i] = x[0];
    p->x[3 * i + 1] = x[1];
    p->x[3 * i + 2] = p->dim == 3 ? x[2] : 0.0;
    p->r[i] = r;
    p->species[i] = species;
    return i;
}

double pk_particles_solid_measure(const pk_particles *p)
{
    double s = 0;
    for (size_t i = 0; i < p->n; i++)
        s += pk_ball_measure(p->dim, p->r[i]);
    return s;
}
