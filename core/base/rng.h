/* rng.h — reproducible random numbers: xoshiro256** seeded through splitmix64.
 * The same seed gives the same stream on every platform (no libc rand()).
 * Independent streams for independent purposes (sizes, positions) come from
 * pk_rng_seed(seed, stream) so that changing one phase does not shift another. */
#ifndef PK_RNG_H
#define PK_RNG_H

#include <stdint.h>

typedef struct {
    uint64_t s[4];
} pk_rng;

void pk_rng_seed(pk_rng *g, uint64_t seed, uint64_t stream);
/* Next 64 random bits.  Inline: hot loops (RSA's batched draws) call it
 * directly, and there is one generator in packd, not a copy per caller. */
static inline uint64_t pk_rng_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static inline uint64_t pk_rng_next(pk_rng *g)
{
    uint64_t *s = g->s;
    uint64_t result = pk_rng_rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = pk_rng_rotl(s[3], 45);
    return result;
}

/* Uniform in [0,1) with 53 random bits. */
static inline double pk_rng_uniform(pk_rng *g)
{
    return (double)(pk_rng_next(g) >> 11) * 0x1.0p-53;
}
/* Uniform in [a,b). */
double pk_rng_range(pk_rng *g, double a, double b);
/* Standard normal (Box–Muller, no cached second value: stream stays simple). */
double pk_rng_normal(pk_rng *g);

#endif
