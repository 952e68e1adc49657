/* client_http.h — the HTTP side of packd's command-line client (submit, jobs,
 * cancel, fetch) over libcurl: JSON requests, streamed downloads hashed with
 * SHA-256 on the way (api/digest.h), and Server-Sent Events.  Every request
 * carries `Authorization: Bearer TOKEN` when a token is set. */
#ifndef PK_CLIENT_HTTP_H
#define PK_CLIENT_HTTP_H

#include <jansson.h>
#include <stddef.h>

typedef struct pk_client {
    const char *server; /* base URL, e.g. http://127.0.0.1:8080 (no trailing slash needed) */
    const char *token;  /* bearer token or NULL */
} pk_client;

typedef struct pk_reply {
    long status;            /* HTTP status; 0 when no answer came (transport error) */
    char *body;             /* the body (NUL-terminated), NULL for downloads */
    size_t len;             /* bytes received */
    char sha256_header[65]; /* X-Content-SHA256, "" if absent */
    char error[512];        /* transport error text when status == 0 */
} pk_reply;

void pk_reply_free(pk_reply *r);
/* The body parsed as JSON (new reference), NULL if it is not JSON. */
json_t *pk_reply_json(const pk_reply *r);

/* One request; path starts with '/' (or is an absolute http(s) URL, used as
 * it is).  body
 * may be NULL; when set it is sent as application/json.  Returns 0 when an
 * HTTP answer came (any status), -1 on a transport error (r->error). */
int pk_client_request(const pk_client *c, const char *method, const char *path, const char *body,
                      pk_reply *r);

/* GET path into file, hashing the bytes as they arrive: hex gets the
 * SHA-256 of what was written.  Returns as pk_client_request; on a non-2xx
 * answer the file is removed and r->body holds the (problem) document. */
int pk_client_download(const pk_client *c, const char *path, const char *file, char hex[65],
                       pk_reply *r);

/* GET a text/event-stream and call fn for each event (event name, data, id);
 * fn returns non-zero to stop.  Returns as pk_client_request when the stream
 * ends. */
typedef int (*pk_sse_fn)(const char *event, const char *data, const char *id, void *ctx);
int pk_client_events(const pk_client *c, const char *path, const char *last_event_id, pk_sse_fn fn,
                     void *ctx, pk_reply *r);

/* Check a downloaded file's digest against what the service declared (the
 * results document's sha256 and the X-Content-SHA256 header; either may be
 * NULL or ""; at least one must be present).  0 when every declared digest
 * matches `got`, else -1 with the reason in err. */
int pk_client_verify(const char *got, const char *declared_doc, const char *declared_header,
                     char *err, size_t errlen);

#endif
