/* tokens.c — bearer tokens in the queue database: make, list, revoke, check;
 * contract in tokens.h. */
#include "tokens.h"

#include <openssl/rand.h>
#include <pthread.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "api/digest.h"
#include "migrations.h"

#define LAST_USED_EVERY_S 60.0 /* last_used is a write: not on every request */

struct pk_tokens {
    sqlite3 *db; /* writes (add, revoke, last_used) */
    pthread_mutex_t mu;
    sqlite3 *rd; /* read-only (migrations.h): a check never waits on a write */
    pthread_mutex_t rd_mu;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

pk_tokens *pk_tokens_open(const char *db_path, char *err, size_t errlen)
{
    pk_tokens *t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    t->db = pk_db_open(db_path, err, errlen);
    if (!t->db) {
        free(t);
        return NULL;
    }
    t->rd = pk_db_open_reader(db_path, err, errlen);
    if (!t->rd) {
        sqlite3_close(t->db);
        free(t);
        return NULL;
    }
    pthread_mutex_init(&t->mu, NULL);
    pthread_mutex_init(&t->rd_mu, NULL);
    return t;
}

void pk_tokens_close(pk_tokens *t)
{
    if (!t)
        return;
    sqlite3_close(t->rd);
    sqlite3_close(t->db);
    pthread_mutex_destroy(&t->mu);
    pthread_mutex_destroy(&t->rd_mu);
    free(t);
}

int pk_token_name_ok(const char *name)
{
    size_t n = strlen(name);
    if (n == 0 || n >= PK_TOKEN_NAME_MAX)
        return 0;
    for (size_t i = 0; i < n; i++) {
        char ch = name[i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
              ch == '.' || ch == '_' || ch == '@' || ch == '-'))
            return 0;
    }
    return 1;
}

int pk_token_generate(char out[PK_TOKEN_LEN + 1])
{
    unsigned char b[32];
    char enc[45];
    if (RAND_bytes(b, sizeof b) != 1)
        return -1;
    pk_base64url(b, sizeof b, enc); /* 43 characters and the NUL */
    _Static_assert(sizeof PK_TOKEN_PREFIX - 1 + 43 == PK_TOKEN_LEN, "token length");
    memcpy(out, PK_TOKEN_PREFIX, sizeof PK_TOKEN_PREFIX - 1);
    memcpy(out + sizeof PK_TOKEN_PREFIX - 1, enc, 44);
    return 0;
}

void pk_token_hash(const char *token, char hex[65])
{
    pk_sha256_hex(token, strlen(token), hex); /* "" on failure: matches no stored hash */
}

int pk_tokens_add(pk_tokens *t, const char *name, int admin, char out[PK_TOKEN_LEN + 1], char *err,
                  size_t errlen)
{
    if (!pk_token_name_ok(name)) {
        snprintf(err, errlen, "a token name is 1 to %d of A-Z a-z 0-9 . _ @ - (got '%s')",
                 PK_TOKEN_NAME_MAX - 1, name);
        return -1;
    }
    char hex[65];
    if (pk_token_generate(out) != 0) {
        snprintf(err, errlen, "no random bytes from the system");
        return -1;
    }
    pk_token_hash(out, hex);
    pthread_mutex_lock(&t->mu);
    sqlite3_stmt *st = NULL;
    int rc = sqlite3_prepare_v2(
        t->db, "INSERT INTO tokens(name, sha256, admin, created) VALUES (?,?,?,?)", -1, &st, NULL);
    if (rc == SQLITE_OK) {
        sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
        sqlite3_bind_text(st, 2, hex, -1, SQLITE_TRANSIENT);
        sqlite3_bind_int(st, 3, admin ? 1 : 0);
        sqlite3_bind_double(st, 4, now_s());
        rc = sqlite3_step(st);
    }
    if (rc == SQLITE_CONSTRAINT)
        snprintf(err, errlen, "a token named '%s' exists (revoke it first to replace it)", name);
    else if (rc != SQLITE_DONE)
        snprintf(err, errlen, "database: %s", sqlite3_errmsg(t->db));
    sqlite3_finalize(st);
    pthread_mutex_unlock(&t->mu);
    if (rc != SQLITE_DONE)
        memset(out, 0, PK_TOKEN_LEN + 1);
    return rc == SQLITE_DONE ? 0 : -1;
}

json_t *pk_tokens_list(pk_tokens *t)
{
    json_t *a = json_array();
    pthread_mutex_lock(&t->mu);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(t->db,
                           "SELECT name, admin, created, last_used FROM tokens ORDER BY name", -1,
                           &st, NULL) == SQLITE_OK)
        while (sqlite3_step(st) == SQLITE_ROW)
            json_array_append_new(a,
                                  json_pack("{s:s,s:b,s:f,s:o}", "name",
                                            (const char *)sqlite3_column_text(st, 0), "admin",
                                            sqlite3_column_int(st, 1), "created",
                                            sqlite3_column_double(st, 2), "last_used",
                                            sqlite3_column_type(st, 3) == SQLITE_NULL
                                                ? json_null()
                                                : json_real(sqlite3_column_double(st, 3))));
    sqlite3_finalize(st);
    pthread_mutex_unlock(&t->mu);
    return a;
}

int pk_tokens_revoke(pk_tokens *t, const char *name)
{
    pthread_mutex_lock(&t->mu);
    sqlite3_stmt *st = NULL;
    int rc = -1;
    if (sqlite3_prepare_v2(t->db, "DELETE FROM tokens WHERE name=?", -1, &st, NULL) == SQLITE_OK) {
        sqlite3_bind_text(st, 1, name, -1, SQLITE_TRANSIENT);
        if (sqlite3_step(st) == SQLITE_DONE)
            rc = sqlite3_changes(t->db) > 0;
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&t->mu);
    return rc;
}

/* The lookup is by the token's hash: its timing says nothing about the
 * token's characters (an attacker cannot choose the hash's prefix). */
/* Record a token's use: best effort and never waiting (a request that
 * finds the store or the database's write lock busy leaves it to a later
 * one), so a check never waits on another connection's commit. */
static void note_used(pk_tokens *t, const char *hex, double now)
{
    if (pthread_mutex_trylock(&t->mu) != 0)
        return;
    sqlite3_stmt *st = NULL;
    sqlite3_busy_timeout(t->db, 0);
    if (sqlite3_prepare_v2(t->db, "UPDATE tokens SET last_used=? WHERE sha256=?", -1, &st, NULL) ==
        SQLITE_OK) {
        sqlite3_bind_double(st, 1, now);
        sqlite3_bind_text(st, 2, hex, -1, SQLITE_TRANSIENT);
        sqlite3_step(st);
    }
    sqlite3_finalize(st);
    sqlite3_busy_timeout(t->db, 5000);
    pthread_mutex_unlock(&t->mu);
}

int pk_tokens_verify(pk_tokens *t, const char *token, char name[PK_TOKEN_NAME_MAX], int *admin)
{
    if (strncmp(token, PK_TOKEN_PREFIX, strlen(PK_TOKEN_PREFIX)) != 0 ||
        strlen(token) != PK_TOKEN_LEN)
        return 0;
    char hex[65];
    pk_token_hash(token, hex);
    double now = now_s();
    int rc = -1, stale = 0;
    pthread_mutex_lock(&t->rd_mu);
    sqlite3_stmt *st = NULL;
    if (sqlite3_prepare_v2(t->rd,
                           "SELECT name, admin, coalesce(last_used, 0) FROM tokens WHERE sha256=?",
                           -1, &st, NULL) == SQLITE_OK) {
        sqlite3_bind_text(st, 1, hex, -1, SQLITE_TRANSIENT);
        int s = sqlite3_step(st);
        rc = s == SQLITE_ROW ? 1 : s == SQLITE_DONE ? 0 : -1;
        if (rc == 1) {
            snprintf(name, PK_TOKEN_NAME_MAX, "%s", (const char *)sqlite3_column_text(st, 0));
            *admin = sqlite3_column_int(st, 1);
            stale = now - sqlite3_column_double(st, 2) >= LAST_USED_EVERY_S;
        }
    }
    sqlite3_finalize(st);
    pthread_mutex_unlock(&t->rd_mu);
    if (stale)
        note_used(t, hex, now);
    return rc;
}

int pk_tokens_count(pk_tokens *t)
{
    pthread_mutex_lock(&t->mu);
    sqlite3_stmt *st = NULL;
    int n = -1;
    if (sqlite3_prepare_v2(t->db, "SELECT count(*) FROM tokens", -1, &st, NULL) == SQLITE_OK &&
        sqlite3_step(st) == SQLITE_ROW)
        n = sqlite3_column_int(st, 0);
    sqlite3_finalize(st);
    pthread_mutex_unlock(&t->mu);
    return n;
}
