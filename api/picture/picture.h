/* picture.h — pictures and plots of result files drawn by packd itself with
 * cairo (`packd picture`, GET /jobs/{id}/results/<kind file>.svg|png):
 *   packing   2D: the grains as the papers draw them — filled by size class,
 *             grains cut by a periodic side drawn on both sides with a dashed
 *             outline, walls solid and periodic sides dashed;
 *             3D: the mid-plane section (z = L_z/2) beside an orthographic
 *             view along −z, depth-shaded (nearer grains brighter); a tetfill
 *             result's tet mesh outlined where the section cuts it;
 *   grading   the resolved grading curve, target against achieved, % passing
 *             over a logarithmic sieve axis, with φ_M and φ_eff;
 *   history   an EDMD run over its events: φ and the reduced pressure
 *             (logarithmic axis);
 *   stress    the stress–strain curve of a homogenization: the components of
 *             P̄ over the F̄ component the load varies most;
 *   residual  the relaxation residual ‖f‖ of every homogenization step
 *             (logarithmic), at its start, relaxed, and the target;
 *   response  an fe2 run over its load steps: the reactions of the supports
 *             and the dilatancy of the specimen.
 * A kind is drawn only from a file that holds its data; asked of another
 * file it fails with an error naming what is missing.  The format follows
 * the output file's extension (.svg or .png). */
#ifndef PK_PICTURE_H
#define PK_PICTURE_H

#include <stddef.h>

typedef enum {
    PK_PICTURE_PACKING,
    PK_PICTURE_GRADING,
    PK_PICTURE_HISTORY,
    PK_PICTURE_STRESS,
    PK_PICTURE_RESIDUAL,
    PK_PICTURE_RESPONSE,
    PK_PICTURE_FIELD
} pk_picture_kind;

/* A kind's name ("packing", "grading", ...) → kind; -1 for any other name. */
int pk_picture_kind_parse(const char *name, pk_picture_kind *kind);

/* The i-th kind (i from 0): its name, its file name in a job's folder
 * without extension ("picture" for packing, else the name), a title and a
 * one-line description (each pointer may be NULL); NULL past the last.  The
 * one list of the kinds: `packd picture` and the service's outputs
 * (api/http/http_outputs.h) read it. */
const char *pk_picture_kind_name(int i, const char **file, const char **title, const char **help);

/* The kind `packd picture` draws when none is named: an fe2 result's field
 * (the macro problem), any other result's packing.  H5 errors silenced by
 * the caller's quiet mode or printed; a file that does not open: packing. */
pk_picture_kind pk_picture_default(const char *h5_path);

/* Draw the picture of h5_path into out_path (written under a temporary name,
 * then renamed).  0 on success, -1 with err. */
int pk_picture_write(const char *h5_path, pk_picture_kind kind, const char *out_path, char *err,
                     size_t errlen);

/* The pictures the service offers for a finished job, drawn into dir: every
 * kind whose data the result holds as <file>.png and <file>.svg (the packing's
 * SVG up to PK_PICTURE_SVG_MAX_GRAINS grains: an SVG holds one element per
 * grain image).  Returns how many were drawn; err names the first failure
 * of the packing (a result without a plot's data is not one). */
#define PK_PICTURE_SVG_MAX_GRAINS 20000
int pk_picture_write_set(const char *h5_path, const char *dir, char *err, size_t errlen);

/* Release cairo's and fontconfig's process-wide caches (call once, when no
 * more pictures follow): a process that drew text ends without leaks. */
void pk_picture_release(void);

#endif
