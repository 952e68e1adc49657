/* data_paths.h — no client learns where the data directory is.  A path
 * under it in a message or document becomes what a client knows it by:
 *   DATA/files/<id>            -> /files/<id>
 *   DATA/jobs/<id>/result.h5   -> /jobs/<id>/results/result
 *   DATA/jobs/<id>/<name>      -> <name>  (a job's own file: worker.log, ...)
 *   DATA anywhere else         -> (data)
 * and in documents an input {"file": "/files/<id>"} (or a job's result) is
 * the link {"href": ...} it was submitted as.  DATA is matched as
 * configured, relative or absolute, and only as a whole path component. */
#ifndef PK_DATA_PATHS_H
#define PK_DATA_PATHS_H

#include <jansson.h>

/* text with the data directory's paths replaced (malloc'd), or NULL when
 * there is none (or no memory). */
char *pk_hide_data_paths(const char *text, const char *data);

/* The same for every string of doc (in place), file inputs back to links. */
void pk_hide_data_paths_json(json_t *doc, const char *data);

#endif
