/* progress.c — the wall clock and the monitor that rate-limits progress
 * callbacks and notices cancellation.  Contract: core/base/progress.h. */
#include "progress.h"

#include <time.h>

double pk_wall_seconds(void)
{
    /* POSIX monotonic clock: wall-clock jumps must not cancel a run. */
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void pk_monitor_begin(pk_monitor *m)
{
    if (!m)
        return;
    if (m->interval_s <= 0)
        m->interval_s = 0.5;
    m->t_start = pk_wall_seconds();
    m->t_last = m->t_start - m->interval_s; /* first tick reports */
    m->cancelled = 0;
    if (!m->begun) {
        m->t_job = m->t_start;
        m->begun = 1;
    }
}

void pk_monitor_start(pk_monitor *m, double wall_limit_s)
{
    if (!m)
        return;
    m->wall_limit_s = wall_limit_s > 0 ? wall_limit_s : 0;
    m->begun = 0;
    pk_monitor_begin(m);
}

int pk_monitor_check(pk_monitor *m)
{
    if (!m)
        return 0;
    if (!m->begun)
        pk_monitor_begin(m);
    if (m->cancelled)
        return m->cancelled;
    if (m->cancel && *m->cancel)
        return m->cancelled = 1;
    if (m->wall_limit_s > 0 && pk_wall_seconds() - m->t_job > m->wall_limit_s)
        return m->cancelled = 2;
    return 0;
}

int pk_monitor_tick(pk_monitor *m, pk_progress *p, int force)
{
    int stop = pk_monitor_check(m);
    if (!m || stop)
        return stop;
    double now = pk_wall_seconds();
    if (!force && now - m->t_last < m->interval_s)
        return 0;
    m->t_last = now;
    p->elapsed_s = now - m->t_start;
    if (!m->fn)
        return 0;
    pk_progress shown = *p; /* lengths in the caller's unit */
    shown.delta_d *= m->length_unit > 0 ? m->length_unit : 1;
    if (m->fn(&shown, m->ctx))
        return m->cancelled = 1;
    return 0;
}
