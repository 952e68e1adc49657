/* test_uuid.c — daemon/store/uuid.c: the RFC 9562 version 4 text form (36
 * characters, dashes at 8-13-18-23, version nibble 4, variant 8/9/a/b,
 * lower-case hex) and no repeat among 10 000 fresh ids. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "daemon/store/uuid.h"

static int format_ok(const char *u)
{
    if (strlen(u) != PK_UUID_LEN)
        return 0;
    for (int i = 0; i < PK_UUID_LEN; i++) {
        int dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash != (u[i] == '-'))
            return 0;
        if (!dash && !((u[i] >= '0' && u[i] <= '9') || (u[i] >= 'a' && u[i] <= 'f')))
            return 0;
    }
    return u[14] == '4' && strchr("89ab", u[19]) != NULL;
}

static void test_format(void)
{
    CHECK(format_ok("f47ac10b-58cc-4372-a567-0e02b2c3d479")); /* RFC 9562's example */
    CHECK(!format_ok("f47ac10b-58cc-1372-a567-0e02b2c3d479"));
    CHECK(!format_ok("f47ac10b-58cc-4372-c567-0e02b2c3d479"));
    for (int i = 0; i < 1000; i++) {
        char u[PK_UUID_LEN + 1];
        CHECK(pk_uuid4(u) == 0);
        CHECK_MSG(format_ok(u), "%s", u);
    }
}

static int cmp(const void *a, const void *b) { return strcmp(a, b); }

/* Distinct, and every one of the 122 random bits varies: a constant or
 * time-only source would fail one or the other. */
static void test_unique(void)
{
    enum { N = 10000 };
    char(*u)[PK_UUID_LEN + 1] = malloc(sizeof *u * N);
    CHECK(u != NULL);
    for (int i = 0; i < N; i++)
        CHECK(pk_uuid4(u[i]) == 0);
    char seen_or[PK_UUID_LEN + 1], seen_and[PK_UUID_LEN + 1];
    memset(seen_or, 0, sizeof seen_or);
    memset(seen_and, 0x7f, sizeof seen_and);
    for (int i = 0; i < N; i++)
        for (int k = 0; k < PK_UUID_LEN; k++) {
            seen_or[k] |= u[i][k];
            seen_and[k] &= u[i][k];
        }
    int varied = 0;
    for (int k = 0; k < PK_UUID_LEN; k++)
        varied += seen_or[k] != seen_and[k];
    CHECK_MSG(varied == PK_UUID_LEN - 5, "%d positions vary", varied); /* 4 dashes, the version */
    qsort(u, N, sizeof *u, cmp);
    int dup = 0;
    for (int i = 1; i < N; i++)
        dup += !strcmp(u[i - 1], u[i]);
    CHECK_MSG(dup == 0, "%d repeated ids", dup);
    free(u);
}

int main(void)
{
    RUN(test_format);
    RUN(test_unique);
    return check_summary();
}
