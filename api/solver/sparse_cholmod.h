/* sparse_cholmod.h — core/base/sparse.h's solver implemented with SuiteSparse
 * CHOLMOD (simplicial LDLᵀ, so the pivots give the inertia). */
#ifndef PK_SPARSE_CHOLMOD_H
#define PK_SPARSE_CHOLMOD_H

#include "core/base/sparse.h"

extern const pk_sparse_solver pk_sparse_cholmod;

#endif
