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

/* What an observable measures; PK_U_NONE: a count, a ratio, a flag or in
 * reduced units (EDMD's time, d̄/u). */
typedef enum {
    PK_U_NONE,
    PK_U_LENGTH,
    PK_U_AREA,
    PK_U_VOLUME,
    PK_U_STIFFNESS,
    PK_U_STRESS,
    PK_U_ENERGY,
    PK_U_FORCE,
    PK_U_SECONDS,
    PK_U_HERTZ,
    PK_U_PLANE_STRESS,
    PK_U_FORCE_PER_THICKNESS
} pk_unit_kind;

/* The unit string of kind in u, or NULL (PK_U_NONE, or a length-based kind
 * without a length unit). */
const char *pk_unit_string(const pk_units *u, pk_unit_kind kind);

/* One row of an owner's unit table: an observable's name (relative to the
 * owner's group under /observables) and its kind.  Tables end with {NULL}. */
typedef struct pk_unit_row {
    const char *name;
    pk_unit_kind kind;
} pk_unit_row;

/* The unit of name in rows (NULL-terminated) with u, or NULL when the table
 * does not list it. */
const char *pk_unit_in(const pk_unit_row *rows, const char *name, const pk_units *u);

#endif
