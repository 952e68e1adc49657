/* test_tokens.c — daemon/store/tokens.c: the token's form, its SHA-256 (FIPS
 * 180-2 test vector), the store on a real SQLite file (add, verify, list,
 * revoke, names), uploads owned per (sha256, owner) after the migration, and
 * no token in clear anywhere in the database files. */
#define _GNU_SOURCE /* memmem */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "daemon/store/queue.h"
#include "daemon/store/tokens.h"

static char dir[] = "/tmp/pk_tokens_XXXXXX";
static char db[256];

static void test_hash_vector(void)
{
    char hex[65];
    pk_token_hash("abc", hex);
    CHECK(!strcmp(hex, "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"));
    pk_token_hash("", hex);
    CHECK(!strcmp(hex, "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"));
}

static void test_generate(void)
{
    char a[PK_TOKEN_LEN + 1], b[PK_TOKEN_LEN + 1];
    CHECK(pk_token_generate(a) == 0 && pk_token_generate(b) == 0);
    CHECK(strlen(a) == PK_TOKEN_LEN && !strncmp(a, PK_TOKEN_PREFIX, strlen(PK_TOKEN_PREFIX)));
    CHECK(strspn(a + strlen(PK_TOKEN_PREFIX),
                 "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_") ==
          PK_TOKEN_LEN - strlen(PK_TOKEN_PREFIX));
    CHECK(strcmp(a, b) != 0);
}

static void test_names(void)
{
    CHECK(pk_token_name_ok("alice") && pk_token_name_ok("ci-runner.lab_2@host"));
    CHECK(!pk_token_name_ok("") && !pk_token_name_ok("a b") && !pk_token_name_ok("a/b") &&
          !pk_token_name_ok("x\n"));
    char longname[PK_TOKEN_NAME_MAX + 1];
    memset(longname, 'a', PK_TOKEN_NAME_MAX);
    longname[PK_TOKEN_NAME_MAX] = 0;
    CHECK(!pk_token_name_ok(longname));
}

/* 1 if needle occurs in any of the database's files. */
static int in_db_files(const char *needle)
{
    const char *suffix[] = {"", "-wal", "-shm"};
    for (int i = 0; i < 3; i++) {
        char p[300];
        snprintf(p, sizeof p, "%s%s", db, suffix[i]);
        FILE *f = fopen(p, "rb");
        if (!f)
            continue;
        size_t cap = 1 << 20, n = 0;
        char *buf = malloc(cap);
        size_t got;
        while ((got = fread(buf + n, 1, cap - n, f)) > 0) {
            n += got;
            if (n == cap)
                buf = realloc(buf, cap *= 2);
        }
        fclose(f);
        int hit = memmem(buf, n, needle, strlen(needle)) != NULL;
        free(buf);
        if (hit)
            return 1;
    }
    return 0;
}

static void test_store(void)
{
    char err[256], alice[PK_TOKEN_LEN + 1], root[PK_TOKEN_LEN + 1], other[PK_TOKEN_LEN + 1];
    pk_tokens *t = pk_tokens_open(db, err, sizeof err);
    CHECK_MSG(t != NULL, "%s", err);
    if (!t)
        return;
    CHECK(pk_tokens_count(t) == 0);
    CHECK(pk_tokens_add(t, "alice", 0, alice, err, sizeof err) == 0);
    CHECK(pk_tokens_add(t, "root", 1, root, err, sizeof err) == 0);
    CHECK(pk_tokens_add(t, "alice", 1, other, err, sizeof err) == -1 && strstr(err, "exists"));
    CHECK(pk_tokens_add(t, "no good", 0, other, err, sizeof err) == -1);

    char name[PK_TOKEN_NAME_MAX];
    int admin = -1;
    CHECK(pk_tokens_verify(t, alice, name, &admin) == 1 && !strcmp(name, "alice") && admin == 0);
    CHECK(pk_tokens_verify(t, root, name, &admin) == 1 && !strcmp(name, "root") && admin == 1);
    char wrong[PK_TOKEN_LEN + 1];
    memcpy(wrong, alice, sizeof wrong);
    wrong[PK_TOKEN_LEN - 1] = wrong[PK_TOKEN_LEN - 1] == 'A' ? 'B' : 'A';
    CHECK(pk_tokens_verify(t, wrong, name, &admin) == 0);
    CHECK(pk_tokens_verify(t, "", name, &admin) == 0);
    CHECK(pk_tokens_verify(t, alice + strlen(PK_TOKEN_PREFIX), name, &admin) == 0);

    json_t *l = pk_tokens_list(t);
    CHECK(json_array_size(l) == 2);
    char *text = json_dumps(l, 0);
    CHECK(text && !strstr(text, alice) && !strstr(text, root) && strstr(text, "\"alice\""));
    CHECK(json_is_number(json_object_get(json_array_get(l, 0), "last_used"))); /* verified above */
    free(text);
    json_decref(l);

    CHECK(!in_db_files(alice) && !in_db_files(root));
    char hex[65];
    pk_token_hash(alice, hex);
    CHECK(in_db_files(hex));

    /* a second connection (the CLI beside the daemon) sees a revocation at once */
    pk_tokens *cli = pk_tokens_open(db, err, sizeof err);
    CHECK(cli && pk_tokens_revoke(cli, "alice") == 1 && pk_tokens_revoke(cli, "alice") == 0);
    pk_tokens_close(cli);
    CHECK(pk_tokens_verify(t, alice, name, &admin) == 0);
    CHECK(pk_tokens_count(t) == 1);
    CHECK(pk_tokens_add(t, "alice", 0, other, err, sizeof err) == 0); /* a new token for the name */
    CHECK(pk_tokens_verify(t, other, name, &admin) == 1 && !strcmp(name, "alice"));
    pk_tokens_close(t);
}

static void test_uploads_per_owner(void)
{
    char err[256];
    pk_queue *q = pk_queue_open(db, err, sizeof err);
    CHECK_MSG(q != NULL, "%s", err);
    if (!q)
        return;
    const char *sha = "ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12ab12";
    CHECK(pk_queue_add_file(q, sha, sha, 10, "text/plain", "alice") == 0);
    json_t *f = pk_queue_get_file(q, sha, "bob");
    CHECK(f == NULL);
    json_decref(f);
    CHECK(pk_queue_add_file(q, sha, sha, 10, "text/plain", "bob") == 0);
    CHECK(pk_queue_add_file(q, sha, sha, 10, "text/plain", "bob") == 0); /* again: no error */
    f = pk_queue_get_file(q, sha, "bob");
    CHECK(f != NULL);
    json_decref(f);
    f = pk_queue_get_file(q, sha, NULL); /* an admin: any owner's */
    CHECK(f != NULL);
    json_decref(f);
    pk_queue_close(q);
}

int main(void)
{
    if (!mkdtemp(dir))
        return 1;
    snprintf(db, sizeof db, "%s/queue.db", dir);
    RUN(test_hash_vector);
    RUN(test_generate);
    RUN(test_names);
    RUN(test_store);
    RUN(test_uploads_per_owner);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    return check_summary();
}
