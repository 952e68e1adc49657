/* schemas_embedded.h — the files of schemas/, compiled into packd.
 * Generated table (build/gen/schemas_embedded.c); see tools/embed.sh. */
#ifndef PK_SCHEMAS_EMBEDDED_H
#define PK_SCHEMAS_EMBEDDED_H

#include <stddef.h>

typedef struct pk_embedded_schema {
    const char *name; /* base file name, e.g. "pack.inputs.schema.json" */
    const char *text; /* file content, NUL-terminated */
    size_t len;
} pk_embedded_schema;

/* Terminated by an entry with name == NULL. */
extern const pk_embedded_schema pk_embedded_schemas[];

/* The schema text for a base file name, or NULL. */
const char *pk_schema_text(const char *name);

#endif
