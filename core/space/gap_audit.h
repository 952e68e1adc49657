/* gap_audit.h — an exact check of a finished packing, independent of the
 * placers' own neighbour structures (its own multi-level cell grid, minimum
 * image; gap_audit.c).
 * Every placer's result goes through it before it is written, so the
 * "smallest gap" in a result file is a measurement, not a promise. */
#ifndef PK_GAP_AUDIT_H
#define PK_GAP_AUDIT_H

#include <stddef.h>

#include "box.h"
#include "particles.h"

typedef struct pk_gap_report {
    double min_gap;     /* smallest surface gap over pairs closer than `horizon` (else = horizon) */
    size_t min_pair[2]; /* the pair that has it (or SIZE_MAX) */
    double min_wall_gap;  /* smallest grain–wall clearance over walled axes (INFINITY if none) */
    size_t pairs_below;   /* pairs with gap < required - tol */
    size_t walls_below;   /* grains with wall clearance < required/2 - tol */
    size_t pairs_checked; /* pairs closer than the last pass's horizon (gap_audit.c) */
} pk_gap_report;

/* required: Δd; tol: absolute tolerance for the "below" counts; horizon:
 * pairs whose gap exceeds it are not examined (pass e.g. max(Δd, r_max)).
 * Returns 0, or -1 on allocation failure. */
int pk_gap_audit(const pk_box *b, const pk_particles *p, double required, double tol,
                 double horizon, pk_gap_report *rep);

#endif
