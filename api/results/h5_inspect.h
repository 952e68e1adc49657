/* h5_inspect.h — a JSON view of a packd result file (`packd inspect`, the
 * daemon's results document): box, grain count, every observable. */
#ifndef PK_H5_INSPECT_H
#define PK_H5_INSPECT_H

#include <jansson.h>
#include <stddef.h>

/* New JSON object, or NULL with err; with "result_digest" (stored) and
 * "result_digest_verified" (recomputed from the file, equal) when the file
 * states one (result_digest.h).  Observables by path under /observables;
 * an H5MD time-dependent element X as "X" (its value; "X/step" and
 * "X/time" under the element that holds them), arrays of rank > 1 nested.
 * Arrays longer than max_array elements are summarised by their shape. */
json_t *pk_h5_inspect(const char *path, size_t max_array, char *err, size_t errlen);

#endif
