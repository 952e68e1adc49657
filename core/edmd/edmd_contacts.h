/* edmd_contacts.h — contact network of a finished hard-sphere packing:
 * contacts (surface gap ≤ tol·(r_i + r_j) above the required Δd; against a
 * wall, clearance ≤ tol·2r_i above the wall gap), rattlers (grains with fewer
 * than dim + 1 contacts to non-rattlers and walls, removed iteratively — the
 * usual local-stability count of jamming studies) and the mean contact
 * number of the backbone.  Uses the shared core/space/grid.h. */
#ifndef PK_EDMD_CONTACTS_H
#define PK_EDMD_CONTACTS_H

#include <stddef.h>
#include <stdint.h>

#include "core/space/box.h"
#include "core/space/particles.h"

typedef struct pk_contact_stats {
    size_t contacts;      /* pairs in contact */
    size_t wall_contacts; /* grain–wall contacts (walled axes only) */
    size_t rattlers;
    double rattler_fraction;  /* rattlers / n */
    double mean_contacts;     /* z of the non-rattlers, wall contacts included (0 if all rattle) */
    size_t backbone;          /* non-rattlers: n − rattlers */
    size_t backbone_contacts; /* contacts among them, wall contacts included */
} pk_contact_stats;

/* The network itself: pair contacts (i < j, unit normal along the minimum
 * image), wall contacts (grain, axis) and the rattler flags. */
typedef struct pk_contact_network {
    size_t npair, nwall;
    int32_t *pi, *pj;
    double *normal; /* 3 per pair */
    int32_t *wi;
    int8_t *waxis;
    uint8_t *rattler; /* n flags */
} pk_contact_network;

/* Contact tolerance (relative to r_i + r_j) for a packing at reduced
 * pressure p: caged grains at pressure p keep gaps of order dim/p of the
 * contact distance (free-volume cages, Skoge et al. 2006), so 10^3·dim/p
 * takes in the spread of the contacts and leaves the near-contacts out
 * (3D mono at p = 10^12: the count is flat from 10^-10 to 10^-6).
 * Clamped to [10^-12, 10^-3]: above round-off, and at low pressure no
 * wider than 10^-3 (a gap of 10^-3 d is no contact). */
double pk_contact_tolerance(int dim, double p);

/* delta_d: the required surface gap (a contact is gap ≤ Δd + tol·(r_i+r_j));
 * wall_gap: the clearance the walls keep (a wall contact is ≤ wall_gap +
 * tol·2r_i).  net may be NULL (statistics only); else it is filled and
 * released by pk_contact_network_free.  Returns 0 or -1 (allocation failure). */
int pk_contact_network_compute(const pk_box *b, const pk_particles *p, double delta_d,
                               double wall_gap, double tol, pk_contact_network *net,
                               pk_contact_stats *cs);
void pk_contact_network_free(pk_contact_network *net);

/* The statistics with walls keeping Δd/2 (pk_contact_network_compute). */
int pk_contact_stats_compute(const pk_box *b, const pk_particles *p, double delta_d, double tol,
                             pk_contact_stats *cs);

#endif
