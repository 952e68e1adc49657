/* result_digest.h — a content hash of a result that is the same run to run:
 * SHA-256 (OpenSSL EVP) over the job as stored and the particle data, not
 * over the file's bytes (those hold wall-clock timings).  Two results with
 * the same digest hold the same grains computed for the same job.
 *
 * Stored as /parameters/result_digest (64 hex digits, attribute "method"
 * saying what was hashed), reported in the summary and by `packd inspect`,
 * checked by `packd submit --wait` and `packd fetch`. */
#ifndef PK_RESULT_DIGEST_H
#define PK_RESULT_DIGEST_H

#include <hdf5.h>

#define PK_RESULT_DIGEST_METHOD                                                                    \
    "sha256: for each of /parameters/job (UTF-8 text), /particles/grains/box/edges, position, "    \
    "radius (IEEE float64 LE), species (int32 LE): its name, 0, its byte length (uint64 LE), "     \
    "its bytes"

/* The digest of an open file (result in memory or on disk): 0, or -1 when
 * it has no job or no grains (checkpoints).  HDF5's error printing is the
 * caller's business (the file functions below silence it). */
int pk_result_digest_compute(hid_t file, char hex[65]);
/* The same from a file on disk (what a client checks a download with). */
int pk_result_digest_file(const char *path, char hex[65]);
/* The digest the file states (/parameters/result_digest): 0, or -1. */
int pk_result_digest_stored(const char *path, char hex[65]);

#endif
