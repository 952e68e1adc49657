/* h5_units.h — the unit strings of packd's results (H5MD units module:
 * SI symbols, space-separated factors with signed powers, "N mm-2").
 * Lengths are the job's (pack: its `unit`; homogenize: the RVE file's),
 * forces N (E_n is read as N per length unit), times s. */
#ifndef PK_H5_UNITS_H
#define PK_H5_UNITS_H

typedef struct pk_units {
    int dim;
    char length[32];    /* "mm" */
    char area[40];      /* "mm+2" */
    char volume[40];    /* "mm+3": the measure of a box of dim dimensions */
    char stiffness[48]; /* "N mm-1" (E_n, E_t) */
    char stress[48];    /* force per length^(dim-1): "N mm-2" in 3D, "N mm-1" in 2D */
    char energy[48];    /* "N mm" */
    /* the plane-strain continuum (fe2's macro problem), per unit thickness:
     * a stress is force per area "N mm-2" (the 2D RVE's "N mm-1" over a
     * slab one length unit thick: the same number), a force per thickness
     * "N mm-1" */
    char plane_stress[48];
    char force_per_thickness[48];
} pk_units;

/* Units for lengths in `length` (NULL or "" : no length unit known, every
 * dimensional figure then goes without one) in dim dimensions. */
void pk_units_init(pk_units *u, const char *length, int dim);

/* The unit of an observable written from a JSON record (its name under
 * /observables, "edmd/delta_d_reached", "homogenize/P"), or NULL when it is
 * dimensionless or a count.  ctx: a pk_units.  A pk_h5_unit_fn.  fe2's
 * datasets are named so too ("fe2/piola_stress", "fe2/mesh/nodes"). */
const char *pk_units_of(const char *name, const void *ctx);

#endif
