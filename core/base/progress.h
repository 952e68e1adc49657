/* progress.h — how long-running core loops report progress and notice cancellation.
 *
 * Every long loop in core/ (RSA, EDMD, tet filling, DEM relaxation) takes a
 * pk_monitor.  The loop calls pk_monitor_tick() cheaply and often; the monitor
 * rate-limits the user callback to `interval_s` of wall time and checks the
 * cancel flag on every tick, so cancellation is honoured well within a second.
 * core/ never knows whether the callback writes to a pipe, a terminal or SSE.
 */
#ifndef PK_PROGRESS_H
#define PK_PROGRESS_H

#include <signal.h>
#include <stddef.h>

typedef struct pk_progress {
    const char *stage;   /* "sizes", "rsa", "edmd", ... */
    double fraction;     /* 0..1 of the stage, or <0 when unknown */
    double phi;          /* current solid fraction (resolved), <0 if n/a */
    size_t done;         /* items finished (particles placed, events, ...) */
    size_t total;        /* items planned, 0 if unknown */
    double elapsed_s;    /* wall time since the stage began */
    double eta_s;        /* estimated seconds left, <0 if unknown */
    double delta_d;      /* shell growth: the gap Δd grown so far (φ stays); 0 otherwise */
    const char *message; /* optional short text, may be NULL */
} pk_progress;

/* Return non-zero from the callback to request cancellation. */
typedef int (*pk_progress_fn)(const pk_progress *p, void *ctx);

typedef struct pk_monitor {
    pk_progress_fn fn; /* may be NULL */
    void *ctx;
    volatile sig_atomic_t *cancel; /* may be NULL; non-zero = stop now */
    double interval_s;             /* min wall time between callbacks (default 0.5) */
    double wall_limit_s;           /* 0 = none; exceeded => stop with reason.  Set it
                                        * with pk_monitor_start: it counts from there */
    double length_unit;            /* a loop in scaled lengths reports x·length_unit (0 = 1) */
    /* private */
    double t_start, t_last, t_job;
    int cancelled, begun;
} pk_monitor;

/* Wall clock in seconds (monotonic where the C library offers it). */
double pk_wall_seconds(void);

/* A stage begins: elapsed_s counts from here.  The job's clock (the wall
 * limit's origin) starts at the first begin, start or tick, whichever comes
 * first: a monitor never begun does not compare its limit with the
 * machine's uptime. */
void pk_monitor_begin(pk_monitor *m);

/* The job begins: its clock starts now, with this wall-time limit (0 =
 * none), across all its stages. */
void pk_monitor_start(pk_monitor *m, double wall_limit_s);

/* Returns 0 to continue, 1 if cancelled (flag or callback), 2 if the wall limit
 * was exceeded.  `p->elapsed_s` is filled in by the monitor.  Cheap when the
 * interval has not elapsed: call it every few hundred iterations. */
int pk_monitor_tick(pk_monitor *m, pk_progress *p, int force);

/* The same stop check as pk_monitor_tick (cancel flag, wall limit), without
 * a report: for a stage boundary that has no progress to give. */
int pk_monitor_check(pk_monitor *m);

#endif
