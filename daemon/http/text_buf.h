/* text_buf.h — a growing text buffer that printf appends to: the /metrics
 * exposition is written through it. */
#ifndef PK_TEXT_BUF_H
#define PK_TEXT_BUF_H

#include <stddef.h>

typedef struct pk_text_buf {
    char *p; /* NUL-terminated once anything was put; free() it */
    size_t n, cap;
} pk_text_buf;

/* Append the formatted text (dropped when memory runs out). */
void pk_text_put(pk_text_buf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
