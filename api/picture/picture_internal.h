/* picture_internal.h — the drawers behind pk_picture_write (picture.h). */
#ifndef PK_PICTURE_INTERNAL_H
#define PK_PICTURE_INTERNAL_H

#include <stddef.h>

int pk_picture_packing(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_grading(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_history(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_stress(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_residual(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_response(const char *h5_path, const char *out_path, char *err, size_t errlen);
int pk_picture_field(const char *h5_path, const char *out_path, char *err, size_t errlen);

#endif
