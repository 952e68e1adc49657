/* html_page.h — HTML views of the service's JSON documents (OGC API – Common:
 * "f=html" and content negotiation).  A page is built from the document the
 * JSON answer would carry, every string escaped; it links the dashboard's
 * stylesheet and runs no script (Content-Security-Policy without scripts). */
#ifndef PK_HTTP_HTML_PAGE_H
#define PK_HTTP_HTML_PAGE_H

#include <jansson.h>
#include <stddef.h>

#include "http.h"

/* A page being written (a growing string); oom set when memory ran out. */
typedef struct pk_html {
    char *buf;
    size_t len, cap;
    int oom;
} pk_html;

void pk_html_raw(pk_html *h, const char *s);  /* markup, as is */
void pk_html_text(pk_html *h, const char *s); /* text or attribute value, escaped; NULL: nothing */
/* <a href="href">text</a>, both escaped */
void pk_html_link(pk_html *h, const char *href, const char *text);
/* A JSON value as text: a string as is, a number or literal printed, else nothing. */
void pk_html_value(pk_html *h, json_t *v);

/* 1 if the client asks for HTML ("f=html", or no f and an Accept that prefers
 * text/html), 0 for JSON ("f=json" or otherwise), -1 for another f. */
int pk_wants_html(pk_req *r);
/* The 400 of an f that is neither json nor html. */
enum MHD_Result pk_send_bad_format(pk_req *r);

/* Renders doc (the JSON answer, links absolute) into the page's <main>. */
typedef void (*pk_html_render)(pk_html *h, json_t *doc);

/* Answer doc (stolen) as the client asks: HTML when "f=html", or without f
 * when Accept prefers text/html; JSON when "f=json" or otherwise (with a
 * link rel=alternate to the HTML view beside rel=self).  Another f is a 400
 * naming the values.  title is the page's heading. */
enum MHD_Result pk_send_doc(pk_req *r, json_t *doc, const char *title, pk_html_render render);

/* The views of /processes and /jobs (html_lists.c). */
void pk_html_processes(pk_html *h, json_t *doc);
void pk_html_jobs(pk_html *h, json_t *doc);

#endif
