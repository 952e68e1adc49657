/* pack_placers.c — the table of the pack process's placers; the contract is
 * in pack_placer.h. */
#include <string.h>

#include "pack_placer.h"

extern const pk_placer pk_placer_rsa;
extern const pk_placer pk_placer_edmd;
extern const pk_placer pk_placer_tetfill;

const pk_placer *const pk_placers[] = {
    &pk_placer_rsa,
    &pk_placer_edmd,
    &pk_placer_tetfill,
    NULL,
};

const pk_placer *pk_placer_find(const char *name)
{
    for (size_t i = 0; name && pk_placers[i]; i++)
        if (strcmp(pk_placers[i]->name, name) == 0)
            return pk_placers[i];
    return NULL;
}

const pk_placer *pk_placer_filling_mesh(void)
{
    size_t i = 0;
    while (pk_placers[i + 1] && !pk_placers[i]->fills_mesh)
        i++;
    return pk_placers[i];
}
