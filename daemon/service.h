/* service.h — the state one `packd serve` shares between its HTTP threads,
 * the executor's threads and the signal loop. */
#ifndef PK_SERVICE_H
#define PK_SERVICE_H

#include <pthread.h>

#include "config.h"
#include "executor.h"
#include "daemon/store/queue.h"
#include "daemon/store/tokens.h"

typedef struct pk_service {
    pthread_mutex_t mu; /* guards cfg (SIGHUP replaces it) */
    pk_config cfg;
    pk_queue *q;
    pk_tokens *tokens; /* bearer tokens (auth.c); its own connection to queue.db */
    pk_executor *exec; /* where jobs run (local workers or Slurm) */
    int draining;      /* SIGTERM received: refuse new jobs (atomic) */
    int stopping;      /* streams must end now (atomic) */
    double started;
    unsigned long long responses[600];           /* by HTTP status (atomic) */
    unsigned long long cache_hits, cache_misses; /* execute requests (atomic), result_cache.h */
} pk_service;

/* A copy of the current configuration. */
pk_config pk_service_config(pk_service *s);

#endif
