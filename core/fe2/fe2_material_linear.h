/* fe2_material_linear.h — a linear elastic pk_fe2_material: the macro
 * solver's own tests (patch tests, Newton, the tangent) without RVEs.
 * Contract of a material: fe2_material.h. */
#ifndef PK_FE2_MATERIAL_LINEAR_H
#define PK_FE2_MATERIAL_LINEAR_H

#include "fe2_material.h"

/* The linear elastic surrogate (patch tests, the macro solver's own tests):
 * P̄ = λ tr(ε) 1 + 2μ ε with ε = sym(F̄ − 1), Ā constant, no history. */
typedef struct pk_fe2_linear_elastic {
    double lambda, mu;
} pk_fe2_linear_elastic;

/* A material over le (borrowed; it must outlive the material). */
pk_fe2_material pk_fe2_linear_elastic_material(const pk_fe2_linear_elastic *le);

#endif
