/* log.h — the daemon's logs: one JSON object per line on stderr
 * {"ts":"2026-11-22T03:04:05.123Z","level":"info","msg":"...", more fields}.
 * Thread-safe; the level can change at run time (SIGHUP). */
#ifndef PK_LOG_H
#define PK_LOG_H

#include "config.h"

void pk_log_set_level(pk_log_level l);

/* Fields are given as a jansson pack format and its arguments, e.g.
 *   pk_log(PK_LOG_INFO, "job started", "{s:s,s:i}", "job", id, "pid", pid);
 * fmt may be NULL for no extra fields. */
void pk_log(pk_log_level l, const char *msg, const char *fmt, ...);

#endif
