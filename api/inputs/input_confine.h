/* input_confine.h — server paths in a request to the daemon: the
 * {"file": "..."} of a mesh or an RVE.
 *
 * Without an input directory the service takes no server path at all: files
 * come as links to an upload or to a job's result (daemon/input_refs.h).
 * With one (config input_dir), a path names a file inside it: relative paths
 * are relative to it; the path resolved (realpath) must stay inside it (no
 * "..", no symlink out), be a regular file (no FIFO, device or directory)
 * and hold at most max_bytes.  For a TetGen base name, <base>.node and
 * <base>.ele are checked alike.  Nothing is opened: the worker reads the file.
 * The messages name the path as given, never where a symlink leads. */
#ifndef PK_INPUT_CONFINE_H
#define PK_INPUT_CONFINE_H

#include <jansson.h>

#include "api/schemas/json_schema.h"

/* Checks every "file" member in inputs and rewrites each accepted path to
 * the file in the resolved input directory, so the worker opens what was
 * checked.  input_dir NULL or "" = refuse every path (rule "serverPath"),
 * else rule "inputDir"; pointers are relative to inputs.  Returns the
 * number of errors appended. */
size_t pk_input_files_confine(json_t *inputs, const char *input_dir, long long max_bytes,
                              pk_schema_errors *errs);

#endif
