/* xdmf.h — an XDMF 3 description of a result file, so ParaView (Xdmf3
 * reader) shows its grains as points with radius, species and id attributes
 * (e.g. with the Point Gaussian representation scaled by radius), a tetfill
 * result's mesh as tetrahedra and a homogenize result's load path as a time
 * series (docs/result-format.md, "XDMF for ParaView").  The XML holds no
 * data: it points into the HDF5 file by name. */
#ifndef PK_XDMF_H
#define PK_XDMF_H

#include <stddef.h>

/* Write xdmf_path describing the result file h5_path; the XML
 * refers to the HDF5 file as `h5_ref` (e.g. a download's file name, when both
 * will be saved side by side), or, when h5_ref is NULL, by the relative path
 * from the XML's folder to h5_path.  The grains are a Polyvertex grid whose
 * connectivity is /particles/grains/id (inline for files without it); with
 * /particles/rve (homogenize) a temporal collection of one such grid per
 * load step takes their place; with /observables/tetfill/mesh_tets a
 * Tetrahedron grid follows.
 * 0 on success, -1 with err. */
int pk_xdmf_write(const char *h5_path, const char *h5_ref, const char *xdmf_path, char *err,
                  size_t errlen);

/* The path of h5_path relative to the folder of xdmf_path (both folders must
 * exist), e.g. "../runs/a.h5".  0 on success. */
int pk_xdmf_relative_ref(const char *h5_path, const char *xdmf_path, char *out, size_t n);

#endif
