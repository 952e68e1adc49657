/* route_dashboard_units.c — GET /dashboard/jobs/{id}/units: the unit of each
 * summary member that has one — the summary's own "units" (its process's
 * observable list, api/results/h5_observables.h) and, for a pack job, its
 * placer's table (the units its record is written with) — so the job page
 * shows "0.1 mm" where the summary says 0.1.  Keys are the summary's paths
 * with '.' ("timing.place_s", "edmd.delta_d_reached"); a member without an
 * entry is a count, a ratio or in reduced units. */
#include <string.h>

#include "auth.h"
#include "route_dashboard.h"
#include "api/pack/pack_placer.h"

/* into[prefix + name, '/' as '.'] = unit */
static void add_unit(json_t *into, const char *prefix, const char *name, const char *unit)
{
    char key[160];
    snprintf(key, sizeof key, "%s%s", prefix, name);
    for (char *s = key; *s; s++)
        if (*s == '/')
            *s = '.';
    json_object_set_new(into, key, json_string(unit));
}

/* Each row of rows with a unit under prefix ("edmd."). */
static void add_rows(json_t *into, const char *prefix, const pk_unit_row *rows, const pk_units *u)
{
    for (; rows && rows->name; rows++) {
        const char *unit = pk_unit_string(u, rows->kind);
        if (unit)
            add_unit(into, prefix, rows->name, unit);
    }
}

static void placer_units(json_t *into, json_t *inputs, json_t *summary)
{
    const char *length = json_string_value(json_object_get(inputs, "unit"));
    json_t *dim = json_object_get(inputs, "dim");
    pk_units u;
    pk_units_init(&u, length ? length : "mm",
                  json_is_integer(dim) ? (int)json_integer_value(dim) : 3);
    const char *algorithm = json_string_value(json_object_get(summary, "algorithm"));
    const pk_placer *placer = algorithm ? pk_placer_find(algorithm) : NULL;
    if (placer) {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "%s.", placer->name);
        add_rows(into, prefix, placer->units, &u);
    }
}

enum MHD_Result route_dashboard_units(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[2]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[2]);
    json_t *units = json_object();
    json_t *summary = json_object_get(row, "summary");
    const char *name;
    json_t *unit;
    json_object_foreach (json_object_get(summary, "units"), name, unit)
        if (json_is_string(unit))
            add_unit(units, "", name, json_string_value(unit));
    const char *process = json_string_value(json_object_get(row, "process"));
    if (process && !strcmp(process, "pack"))
        placer_units(units, json_object_get(row, "inputs"), summary);
    json_decref(row);
    return pk_send_json(r, 200, json_pack("{s:o}", "units", units), NULL);
}
