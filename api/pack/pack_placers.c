/* pack_placers.c — the table of the pack process's placers; the contract is
 * in pack_placer.h. */
#include <string.h>

#include "api/schemas/json_schema.h"
#include "pack_placer.h"

extern const pk_placer pk_placer_rsa;
extern const pk_placer pk_placer_edmd;
extern const pk_placer pk_placer_tetfill;

/* The built-in rows, then those added by pk_placer_register. */
#define PK_PLACERS_MAX 16
static const pk_placer *table[PK_PLACERS_MAX + 1] = {
    &pk_placer_rsa,
    &pk_placer_edmd,
    &pk_placer_tetfill,
};

const pk_placer *pk_placer_at(size_t i) { return i < PK_PLACERS_MAX ? table[i] : NULL; }

const pk_placer *pk_placer_find(const char *name)
{
    const pk_placer *p;
    for (size_t i = 0; name && (p = pk_placer_at(i)); i++)
        if (strcmp(p->name, name) == 0)
            return p;
    return NULL;
}

const pk_placer *pk_placer_filling_mesh(void)
{
    const pk_placer *p;
    for (size_t i = 0; (p = pk_placer_at(i)); i++)
        if (p->fills_mesh)
            return p;
    return table[0];
}

int pk_placer_register(const pk_placer *p)
{
    size_t n = 0;
    while (table[n])
        n++;
    json_t *alg = json_object_get(
        json_object_get(pk_schema_get("pack.inputs.schema.json"), "properties"), "algorithm");
    json_t *names = json_object_get(alg, "enum");
    if (!p || !p->name || !p->place || pk_placer_find(p->name) || n == PK_PLACERS_MAX ||
        !json_is_array(names))
        return -1;
    table[n] = p;
    return json_array_append_new(names, json_string(p->name));
}
