/* route_dashboard_units.c — GET /dashboard/jobs/{id}/units: the unit of each
 * summary member that has one, from the tables the result file's units come
 * from (a pack job: pk_pack_observables and its placer's; h5_units.h), so the
 * job page shows "0.1 mm" where the summary says 0.1.  Keys are the summary's
 * paths with '.' ("timing.place_s", "edmd.delta_d_reached"); a member without
 * an entry is a count, a ratio or in reduced units, or its process has no
 * table here. */
#include <string.h>

#include "auth.h"
#include "route_dashboard.h"
#include "api/pack/pack_job.h"
#include "api/pack/pack_placer.h"

/* name's unit under prefix ("" or "edmd."), '/' as '.', if it has one. */
static void add_row(json_t *into, const char *prefix, const char *name, pk_unit_kind kind,
                    const pk_units *u)
{
    const char *unit = pk_unit_string(u, kind);
    if (!unit)
        return;
    char key[160];
    snprintf(key, sizeof key, "%s%s", prefix, name);
    for (char *s = key; *s; s++)
        if (*s == '/')
            *s = '.';
    json_object_set_new(into, key, json_string(unit));
}

static void pack_units(json_t *into, json_t *inputs, json_t *summary)
{
    const char *length = json_string_value(json_object_get(inputs, "unit"));
    json_t *dim = json_object_get(inputs, "dim");
    pk_units u;
    pk_units_init(&u, length ? length : "mm",
                  json_is_integer(dim) ? (int)json_integer_value(dim) : 3);
    for (const pk_obs_row *row = pk_pack_observables; row->name; row++)
        if (row->form != PK_OBS_FILE)
            add_row(into, "", row->name, row->kind, &u);
    const char *algorithm = json_string_value(json_object_get(summary, "algorithm"));
    const pk_placer *placer = algorithm ? pk_placer_find(algorithm) : NULL;
    if (placer) {
        char prefix[64];
        snprintf(prefix, sizeof prefix, "%s.", placer->name);
        for (const pk_unit_row *row = placer->units; row && row->name; row++)
            add_row(into, prefix, row->name, row->kind, &u);
    }
}

enum MHD_Result route_dashboard_units(pk_req *r)
{
    json_t *row = pk_job_visible(r, r->seg[2]);
    if (!row)
        return pk_reply_problem(r, PK_P_NO_SUCH_JOB, r->seg[2]);
    json_t *units = json_object();
    const char *process = json_string_value(json_object_get(row, "process"));
    if (process && !strcmp(process, "pack"))
        pack_units(units, json_object_get(row, "inputs"), json_object_get(row, "summary"));
    json_decref(row);
    return pk_send_json(r, 200, json_pack("{s:o}", "units", units), NULL);
}
