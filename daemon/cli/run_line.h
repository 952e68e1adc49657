/* run_line.h — `packd run`'s live progress line on a terminal: one line on
 * stderr, redrawn in place from the pk_monitor callbacks (stage, %, φ or
 * step, elapsed, estimated remaining). */
#ifndef PK_RUN_LINE_H
#define PK_RUN_LINE_H

#include <stdio.h>

#include "core/base/progress.h"

typedef struct pk_run_line {
    FILE *tty; /* NULL: no line (not a terminal) */
    int utf8;  /* the locale takes "φ" */
    int cols;  /* the terminal's width */
    int drawn; /* a line is on the screen */
    double t0; /* the run's start (wall seconds) */
    /* the last stage that knew its fraction: an inner stage without one
     * (a relaxation inside a homogenization step) is shown beside it */
    char outer[24];
    double fraction, phi, eta_s, delta_d, t_outer;
    size_t done, total;
} pk_run_line;

/* The line goes to tty when it is a terminal (and TERM is not "dumb"). */
void pk_run_line_init(pk_run_line *l, FILE *tty);

/* Redraw from one progress report (the monitor rate-limits the calls). */
void pk_run_line_draw(pk_run_line *l, const pk_progress *p);

/* Erase the line, so that messages and the summary start on a clean line. */
void pk_run_line_clear(pk_run_line *l);

/* Format seconds as "12.3 s", "4 min 05 s", "1 h 02 min". */
void pk_run_line_duration(double s, char *out, size_t n);

#endif
