/* sha256.h — SHA-256 (FIPS 180-4), used for the digest of result files and
 * uploads and for idempotency request fingerprints.  Small and dependency-free. */
#ifndef PK_SHA256_H
#define PK_SHA256_H

#include <stddef.h>
#include <stdint.h>

typedef struct pk_sha256 {
    uint32_t h[8];
    uint64_t len;        /* bytes hashed so far */
    unsigned char buf[64];
    size_t nbuf;
} pk_sha256;

void pk_sha256_init(pk_sha256 *s);
void pk_sha256_update(pk_sha256 *s, const void *data, size_t n);
void pk_sha256_final(pk_sha256 *s, unsigned char out[32]);

/* One call: hex digest (65 bytes incl. NUL) of a buffer. */
void pk_sha256_hex(const void *data, size_t n, char hex[65]);
/* Hex digest of a file; 0 on success, -1 on I/O error (errno set). */
int pk_sha256_file_hex(const char *path, char hex[65]);
/* 32-byte digest from 64 hex digits; 0 on success. */
int pk_sha256_from_hex(const char *hex, unsigned char out[32]);

#endif
