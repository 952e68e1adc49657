/* job_verdict.c — the verdict of a finished job (contract in job_verdict.h). */
#include "job_verdict.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static json_t *vformat(const char *fmt, va_list ap)
{
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    return json_string(buf);
}

void pk_verdict_warn(json_t *summary, const char *fmt, ...)
{
    json_t *w = json_object_get(summary, "warnings");
    if (!json_is_array(w)) {
        w = json_array();
        json_object_set_new(summary, "warnings", w);
    }
    va_list ap;
    va_start(ap, fmt);
    json_array_append_new(w, vformat(fmt, ap));
    va_end(ap);
}

void pk_verdict_fail(json_t *summary, const char *fmt, ...)
{
    json_object_set_new(summary, "complete", json_false());
    if (json_is_string(json_object_get(summary, "failure")))
        return;
    va_list ap;
    va_start(ap, fmt);
    json_object_set_new(summary, "failure", vformat(fmt, ap));
    va_end(ap);
}

int pk_verdict_failed(const json_t *summary)
{
    return json_is_string(json_object_get(summary, "failure"));
}

const char *pk_verdict_status(const json_t *summary)
{
    return pk_verdict_failed(summary) ? "failed" : "successful";
}

int pk_verdict_write_h5(pk_h5 *h, const json_t *summary)
{
    int rc = pk_h5_obs_string(h, "verdict/status", pk_verdict_status(summary));
    pk_h5_obs_int(h, "verdict/complete", json_is_true(json_object_get(summary, "complete")));
    if (pk_verdict_failed(summary))
        pk_h5_obs_string(h, "verdict/failure",
                         json_string_value(json_object_get(summary, "failure")));
    json_t *w = json_object_get(summary, "warnings");
    size_t n = json_array_size(w), len = 1, i;
    json_t *e;
    json_array_foreach (w, i, e)
        len += strlen(json_string_value(e)) + 1;
    char *text = malloc(len);
    if (!text)
        return -1;
    text[0] = 0;
    json_array_foreach (w, i, e) {
        strcat(text, json_string_value(e));
        if (i + 1 < n)
            strcat(text, "\n");
    }
    pk_h5_obs_string(h, "verdict/warnings", text);
    pk_h5_obs_int(h, "verdict/warning_count", (int64_t)n);
    free(text);
    return rc ? -1 : 0;
}

int pk_verdict_close_h5(pk_h5 *h, int failed, const json_t *summary, const char *out_path,
                        char *err, size_t errlen)
{
    if (failed || pk_verdict_write_h5(h, summary) != 0 || pk_h5_failed(h)) {
        pk_h5_abort(h); /* a half-written file never takes the result's name */
        snprintf(err, errlen, "writing %s failed", out_path);
        return -1;
    }
    return pk_h5_commit(h, err, errlen);
}
