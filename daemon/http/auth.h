/* auth.h — who a request is and what it may see (docs/service.md, "Tokens
 * and owners").  The dispatcher calls pk_authorize once per request, before
 * the handler; handlers look jobs up through pk_job_visible and scope lists
 * and uploads with pk_scope, so another owner's job is answered exactly like
 * one that does not exist. */
#ifndef PK_AUTH_H
#define PK_AUTH_H

#include "http.h"

/* 1 when bearer tokens are required: auth = on, or auto with a bind address
 * that is not loopback or with a trusted proxy (which forwards anyone).  why (may be NULL) gets a sentence for the log. */
int pk_auth_required(const pk_config *c, const char **why);

/* Set r->owner and r->admin for a route of the given access.  Returns 1 to
 * go on to the handler, 0 after replying 401 (no or a wrong token, with
 * WWW-Authenticate: Bearer), 403 (not an admin) or 503 (token store down);
 * *reply is then the MHD result to return. */
int pk_authorize(pk_req *r, pk_access access, enum MHD_Result *reply);

/* The owner a request's lookups are limited to; NULL for an admin (all). */
const char *pk_scope(const pk_req *r);

/* The job row (as pk_queue_get) if the job exists and this request may see
 * it; NULL otherwise. */
json_t *pk_job_visible(pk_req *r, const char *id);

#endif
