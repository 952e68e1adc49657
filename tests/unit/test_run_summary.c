/* test_run_summary.c — the human summary of `packd run` (daemon/cli/run_summary.h):
 * the smallest gap never reads as the bound it misses. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "daemon/cli/run_summary.h"

static char *printed(double gap, long long below)
{
    json_t *s = json_pack("{s:s,s:s,s:b,s:i,s:i,s:f,s:I}", "process", "pack", "algorithm", "rsa",
                          "complete", below == 0, "count_placed", 10, "count_requested", 10,
                          "smallest_gap", gap, "pairs_below_delta_d", (json_int_t)below);
    char *text = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&text, &n);
    pk_run_summary_print(f, s, "out.h5", NULL, 1.0, 0);
    fclose(f);
    json_decref(s);
    return text;
}

static void test_violation_never_reads_as_bound(void)
{
    char *t = printed(0.9999996, 1);
    CHECK_MSG(strstr(t, "smallest 0.9999996, 1 pairs below the minimum"), "%s", t);
    free(t);
    t = printed(1 - 1e-12, 1); /* just past the audit's tolerance */
    CHECK_MSG(strstr(t, "smallest 0.999999999999, 1 pairs below"), "%s", t);
    free(t);
}

static void test_gap_digits(void)
{
    char *t = printed(1.00000418, 0); /* the worked example's figure */
    CHECK_MSG(strstr(t, "  gap       smallest 1.00000418, 0 pairs below the minimum\n"), "%s", t);
    free(t);
    char g[32];
    pk_run_summary_gap_text(0.5, 0, g, sizeof g);
    CHECK(!strcmp(g, "0.5"));
    pk_run_summary_gap_text(1 - 1e-15, 3, g, sizeof g);
    CHECK_MSG(strtod(g, NULL) == 1 - 1e-15, "%s", g);
}

int main(void)
{
    RUN(test_violation_never_reads_as_bound);
    RUN(test_gap_digits);
    return check_summary();
}
