/* executor.c — the back end the configuration names, and the calls through
 * its operations; contract in executor.h. */
#include "executor.h"

#include <stdio.h>
#include <string.h>

#include "log.h"

pk_executor *pk_executor_start(pk_queue *q, const char *exe, const pk_config *c, char *err,
                               size_t errlen)
{
    if (c->executor == PK_EXECUTOR_SLURM)
        return pk_executor_slurm_start(q, exe, c, err, errlen);
    int failed = 0, requeued = pk_queue_recover(q, c->max_attempts, &failed);
    if (requeued || failed)
        pk_log(PK_LOG_WARN, "recovered jobs of a previous run", "{s:i,s:i}", "requeued", requeued,
               "failed", failed);
    pk_executor *e = pk_executor_local_start(q, exe, c, 0);
    if (!e)
        snprintf(err, errlen, "cannot start the worker thread");
    return e;
}

void pk_executor_configure(pk_executor *e, const pk_config *c) { e->ops->configure(e, c); }

void pk_executor_wake(pk_executor *e)
{
    if (e)
        e->ops->wake(e);
}

int pk_executor_busy(pk_executor *e) { return e->ops->busy(e); }

int pk_executor_capacity(pk_executor *e) { return e->ops->capacity(e); }

int pk_executor_healthy(pk_executor *e, char *why, size_t n)
{
    if (n)
        why[0] = 0;
    return e->ops->healthy(e, why, n);
}

const char *pk_executor_name(const pk_executor *e) { return e->ops->name; }

int pk_executor_poll_stats(pk_executor *e, long long *cycles, double *seconds)
{
    if (!e->ops->poll_stats)
        return 0;
    e->ops->poll_stats(e, cycles, seconds);
    return 1;
}

void pk_executor_stop(pk_executor *e, double grace_s)
{
    if (e)
        e->ops->stop(e, grace_s);
}

void pk_executor_free(pk_executor *e)
{
    if (e)
        e->ops->destroy(e);
}

int pk_executor_unrecorded(pk_executor *e)
{
    return e && e->ops->unrecorded ? e->ops->unrecorded(e) : 0;
}
