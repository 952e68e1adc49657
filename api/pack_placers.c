#include <string.h>

#include "pack_placer.h"

extern const pk_placer pk_placer_rsa;

const pk_placer *const pk_placers[] = {
    &pk_placer_rsa,
    NULL,
};

const pk_placer *pk_placer_find(const char *name)
{
    for (size_t i = 0; name && pk_placers[i]; i++)
        if (strcmp(pk_placers[i]->name, name) == 0)
            return pk_placers[i];
    return NULL;
}
