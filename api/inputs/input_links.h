/* input_links.h — file inputs given by link, {"href": "..."}: the service
 * resolves them (daemon/input_refs.c), a job file run by `packd run` must
 * name files by path.  One walker serves both. */
#ifndef PK_INPUT_LINKS_H
#define PK_INPUT_LINKS_H

#include <jansson.h>

#include "api/schemas/json_schema.h"

/* Calls fn for every object {"href": <string>} (and nothing else) inside
 * inputs, with the JSON pointer of that object relative to inputs.  Returns
 * the number of links visited. */
size_t pk_input_links_each(json_t *inputs,
                           void (*fn)(json_t *link, const char *href, const char *pointer,
                                      void *ctx),
                           void *ctx);

/* Calls fn for every object with a string member "file" (a path), with
 * its pointer relative to inputs.  Returns the number visited. */
size_t pk_input_files_each(json_t *inputs,
                           void (*fn)(json_t *obj, const char *file, const char *pointer,
                                      void *ctx),
                           void *ctx);

/* For job files: every link is an error (rule "href"). */
size_t pk_input_links_refuse(json_t *inputs, pk_schema_errors *errs);

#endif
