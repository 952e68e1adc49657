/* log.c — the daemon's JSON-lines logs on stderr.
 * Contract: daemon/log.h. */
#include "log.h"

#include "api/http/http_time.h"

#include <jansson.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static pk_log_level min_level = PK_LOG_INFO;
static pthread_mutex_t log_lock = PTHREAD_MUTEX_INITIALIZER;

void pk_log_set_level(pk_log_level l) { __atomic_store_n(&min_level, l, __ATOMIC_RELAXED); }

void pk_log(pk_log_level l, const char *msg, const char *fmt, ...)
{
    if (l < __atomic_load_n(&min_level, __ATOMIC_RELAXED))
        return;
    json_t *o = NULL;
    if (fmt) {
        va_list ap;
        va_start(ap, fmt);
        json_error_t jerr;
        o = json_vpack_ex(&jerr, 0, fmt, ap);
        va_end(ap);
    }
    if (!o)
        o = json_object();
    char t[64];
    pk_time_rfc3339(-1, t);
    json_object_set_new(o, "ts", json_string(t));
    json_object_set_new(o, "level", json_string(pk_log_level_name(l)));
    json_object_set_new(o, "msg", json_string(msg));
    char *line = json_dumps(o, JSON_COMPACT | JSON_PRESERVE_ORDER);
    json_decref(o);
    if (!line)
        return;
    pthread_mutex_lock(&log_lock);
    fprintf(stderr, "%s\n", line);
    fflush(stderr);
    pthread_mutex_unlock(&log_lock);
    free(line);
}
