/* plot_data.h — the series a plot reads from a result file: 1-D step
 * series, tensor components per step, their unit attributes and the
 * scalars a title quotes.  A series is found in either layout a result
 * may use: a flat dataset (`dr/residual`, `P/11`) or an H5MD
 * time-dependent element (a group with `value`: [steps] or [steps][d][d]). */
#ifndef PK_PLOT_DATA_H
#define PK_PLOT_DATA_H

#include <hdf5.h>
#include <stddef.h>

/* The file opened read-only with HDF5's error printing off; close with
 * pk_plot_file_close.  -1 when it does not open. */
hid_t pk_plot_file_open(const char *path);
void pk_plot_file_close(hid_t f);

/* The step series at path as doubles (malloc'd, *n entries), or NULL
 * when absent, empty or not one-dimensional. */
double *pk_plot_series(hid_t f, const char *path, size_t *n);

/* Component (a, b) (0-based) of the tensor series at path: `path/ab`
 * (1-based names) or element [k][a][b] of `path` / `path/value`.
 * NULL when absent. */
double *pk_plot_tensor(hid_t f, const char *path, int a, int b, size_t *n);

/* The "unit" attribute of path (or of path/value), fixed or variable
 * length; "" when absent. */
void pk_plot_unit(hid_t f, const char *path, char *out, size_t n);

/* A scalar string dataset, malloc'd (NULL when absent), or copied into out
 * ("" when absent). */
char *pk_plot_text(hid_t f, const char *path);
void pk_plot_string(hid_t f, const char *path, char *out, size_t n);

/* A scalar number; NAN when absent. */
double pk_plot_scalar(hid_t f, const char *path);

#endif
