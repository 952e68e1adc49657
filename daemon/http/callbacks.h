/* callbacks.h — OGC API - Processes "subscriber" callbacks: every status
 * change of a job whose execute request named a subscriber is POSTed there
 * (inProgressUri: the statusInfo of accepted and running; successUri: the
 * results document; failedUri: the statusInfo of the failed job), as JSON,
 * by one thread that follows the queue's status events and runs the POSTs
 * side by side (libcurl multi; a bounded share per owner, a job's in
 * order), so a receiver that hangs delays no other owner's.  A delivery
 * answered other than 2xx is retried (RETRIES times, backing off); one to
 * a private, loopback or link-local address is refused unless that address
 * is in the config key callback_allow (checked on the address connected
 * to, so a name that resolves there is refused too).  The last event
 * handed on is kept in DATA/callbacks.last: a restart goes on from there. */
#ifndef PK_CALLBACKS_H
#define PK_CALLBACKS_H

#include "daemon/service.h"

int pk_callbacks_start(pk_service *svc);
void pk_callbacks_stop(void);

/* 1 when a callback may connect to ip (text form): a public address, or
 * one listed in allow (comma-separated). */
int pk_callback_address_ok(const char *ip, const char *allow);

#endif
