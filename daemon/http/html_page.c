/* html_page.c — the page frame, escaping and negotiation of HTML views.
 * Contract: daemon/http/html_page.h. */
#include "html_page.h"

#include <stdlib.h>
#include <string.h>

#include "route_dashboard.h"

/* No script at all; styles only from the service's own stylesheet. */
#define HTML_CSP                                                                                   \
    "default-src 'none'; style-src 'self'; img-src 'self'; base-uri 'none'; form-action 'none'; "  \
    "frame-ancestors 'none'"

static void put(pk_html *h, const char *s, size_t n)
{
    if (h->oom)
        return;
    if (h->len + n + 1 > h->cap) {
        size_t cap = (h->len + n + 1) * 2;
        char *b = realloc(h->buf, cap);
        if (!b) {
            h->oom = 1;
            return;
        }
        h->buf = b;
        h->cap = cap;
    }
    memcpy(h->buf + h->len, s, n);
    h->len += n;
    h->buf[h->len] = 0;
}

void pk_html_raw(pk_html *h, const char *s) { put(h, s, strlen(s)); }

void pk_html_text(pk_html *h, const char *s)
{
    for (const char *p = s; p && *p;) {
        size_t n = strcspn(p, "&<>\"'");
        put(h, p, n);
        p += n;
        if (!*p)
            break;
        const char *e = *p == '&' ? "&amp;"
            : *p == '<'           ? "&lt;"
            : *p == '>'           ? "&gt;"
            : *p == '"'           ? "&quot;"
                                  : "&#39;";
        pk_html_raw(h, e);
        p++;
    }
}

void pk_html_link(pk_html *h, const char *href, const char *text)
{
    pk_html_raw(h, "<a href=\"");
    pk_html_text(h, href);
    pk_html_raw(h, "\">");
    pk_html_text(h, text);
    pk_html_raw(h, "</a>");
}

void pk_html_value(pk_html *h, json_t *v)
{
    if (json_is_string(v)) {
        pk_html_text(h, json_string_value(v));
        return;
    }
    if (!json_is_number(v) && !json_is_boolean(v))
        return;
    char *s = json_dumps(v, JSON_ENCODE_ANY | JSON_REAL_PRECISION(6));
    pk_html_text(h, s);
    free(s);
}

/* The href of doc's link of relation rel, or NULL. */
static const char *link_href(json_t *doc, const char *rel)
{
    size_t i;
    json_t *l;
    json_array_foreach (json_object_get(doc, "links"), i, l) {
        const char *lr = json_string_value(json_object_get(l, "rel"));
        if (lr && !strcmp(lr, rel))
            return json_string_value(json_object_get(l, "href"));
    }
    return NULL;
}

/* href with the query parameter f=value added (a copy to free). */
static char *with_format(const char *href, const char *value)
{
    size_t n = strlen(href) + strlen(value) + 4;
    char *s = malloc(n);
    if (s)
        snprintf(s, n, "%s%cf=%s", href, strchr(href, '?') ? '&' : '?', value);
    return s;
}

static void page_start(pk_html *h, const char *title, json_t *doc)
{
    pk_html_raw(h,
                "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
                "<title>");
    pk_html_text(h, title);
    /* relative links: every page sits at the top level, under public_url's path too */
    pk_html_raw(h,
                " — packd</title><link rel=\"stylesheet\" href=\"dashboard/style.css\">"
                "<link rel=\"icon\" href=\"dashboard/favicon.svg\" type=\"image/svg+xml\">"
                "</head>\n<body><header><h1><a href=\"./\">packd</a></h1>"
                "<a href=\"processes?f=html\">processes</a> <a href=\"jobs?f=html\">jobs</a> "
                "<a href=\"api?f=html\">API</a></header>\n<main><h2>");
    pk_html_text(h, title);
    pk_html_raw(h, "</h2>\n");
    const char *self = link_href(doc, "self");
    char *json = self ? with_format(self, "json") : NULL;
    if (json) {
        pk_html_raw(h, "<p class=\"comment\">This page as JSON: ");
        pk_html_link(h, json, json);
        pk_html_raw(h, "</p>\n");
    }
    free(json);
}

int pk_wants_html(pk_req *r)
{
    const char *f = pk_query(r, "f");
    if (!f)
        return pk_prefers_html(r);
    return !strcmp(f, "html") ? 1 : !strcmp(f, "json") ? 0 : -1;
}

enum MHD_Result pk_send_bad_format(pk_req *r)
{
    return pk_send_problem(r, 400, PK_PROBLEM_INVALID_INPUT, "Invalid query parameter",
                           "query parameter f is json or html", NULL, 0);
}

enum MHD_Result pk_send_doc(pk_req *r, json_t *doc, const char *title, pk_html_render render)
{
    int html = pk_wants_html(r);
    if (html < 0) {
        json_decref(doc);
        return pk_send_bad_format(r);
    }
    pk_client_view(r, doc);
    if (!html) {
        const char *self = link_href(doc, "self");
        char *alt = self ? with_format(self, "html") : NULL;
        if (alt)
            json_array_append_new(json_object_get(doc, "links"),
                                  json_pack("{s:s,s:s,s:s,s:s}", "href", alt, "rel", "alternate",
                                            "type", "text/html", "title", "this document as HTML"));
        free(alt);
        struct MHD_Response *resp = pk_json_response(doc, "application/json");
        if (resp)
            MHD_add_response_header(resp, "Vary", "Accept");
        return pk_send(r, 200, resp);
    }
    pk_html h = {0};
    page_start(&h, title, doc);
    render(&h, doc);
    pk_html_raw(&h, "</main></body></html>\n");
    json_decref(doc);
    if (h.oom) {
        free(h.buf);
        return pk_reply_problem(r, PK_P_INTERNAL, "out of memory writing the page");
    }
    struct MHD_Response *resp =
        MHD_create_response_from_buffer(h.len, h.buf, MHD_RESPMEM_MUST_FREE);
    if (!resp) {
        free(h.buf);
        return MHD_NO;
    }
    MHD_add_response_header(resp, "Content-Type", "text/html; charset=utf-8");
    MHD_add_response_header(resp, "Content-Security-Policy", HTML_CSP);
    MHD_add_response_header(resp, "Vary", "Accept");
    MHD_add_response_header(resp, "Cache-Control", "no-cache");
    return pk_send(r, 200, resp);
}
