/* host_check.h — the Host header a request may carry (DNS rebinding: a page
 * of attacker.example whose name is made to point at 127.0.0.1 reaches the
 * daemon with Host: attacker.example).  allowed_hosts is a comma-separated
 * list of names and addresses, "*" for any; empty (the default) means the
 * bind address, localhost, 127.0.0.1, ::1, this machine's host name and
 * every address of its interfaces, and the host of public_url.  A port in
 * the header is ignored; a request without Host (HTTP/1.0) passes. */
#ifndef PK_HTTP_HOST_CHECK_H
#define PK_HTTP_HOST_CHECK_H

#include "daemon/config.h"

/* 1 if host (a Host header value, may be NULL) is allowed by cfg. */
int pk_host_allowed(const pk_config *cfg, const char *host);

#endif
