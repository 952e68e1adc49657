/* picture.c — the picture kinds of a result file (contract in picture.h). */
#include "picture.h"

#include <cairo.h>
#include <fontconfig/fontconfig.h>
#include <hdf5.h>
#include <stdio.h>
#include <string.h>

#include "api/results/h5_result.h"
#include "picture_internal.h"

static const struct {
    const char *name, *file, *title, *help;
    pk_picture_kind kind;
    int (*draw)(const char *h5_path, const char *out_path, char *err, size_t errlen);
} kinds[] = {
    /* first: an fe2 result's default picture is its macro problem, not its RVE */
    {"field", "field", "the FE² stress field",
     "the macro mesh deformed, coloured by the von Mises stress (fe2 results)", PK_PICTURE_FIELD,
     pk_picture_field},
    {"packing", "picture", "the packing",
     "the grains by size class (3D: mid-plane section and depth-shaded view along -z)",
     PK_PICTURE_PACKING, pk_picture_packing},
    {"grading", "grading", "the grading curve",
     "the grading curve, target against achieved (pack results)", PK_PICTURE_GRADING,
     pk_picture_grading},
    {"history", "history", "the placer's history",
     "phi and reduced pressure over the events (pack results of a placer with a history: EDMD)",
     PK_PICTURE_HISTORY, pk_picture_history},
    {"stress", "stress", "the stress-strain curve",
     "stress-strain curve, P components over F (homogenize results)", PK_PICTURE_STRESS,
     pk_picture_stress},
    {"residual", "residual", "the residual history",
     "relaxation residual of every load step (homogenize results)", PK_PICTURE_RESIDUAL,
     pk_picture_residual},
    {"response", "response", "the fe2 response",
     "reactions of the supports and dilatancy per load step (fe2 results)", PK_PICTURE_RESPONSE,
     pk_picture_response},
};
#define KINDS (sizeof kinds / sizeof *kinds)

int pk_picture_kind_parse(const char *name, pk_picture_kind *kind)
{
    for (size_t i = 0; i < KINDS; i++)
        if (name && !strcmp(name, kinds[i].name)) {
            *kind = kinds[i].kind;
            return 0;
        }
    return -1;
}

const char *pk_picture_kind_name(int i, const char **file, const char **title, const char **help)
{
    if (i < 0 || (size_t)i >= KINDS)
        return NULL;
    if (file)
        *file = kinds[i].file;
    if (title)
        *title = kinds[i].title;
    if (help)
        *help = kinds[i].help;
    return kinds[i].name;
}

pk_picture_kind pk_picture_default(const char *h5_path)
{
    hid_t f = H5Fopen(h5_path, H5F_ACC_RDONLY, H5P_DEFAULT);
    int fe2 = f >= 0 && H5Lexists(f, "/observables/fe2", H5P_DEFAULT) > 0 &&
        H5Lexists(f, "/observables/fe2/mesh", H5P_DEFAULT) > 0;
    if (f >= 0)
        H5Fclose(f);
    return fe2 ? PK_PICTURE_FIELD : PK_PICTURE_PACKING;
}

int pk_picture_write(const char *h5_path, pk_picture_kind kind, const char *out_path, char *err,
                     size_t errlen)
{
    for (size_t i = 0; i < KINDS; i++)
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
    static const char *const ext[] = {"png", "svg"};
    int drawn = 0, failed = 0;
    char path[4096], e[512];
    for (size_t i = 0; i < KINDS; i++)
        for (int svg = 0; svg < 2; svg++) {
            int packing = kinds[i].kind == PK_PICTURE_PACKING;
            if (packing && svg && n > PK_PICTURE_SVG_MAX_GRAINS)
                continue;
            snprintf(path, sizeof path, "%s/%s.%s", dir, kinds[i].file, ext[svg]);
            if (kinds[i].draw(h5_path, path, e, sizeof e) == 0)
                drawn++;
            else if (packing && !failed++)
                snprintf(err, errlen, "%s", e);
        }
    return drawn;
}

void pk_picture_release(void)
{
    cairo_debug_reset_static_data();
    FcFini();
}
