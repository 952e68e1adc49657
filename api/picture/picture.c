/* picture.c — the picture kinds of a result file (contract in picture.h). */
#include "picture.h"

#include <cairo.h>
#include <fontconfig/fontconfig.h>
#include <stdio.h>
#include <string.h>

#include "api/results/h5_result.h"
#include "picture_internal.h"

static const struct {
    const char *name;
    pk_picture_kind kind;
    int (*draw)(const char *h5_path, const char *out_path, char *err, size_t errlen);
} kinds[] = {
    {"packing", PK_PICTURE_PACKING, pk_picture_packing},
    {"grading", PK_PICTURE_GRADING, pk_picture_grading},
};

int pk_picture_kind_parse(const char *name, pk_picture_kind *kind)
{
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
        if (name && !strcmp(name, kinds[i].name)) {
            *kind = kinds[i].kind;
            return 0;
        }
    return -1;
}

int pk_picture_write(const char *h5_path, pk_picture_kind kind, const char *out_path, char *err,
                     size_t errlen)
{
    for (size_t i = 0; i < sizeof kinds / sizeof *kinds; i++)
        if (kinds[i].kind == kind)
            return kinds[i].draw(h5_path, out_path, err, errlen);
    snprintf(err, errlen, "no such picture kind");
    return -1;
}

int pk_picture_write_set(const char *h5_path, const char *dir, char *err, size_t errlen)
{
    pk_box b;
    pk_particles p;
    if (pk_h5_read_particles(h5_path, &b, &p, err, errlen) != 0)
        return 0;
    size_t n = p.n;
    pk_particles_free(&p);
    static const struct {
        const char *file;
        pk_picture_kind kind;
        int svg;
    } set[] = {{"picture.png", PK_PICTURE_PACKING, 0},
               {"picture.svg", PK_PICTURE_PACKING, 1},
               {"grading.png", PK_PICTURE_GRADING, 0},
               {"grading.svg", PK_PICTURE_GRADING, 1}};
    int drawn = 0, failed = 0;
    char path[4096], e[512];
    for (size_t i = 0; i < sizeof set / sizeof *set; i++) {
        if (set[i].kind == PK_PICTURE_PACKING && set[i].svg && n > PK_PICTURE_SVG_MAX_GRAINS)
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, set[i].file);
        if (pk_picture_write(h5_path, set[i].kind, path, e, sizeof e) == 0)
            drawn++;
        else if (set[i].kind == PK_PICTURE_PACKING && !failed++)
            snprintf(err, errlen, "%s", e);
    }
    return drawn;
}

void pk_picture_release(void)
{
    cairo_debug_reset_static_data();
    FcFini();
}
