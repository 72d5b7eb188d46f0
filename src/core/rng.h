/* PCG32 (O'Neill 2014). A stream per (seed, pass, pixel or path) makes a
 * pass deterministic whatever the thread count or schedule. */
#ifndef CDL_RNG_H
#define CDL_RNG_H

#include <stdint.h>

typedef struct cdl_rng {
    uint64_t state, inc;
} cdl_rng;

static inline uint32_t cdl_rng_u32(cdl_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31u));
}

/* SplitMix64 finaliser: spreads nearby stream ids over the state space. */
static inline uint64_t cdl_mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline void cdl_rng_seed(cdl_rng *r, uint64_t seed, uint64_t stream)
{
    r->state = 0u;
    r->inc = (cdl_mix64(stream ^ (seed << 1)) << 1u) | 1u;
    cdl_rng_u32(r);
    r->state += cdl_mix64(seed + 0x632be59bd9b4e019ULL * stream);
    cdl_rng_u32(r);
}

/* Uniform float in [0, 1): 24 random mantissa bits, never 1. */
static inline float cdl_rng_float(cdl_rng *r)
{
    return (float)(cdl_rng_u32(r) >> 8) * 0x1p-24f;
}

#endif
