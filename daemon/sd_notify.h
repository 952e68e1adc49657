/* sd_notify.h — tell systemd about the service's state (Type=notify units):
 * one datagram to $NOTIFY_SOCKET, as sd_notify(3) does, without linking
 * libsystemd.  A no-op when the variable is unset (not under systemd). */
#ifndef PK_SD_NOTIFY_H
#define PK_SD_NOTIFY_H

/* state: e.g. "READY=1", "RELOADING=1", "STOPPING=1".  0 sent or nothing
 * to do, -1 on a socket error. */
int pk_sd_notify(const char *state);

#endif
