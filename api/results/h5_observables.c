/* h5_observables.c — one observable list to the summary and the file; the
 * contract is in h5_observables.h. */
#include "h5_observables.h"

#include <stdio.h>
#include <string.h>

const char *pk_obs_file(const pk_obs_row *row) { return row->file ? row->file : row->name; }

json_t *pk_obs_value(json_t *values, const char *name)
{
    char key[128];
    const char *slash;
    while (values && (slash = strchr(name, '/'))) {
        snprintf(key, sizeof key, "%.*s", (int)(slash - name), name);
        values = json_object_get(values, key);
        name = slash + 1;
    }
    return json_object_get(values, name);
}

int pk_obs_set(json_t *values, const char *name, json_t *v)
{
    char key[128];
    const char *slash;
    while ((slash = strchr(name, '/'))) {
        snprintf(key, sizeof key, "%.*s", (int)(slash - name), name);
        json_t *sub = json_object_get(values, key);
        if (!sub && json_object_set_new(values, key, sub = json_object()) != 0)
            sub = NULL;
        if (!json_is_object(sub)) {
            json_decref(v);
            return -1;
        }
        values = sub;
        name = slash + 1;
    }
    return v ? json_object_set_new(values, name, v) : -1;
}

const pk_obs_row *pk_obs_row_named(const pk_obs_row *rows, const char *name)
{
    for (; rows && rows->name; rows++)
        if (rows->form != PK_OBS_FILE && !strcmp(rows->name, name))
            return rows;
    return NULL;
}

const char *pk_obs_unit_at(const pk_obs_row *rows, const char *path, const pk_units *u)
{
    for (; rows && rows->name; rows++)
        if (!strcmp(pk_obs_file(rows), path))
            return pk_unit_string(u, rows->kind);
    return NULL;
}

int pk_h5_obs_rows(pk_h5 *h, const pk_obs_row *rows, json_t *values, const pk_units *u)
{
    int rc = 0;
    for (; rows->name; rows++) {
        if (rows->form != PK_OBS_SCALAR)
            continue;
        json_t *v = pk_obs_value(values, rows->name);
        const char *unit = pk_unit_string(u, rows->kind), *file = pk_obs_file(rows);
        if (json_is_integer(v) && !unit)
            rc |= pk_h5_obs_int(h, file, (int64_t)json_integer_value(v));
        else if (json_is_number(v))
            rc |= pk_h5_obs_double(h, file, json_number_value(v), unit);
        else if (json_is_boolean(v))
            rc |= pk_h5_obs_int(h, file, json_is_true(v));
        else if (json_is_string(v))
            rc |= pk_h5_obs_string(h, file, json_string_value(v));
        else if (v) /* absent: not defined for this run (e.g. no φ target when jammed) */
            rc = -1;
    }
    return rc ? -1 : 0;
}

json_t *pk_obs_units_json(const pk_obs_row *rows, json_t *summary, const pk_units *u)
{
    json_t *units = json_object();
    for (; units && rows->name; rows++) {
        const char *unit = pk_unit_string(u, rows->kind);
        if (rows->form != PK_OBS_FILE && unit && pk_obs_value(summary, rows->name))
            json_object_set_new(units, rows->name, json_string(unit));
    }
    return units;
}
