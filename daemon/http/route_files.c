/* POST /files (upload a mesh or RVE file) and GET /files/{id}.  Files are
 * content-addressed: the id is the SHA-256 of the bytes, so an upload
 * repeated is stored once; each owner who sends the bytes owns the upload. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "auth.h"
#include "http.h"
#include "api/digest.h"

static int write_all(const char *path, const char *data, size_t n)
{
    char tmp[1400];
    if (snprintf(tmp, sizeof tmp, "%s.tmp.%d", path, (int)getpid()) >= (int)sizeof tmp)
        return -1;
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
    if (fd < 0)
        return -1;
    size_t off = 0;
    while (off < n) {
        ssize_t w = write(fd, data + off, n - off);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            close(fd);
            unlink(tmp);
            return -1;
        }
        off += (size_t)w;
    }
    if (fsync(fd) != 0 || close(fd) != 0 || rename(tmp, path) != 0) {
        unlink(tmp);
        return -1;
    }
    return 0;
}

enum MHD_Result route_files_post(pk_req *r)
{
    if (r->body_len == 0)
        return pk_reply_problem(r, PK_P_BAD_REQUEST, "empty upload");
    pk_config cfg = pk_service_config(r->svc);
    char hex[65], dir[1100], path[1200], owner[128], href[80];
    pk_sha256_hex(r->body, r->body_len, hex);
    snprintf(dir, sizeof dir, "%s/files", cfg.data);
    mkdir(dir, 0750);
    snprintf(path, sizeof path, "%s/%s", dir, hex);
    const char *ct = pk_header(r, "Content-Type"); /* not a form type (http_server.c) */
    pk_owner(r, owner, sizeof owner);
    if (write_all(path, r->body, r->body_len) != 0 ||
        pk_queue_add_file(r->svc->q, hex, hex, (long long)r->body_len, ct, owner) != 0)
        return pk_reply_problem(r, PK_P_INTERNAL, "cannot store the file");
    snprintf(href, sizeof href, "/files/%s", hex);
    json_t *doc = json_pack("{s:s,s:s,s:s,s:I,s:s}", "id", hex, "href", href, "sha256", hex, "size",
                            (json_int_t)r->body_len, "type", ct);
    struct MHD_Response *resp = pk_json_response(doc, "application/json");
    if (resp)
        MHD_add_response_header(resp, "Location", href);
    return pk_send(r, 201, resp);
}

enum MHD_Result route_file_get(pk_req *r)
{
    json_t *f = pk_queue_get_file(r->svc->q, r->seg[1], pk_scope(r));
    if (!f)
        return pk_reply_problem(r, PK_P_NO_SUCH_FILE, r->seg[1]);
    pk_config cfg = pk_service_config(r->svc);
    char path[1200];
    snprintf(path, sizeof path, "%s/files/%s", cfg.data, r->seg[1]);
    /* an upload is data, never a page: whatever type it was sent with, it
     * goes back as bytes to save (pk_send_file adds nosniff and a sandbox) */
    const char *sent = json_string_value(json_object_get(f, "media_type"));
    const char *ctype = sent && !strcasecmp(sent, "application/x-hdf5")
        ? "application/x-hdf5"
        : "application/octet-stream";
    enum MHD_Result rc =
        pk_send_file(r, path, ctype, json_string_value(json_object_get(f, "sha256")), r->seg[1]);
    json_decref(f);
    return rc;
}
