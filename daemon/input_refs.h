/* input_refs.h — file-valued inputs by link.  A service client names a file
 * input with {"href": "/files/<sha256>"} (an upload) or
 * {"href": "/jobs/<id>/results/result"} (the result of a finished job — an
 * RVE for `homogenize`); the daemon replaces each such object by
 * {"file": "<absolute path>"} before the job is validated and queued, so
 * workers run exactly what `packd run` runs. */
#ifndef PK_INPUT_REFS_H
#define PK_INPUT_REFS_H

#include <jansson.h>

#include "api/schemas/json_schema.h"
#include "daemon/store/queue.h"

/* Rewrites inputs in place.  Unknown or unusable links become errors
 * (pointer relative to the inputs object, rule "href"); so do links to
 * another owner's upload or job when owner is not NULL (NULL: an admin,
 * any owner's).  Returns the number of errors appended. */
size_t pk_resolve_input_refs(json_t *inputs, const char *data_dir, pk_queue *q, const char *owner,
                             pk_schema_errors *errs);

#endif
