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

const char *pk_unit_string(const pk_units *u, pk_unit_kind kind)
{
    const int L = u->length[0] != 0;
    switch (kind) {
    case PK_U_NONE: return NULL;
    case PK_U_SECONDS: return "s";
    case PK_U_HERTZ: return "s-1";
    case PK_U_FORCE: return "N";
    case PK_U_LENGTH: return L ? u->length : NULL;
    case PK_U_AREA: return L ? u->area : NULL;
    case PK_U_VOLUME: return L ? u->volume : NULL;
    case PK_U_STIFFNESS: return L ? u->stiffness : NULL;
    case PK_U_STRESS: return L ? u->stress : NULL;
    case PK_U_ENERGY: return L ? u->energy : NULL;
    case PK_U_PLANE_STRESS: return L ? u->plane_stress : NULL;
    case PK_U_FORCE_PER_THICKNESS: return L ? u->force_per_thickness : NULL;
    }
    return NULL;
}

const char *pk_unit_in(const pk_unit_row *rows, const char *name, const pk_units *u)
{
    for (; rows && rows->name; rows++)
        if (!strcmp(rows->name, name))
            return pk_unit_string(u, rows->kind);
    return NULL;
}
