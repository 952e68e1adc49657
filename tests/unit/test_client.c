/* test_client.c — the client's integrity check, pk_client_verify against the
 * results document's digest and the X-Content-SHA256 header (the file's
 * SHA-256 itself: test_sha256.c); and the client options' precedence (flag,
 * environment, built-in default). */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "daemon/cli/client_args.h"
#include "daemon/cli/client_http.h"

#define ABC "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"

static void test_verify(void)
{
    char err[300];
    char other[] = ABC;
    other[0] = 'c';
    CHECK(pk_client_verify(ABC, ABC, ABC, err, sizeof err) == 0);
    CHECK(pk_client_verify(ABC, ABC, "", err, sizeof err) == 0);
    CHECK(pk_client_verify(ABC, NULL, ABC, err, sizeof err) == 0);
    CHECK(pk_client_verify(ABC, other, ABC, err, sizeof err) == -1 &&
          strstr(err, "results document"));
    CHECK(pk_client_verify(ABC, ABC, other, err, sizeof err) == -1 &&
          strstr(err, "X-Content-SHA256"));
    CHECK(pk_client_verify(ABC, NULL, NULL, err, sizeof err) ==
          -1); /* nothing declared: not verified */
    CHECK(pk_client_verify("", ABC, ABC, err, sizeof err) == -1);
}

static void test_option_precedence(void)
{
    pk_client_args a;
    unsetenv("PACKD_SERVER");
    unsetenv("PACKD_TOKEN");
    char *v1[] = {"jobs", NULL};
    CHECK(pk_client_parse(1, v1, &a) == 0);
    CHECK(!strcmp(a.server, "http://127.0.0.1:8080") && a.token == NULL && !strcmp(a.limit, "20"));
    setenv("PACKD_SERVER", "http://env:1", 1);
    setenv("PACKD_TOKEN", "envtok", 1);
    CHECK(pk_client_parse(1, v1, &a) == 0);
    CHECK(!strcmp(a.server, "http://env:1") && !strcmp(a.token, "envtok"));
    char *v2[] = {"submit", "job.json", "--server", "http://flag:2", "--token", "t",
                  "-o",     "x.h5",     NULL};
    CHECK(pk_client_parse(8, v2, &a) == 0);
    CHECK(!strcmp(a.server, "http://flag:2") && !strcmp(a.token, "t") && a.wait == 1 &&
          !strcmp(a.arg, "job.json"));
    char *v3[] = {"fetch", "ID", NULL}; /* fetch needs -o */
    CHECK(pk_client_parse(2, v3, &a) == 64);
    char *v4[] = {"cancel", "ID", "--wait", NULL}; /* --wait is submit's */
    CHECK(pk_client_parse(3, v4, &a) == 64);
    unsetenv("PACKD_SERVER");
    unsetenv("PACKD_TOKEN");
}

int main(void)
{
    RUN(test_verify);
    RUN(test_option_precedence);
    return check_summary();
}
