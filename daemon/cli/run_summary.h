/* run_summary.h — what `packd run` prints when the job ends: the summary as
 * JSON (for programs and the service's workers), or a few lines for a
 * person on a terminal. */
#ifndef PK_RUN_SUMMARY_H
#define PK_RUN_SUMMARY_H

#include <jansson.h>
#include <stdio.h>

/* Take the time series out of the printed summary: every member named
 * "history" (EDMD's φ(t)), at any depth.  They stay in the result file
 * under /observables/ (docs/result-format.md). */
void pk_run_summary_drop_series(json_t *summary);

/* The smallest gap as the summary prints it: 9 significant digits, and with
 * pairs below the minimum as many as it takes to read back the exact value,
 * so a violation never reads as the bound it misses (0.9999996 is never
 * "1" beside "1 pairs below the minimum"). */
void pk_run_summary_gap_text(double gap, long long pairs_below, char *out, size_t n);

/* A short human summary: process, status, grains, φ achieved vs target (or
 * the homogenization's steps), wall time, warnings, failure, the output
 * files (xdmf NULL = none written). */
void pk_run_summary_print(FILE *f, const json_t *summary, const char *output, const char *xdmf,
                          double seconds, int utf8);

#endif
