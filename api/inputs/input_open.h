/* input_open.h — open a file a job names as input (mesh, RVE) without
 * trusting it: only a regular file is read (a FIFO, a device such as
 * /dev/zero, a directory or a socket is refused at once, never waited on),
 * and only up to a size limit. */
#ifndef PK_INPUT_OPEN_H
#define PK_INPUT_OPEN_H

#include <stdio.h>

/* The largest input file any reader accepts (the service's input_max_bytes
 * is usually smaller and is checked when a job is submitted). */
#define PK_INPUT_MAX_BYTES (16LL << 30)

/* A read-only descriptor of a regular file of at most max_bytes (0 =
 * PK_INPUT_MAX_BYTES), or -1 with the reason in err.  The file is opened
 * with O_NONBLOCK, so naming a FIFO does not block; the descriptor is then
 * switched back to blocking reads. */
int pk_input_open(const char *path, long long max_bytes, char *err, size_t errlen);

/* The same as a stdio stream ("r"), or NULL with err. */
FILE *pk_input_fopen(const char *path, long long max_bytes, char *err, size_t errlen);

/* Check at validation that a job's input file opens: 0, or -1 with an error
 * at pointer with rule ("cannot open rve.h5: No such file or directory"). */
#include "api/schemas/json_schema.h"
int pk_input_check(const char *path, const char *pointer, const char *rule, pk_schema_errors *errs);

#endif
