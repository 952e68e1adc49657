/* schemas_embedded.c — lookup over the generated table of schemas/ files
 * (build/gen/schemas_embedded.c, written by tools/embed.sh). */
#include "schemas_embedded.h"

#include <string.h>

const char *pk_schema_text(const char *name)
{
    if (!name)
        return NULL;
    const char *base = strrchr(name, '/');
    base = base ? base + 1 : name;
    for (const pk_embedded_schema *s = pk_embedded_schemas; s->name; s++)
        if (strcmp(s->name, base) == 0)
            return s->text;
    return NULL;
}
