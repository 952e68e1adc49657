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

/* A short human summary: process, status, grains, φ achieved vs target (or
 * the homogenization's steps), wall time, warnings, failure, the output
 * files (xdmf NULL = none written). */
void pk_run_summary_print(FILE *f, const json_t *summary, const char *output, const char *xdmf,
                          double seconds, int utf8);

#endif
