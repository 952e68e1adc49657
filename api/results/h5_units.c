/* h5_units.c — unit strings of the observables (contract in h5_units.h). */
#include "h5_units.h"

#include <stdio.h>
#include <string.h>

void pk_units_init(pk_units *u, const char *length, int dim)
{
    memset(u, 0, sizeof *u);
    u->dim = dim;
    if (!length || !*length || !strcmp(length, "1"))
        return;
    snprintf(u->length, sizeof u->length, "%s", length);
    snprintf(u->area, sizeof u->area, "%s+2", length);
    snprintf(u->volume, sizeof u->volume, "%s+%d", length, dim);
    snprintf(u->stiffness, sizeof u->stiffness, "N %s-1", length);
    snprintf(u->stress, sizeof u->stress, "N %s-%d", length, dim - 1);
    snprintf(u->energy, sizeof u->energy, "N %s", length);
    snprintf(u->plane_stress, sizeof u->plane_stress, "N %s-2", length);
    snprintf(u->force_per_thickness, sizeof u->force_per_thickness, "N %s-1", length);
}

typedef enum {
    U_LENGTH,
    U_VOLUME,
    U_STIFF,
    U_STRESS,
    U_ENERGY,
    U_FORCE,
    U_S,
    U_HZ,
    U_AREA,
    U_PSTRESS,
    U_FORCE_T
} kind;

/* Observables with a unit; every other one is a count, a ratio, a flag or
 * in reduced units (EDMD's time, d̄/u). */
static const struct {
    const char *name;
    kind k;
} table[] = {
    {"edmd/delta_d_reached", U_LENGTH},
    {"edmd/wall_gap_guaranteed", U_LENGTH},
    {"edmd/start_seconds", U_S},
    {"edmd/collisions_per_second", U_HZ},
    {"tetfill/r_min", U_LENGTH},
    {"tetfill/r_max", U_LENGTH},
    {"tetfill/overlap_bound", U_LENGTH},
    {"tetfill/mesh_volume", U_VOLUME},
    {"tetfill/mesh_edge_mean", U_LENGTH},
    {"tetfill/mesh_origin", U_LENGTH},
    {"tetfill/seconds_geometric", U_S},
    {"homogenize/rve_volume", U_VOLUME},
    {"homogenize/E_n", U_STIFF},
    {"homogenize/friction/E_t", U_STIFF},
    {"homogenize/P", U_STRESS},
    {"homogenize/sigma", U_STRESS},
    {"homogenize/sigma_skew", U_STRESS},
    {"homogenize/energy", U_ENERGY},
    {"homogenize/energy_density", U_STRESS},
    {"homogenize/energy_tangential", U_ENERGY},
    {"homogenize/dissipation", U_ENERGY},
    {"homogenize/sum_force", U_FORCE},
    {"homogenize/dr/residual", U_FORCE},
    {"homogenize/dr/residual_initial", U_FORCE},
    {"homogenize/tangent/A", U_STRESS},
    {"homogenize/tangent/seconds", U_S},
    {"homogenize/final_state/position", U_LENGTH},
    {"homogenize/final_state/fluctuation", U_LENGTH},
    {"fe2/mesh/nodes", U_LENGTH},
    {"fe2/mesh/gauss_position", U_LENGTH},
    {"fe2/mesh/gauss_weight", U_AREA},
    {"fe2/displacement", U_LENGTH},
    {"fe2/position", U_LENGTH},
    {"fe2/piola_stress", U_PSTRESS},
    {"fe2/cauchy_stress", U_PSTRESS},
    {"fe2/von_mises", U_PSTRESS},
    {"fe2/von_mises_element", U_PSTRESS},
    {"fe2/rve/energy_density", U_PSTRESS},
    {"fe2/reaction", U_FORCE_T},
    {"fe2/area", U_AREA},
    {"fe2/reference_area", U_AREA},
    {"fe2/micro", U_LENGTH}, /* the RVE centres micro/gauss_point_<g> */
    {"fe2/newton/solves/abs_residual_0", U_FORCE_T},
    {"fe2/E_n", U_STIFF},
};

const char *pk_units_of(const char *name, const void *ctx)
{
    const pk_units *u = ctx;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        if (strcmp(table[i].name, name) != 0)
            continue;
        switch (table[i].k) {
        case U_S: return "s";
        case U_HZ: return "s-1";
        case U_FORCE: return "N";
        case U_LENGTH: return u->length[0] ? u->length : NULL;
        case U_VOLUME: return u->length[0] ? u->volume : NULL;
        case U_STIFF: return u->length[0] ? u->stiffness : NULL;
        case U_STRESS: return u->length[0] ? u->stress : NULL;
        case U_ENERGY: return u->length[0] ? u->energy : NULL;
        case U_AREA: return u->length[0] ? u->area : NULL;
        case U_PSTRESS: return u->length[0] ? u->plane_stress : NULL;
        case U_FORCE_T: return u->length[0] ? u->force_per_thickness : NULL;
        }
    }
    return NULL;
}
