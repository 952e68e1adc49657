/* homog_system.h — the problem every equilibrium solver of core/homog works
 * on (dynamic relaxation, FIRE, the Newton hybrid): the free particles of
 * one load step of the RVE at fixed geometry, Meier 2009 §4.4.  One struct,
 * passed by pointer, instead of its six members in every signature. */
#ifndef PK_HOMOG_SYSTEM_H
#define PK_HOMOG_SYSTEM_H

#include <stddef.h>
#include <stdint.h>

#include "core/dem/dem_contact.h"

typedef struct pk_dem_system {
    pk_dem_pairs *c;      /* the candidate pair list, (re)built by the solvers as needed */
    const pk_dem_geom *g; /* the box under F̄ */
    const double *r;      /* radii [np] */
    size_t np;
    double E;               /* normal contact stiffness E_n (4.3) */
    const uint8_t *is_free; /* [np] 1: the grain relaxes, 0: prescribed (4.24)/(4.27) */
} pk_dem_system;

#endif
