/* check.h — the tiny test harness every unit test uses.
 *
 *   static void test_something(void) { CHECK(x == 1); CHECK_NEAR(a, b, tol); }
 *   int main(void) { RUN(test_something); return check_summary(); }
 *
 * Each RUN is one test case: it passes if none of its CHECKs failed.  The
 * binary prints "PASS name" / "FAIL name" lines and exits non-zero on any
 * failure; a case that cannot run on this machine is SKIP(name, reason...)
 * instead ("SKIP name: reason", neither passed nor failed).  tests/run.sh
 * adds the cases of all binaries into the final "N passed, N failed, N
 * skipped" line. */
#ifndef PK_CHECK_H
#define PK_CHECK_H

#include <math.h>
#include <stdio.h>

static int check_case_failed, check_passed, check_failed;

#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "  %s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond);             \
            check_case_failed = 1;                                                                 \
        }                                                                                          \
    } while (0)

#define CHECK_MSG(cond, ...)                                                                       \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "  %s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);             \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            check_case_failed = 1;                                                                 \
        }                                                                                          \
    } while (0)

/* |a-b| <= tol, with both values printed on failure. */
#define CHECK_NEAR(a, b, tol)                                                                      \
    do {                                                                                           \
        double check_a_ = (a), check_b_ = (b), check_t_ = (tol);                                   \
        if (!(fabs(check_a_ - check_b_) <= check_t_)) {                                            \
            fprintf(stderr, "  %s:%d: |%s - %s| = |%.17g - %.17g| > %g\n", __FILE__, __LINE__, #a, \
                    #b, check_a_, check_b_, check_t_);                                             \
            check_case_failed = 1;                                                                 \
        }                                                                                          \
    } while (0)

#define RUN(fn)                                                                                    \
    do {                                                                                           \
        check_case_failed = 0;                                                                     \
        fn();                                                                                      \
        if (check_case_failed) {                                                                   \
            check_failed++;                                                                        \
            printf("FAIL %s\n", #fn);                                                              \
        } else {                                                                                   \
            check_passed++;                                                                        \
            printf("PASS %s\n", #fn);                                                              \
        }                                                                                          \
        fflush(stdout);                                                                            \
    } while (0)

#define SKIP(fn, ...)                                                                              \
    do {                                                                                           \
        printf("SKIP %s: ", #fn);                                                                  \
        printf(__VA_ARGS__);                                                                       \
        putchar('\n');                                                                             \
        fflush(stdout);                                                                            \
    } while (0)

static inline int check_summary(void) { return check_failed ? 1 : 0; }

#endif
