/* tokens.h — bearer tokens (RFC 6750) of the job service: `packd token
 * add|list|revoke` writes them, the daemon checks every request's token here.
 *
 * A token is "packd_" + 43 base64url characters (32 random bytes from the
 * kernel via OpenSSL's RAND_bytes).  It is shown once, when made; the
 * database (table tokens of DATA/queue.db) keeps only its SHA-256 (OpenSSL
 * EVP), the name it acts as (the owner of the jobs it submits) and whether
 * it is an admin token (sees and dismisses every owner's jobs). */
#ifndef PK_TOKENS_H
#define PK_TOKENS_H

#include <jansson.h>
#include <stddef.h>

#define PK_TOKEN_PREFIX "packd_"
#define PK_TOKEN_LEN 49      /* prefix + 43 characters */
#define PK_TOKEN_NAME_MAX 64 /* a name: 1..63 of [A-Za-z0-9._@-] */

typedef struct pk_tokens pk_tokens;

/* Open the token store of a queue database (created and migrated if new).
 * Safe beside a running daemon.  NULL with err. */
pk_tokens *pk_tokens_open(const char *db_path, char *err, size_t errlen);
void pk_tokens_close(pk_tokens *t);

/* 1 if name is a valid token name. */
int pk_token_name_ok(const char *name);

/* A new random token (PK_TOKEN_LEN characters + NUL); 0, -1 without entropy. */
int pk_token_generate(char out[PK_TOKEN_LEN + 1]);

/* Hex SHA-256 of the token's text: what the database stores. */
void pk_token_hash(const char *token, char hex[65]);

/* Make a token for name; the plain token goes to out (shown once).
 * 0, or -1 with err (bad or taken name, database error). */
int pk_tokens_add(pk_tokens *t, const char *name, int admin, char out[PK_TOKEN_LEN + 1], char *err,
                  size_t errlen);

/* [{"name", "admin", "created", "last_used"}] by name; never the token. */
json_t *pk_tokens_list(pk_tokens *t);

/* Remove name's token: 1 removed, 0 no such name, -1 database error. */
int pk_tokens_revoke(pk_tokens *t, const char *name);

/* The name and admin flag of a presented token: 1 valid, 0 unknown, -1 the
 * database did not answer.  Records last_used (at most once a minute, best
 * effort: never waiting on another write). */
int pk_tokens_verify(pk_tokens *t, const char *token, char name[PK_TOKEN_NAME_MAX], int *admin);

/* Tokens stored (-1 on error). */
int pk_tokens_count(pk_tokens *t);

#endif
