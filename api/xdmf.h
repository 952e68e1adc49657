/* xdmf.h — an XDMF 3 description of a result file's grains, so ParaView
 * (Xdmf3 reader) shows them as points with radius and species attributes
 * (e.g. with the Point Gaussian representation scaled by radius).  The XML
 * holds no data: it points into the HDF5 file by name. */
#ifndef PK_XDMF_H
#define PK_XDMF_H

#include <stddef.h>

/* Write xdmf_path describing the grains of the result file h5_path; the XML
 * refers to the HDF5 file as `h5_ref` (the name it will have beside the XML,
 * e.g. its base name).  0 on success, -1 with err. */
int pk_xdmf_write(const char *h5_path, const char *h5_ref, const char *xdmf_path, char *err,
                  size_t errlen);

#endif
