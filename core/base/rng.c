/* rng.c — xoshiro256** seeded through splitmix64, one stream per purpose.
 * Contract: core/base/rng.h. */
#include "rng.h"

#include <math.h>

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void pk_rng_seed(pk_rng *g, uint64_t seed, uint64_t stream)
{
    uint64_t x = seed ^ (0xD1B54A32D192ED03ull * (stream + 1));
    for (int i = 0; i < 4; i++)
        g->s[i] = splitmix64(&x);
}

double pk_rng_range(pk_rng *g, double a, double b) { return a + (b - a) * pk_rng_uniform(g); }

double pk_rng_normal(pk_rng *g)
{
    double u1 = 1.0 - pk_rng_uniform(g); /* (0,1] so log is finite */
    double u2 = pk_rng_uniform(g);
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}
