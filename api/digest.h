/* digest.h — SHA-256 (FIPS 180-4) and its text forms, over OpenSSL's EVP:
 * the digest of result files and uploads (ETag, X-Content-SHA256,
 * Repr-Digest), idempotency request fingerprints, checkpoint keys and the
 * stored hash of bearer tokens. */
#ifndef PK_DIGEST_H
#define PK_DIGEST_H

#include <stddef.h>

/* Incremental hashing: new, update any number of times, final (which also
 * frees).  new is NULL and update/final are -1 when OpenSSL fails. */
typedef struct pk_sha256 pk_sha256;
pk_sha256 *pk_sha256_new(void);
int pk_sha256_update(pk_sha256 *s, const void *data, size_t n);
int pk_sha256_final(pk_sha256 *s, unsigned char out[32]);
void pk_sha256_free(pk_sha256 *s);

/* Hex digest (65 bytes incl. NUL) of a buffer; 0, or -1 with hex = "". */
int pk_sha256_hex(const void *data, size_t n, char hex[65]);
/* Hex digest of a file; 0 on success, -1 on I/O error (errno set). */
int pk_sha256_file_hex(const char *path, char hex[65]);
/* 32-byte digest from 64 hex digits; 0 on success. */
int pk_sha256_from_hex(const char *hex, unsigned char out[32]);

/* Lower-case hex of n bytes into hex[2n + 1]. */
void pk_hex(const unsigned char *d, size_t n, char *hex);
/* Base64 (RFC 4648 §4, padded) of n bytes into out[4 * ((n + 2) / 3) + 1]. */
void pk_base64(const unsigned char *in, size_t n, char *out);
/* Base64url (RFC 4648 §5) without padding, same room as pk_base64. */
void pk_base64url(const unsigned char *in, size_t n, char *out);

#endif
