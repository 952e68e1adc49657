/* edmd_contacts.h — contact network of a finished hard-sphere packing:
 * contacts (surface gap ≤ tol·(r_i + r_j) above the required Δd), rattlers
 * (grains with fewer than dim + 1 contacts to non-rattlers, removed
 * iteratively — the usual local-stability count of jamming studies) and the
 * mean contact number of the backbone.  Uses the shared core/grid.h. */
#ifndef PK_EDMD_CONTACTS_H
#define PK_EDMD_CONTACTS_H

#include <stddef.h>

#include "box.h"
#include "particles.h"

typedef struct pk_contact_stats {
    size_t contacts;          /* pairs in contact */
    size_t rattlers;
    double rattler_fraction;  /* rattlers / n */
    double mean_contacts;     /* mean contact number z of the non-rattlers (2·contacts/n if all rattle) */
} pk_contact_stats;

/* delta_d: the required surface gap (a contact is gap ≤ Δd + tol·(r_i+r_j)).
 * Returns 0 or -1 (allocation failure). */
int pk_contact_stats_compute(const pk_box *b, const pk_particles *p, double delta_d, double tol,
                             pk_contact_stats *cs);

#endif
