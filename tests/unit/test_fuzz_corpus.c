/* test_fuzz_corpus.c — replay the committed fuzz corpus (tests/fuzz/corpus/
 * <target>/, seeds and every input that once crashed or hung a reader)
 * through the fuzz targets, in the ordinary and the sanitized build: a
 * regression fails here even where clang's libFuzzer is missing.  Each
 * input must finish within 10 s. */
#include <dirent.h>
#include <signal.h>

#include "check.h"
#include "fuzz/target_http.h"
#include "fuzz/targets.h"

FUZZ_SANITIZER_OPTIONS

static const char *current = "";

static void on_alarm(int sig)
{
    (void)sig;
    fprintf(stderr, "FAIL fuzz input %s: no answer within 10 s\n", current);
    _exit(1);
}

static size_t replay(const char *target, void (*fn)(const uint8_t *, size_t))
{
    const char *src = getenv("PACKD_SRC");
    char path[4096];
    snprintf(path, sizeof path, "%s/tests/fuzz/corpus/%s", src ? src : ".", target);
    DIR *d = opendir(path);
    CHECK_MSG(d != NULL, "no corpus %s", path);
    if (!d)
        return 0;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char f[4400];
        snprintf(f, sizeof f, "%s/%s", path, e->d_name);
        FILE *in = fopen(f, "rb");
        if (!in)
            continue;
        uint8_t *buf = malloc(1 << 20);
        size_t len = fread(buf, 1, 1 << 20, in);
        fclose(in);
        current = f;
        alarm(10);
        fn(buf, len);
        alarm(0);
        free(buf);
        n++;
    }
    closedir(d);
    CHECK_MSG(n > 0, "empty corpus %s", path);
    return n;
}

static void test_request(void) { replay("request", fuzz_request); }
static void test_gmsh(void) { replay("gmsh", fuzz_gmsh); }
static void test_tetgen(void) { replay("tetgen", fuzz_tetgen); }
static void test_h5_rve(void) { replay("h5_rve", fuzz_h5_rve); }
static void test_http(void) { replay("http", fuzz_http); }

int main(void)
{
    signal(SIGALRM, on_alarm);
    RUN(test_request);
    RUN(test_gmsh);
    RUN(test_tetgen);
    RUN(test_h5_rve);
    RUN(test_http);
    return check_summary();
}
