/* web_assets.h — files compiled into the binary for the dashboard
 * (tools/embed.sh): the files of web/ by base name ("app.js") and the example jobs
 * by their path under examples/ ("examples/meier-quartz-2d.json"). */
#ifndef PK_WEB_ASSETS_H
#define PK_WEB_ASSETS_H

#include <stddef.h>

typedef struct pk_web_asset {
    const char *name;
    const unsigned char *data; /* NUL-terminated after len bytes */
    size_t len;
} pk_web_asset;

extern const pk_web_asset pk_web_assets[]; /* terminated by {NULL} */

#endif
