/* rng.h — reproducible random numbers: xoshiro256** seeded through splitmix64.
 * The same seed gives the same stream on every platform (no libc rand()).
 * Independent streams for independent purposes (sizes, positions) come from
 * pk_rng_seed(seed, stream) so that changing one phase does not shift another. */
#ifndef PK_RNG_H
#define PK_RNG_H

#include <stdint.h>

typedef struct { uint64_t s[4]; } pk_rng;

void pk_rng_seed(pk_rng *g, uint64_t seed, uint64_t stream);
uint64_t pk_rng_next(pk_rng *g);
/* Uniform in [0,1) with 53 random bits. */
double pk_rng_uniform(pk_rng *g);
/* Uniform in [a,b). */
double pk_rng_range(pk_rng *g, double a, double b);
/* Standard normal (Box–Muller, no cached second value: stream stays simple). */
double pk_rng_normal(pk_rng *g);

#endif
