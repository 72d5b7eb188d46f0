/* Morton (Z-order) codes: points close in space get close codes, so a
 * list sorted by them visits space coherently (cache-friendly queries). */
#ifndef CDL_MORTON_H
#define CDL_MORTON_H

#include <stdint.h>

/* 10 bits of x spread to every third bit. */
static inline uint64_t cdl_morton_spread3(uint32_t x)
{
    uint64_t v = x & 0x3ff;
    v = (v | v << 16) & 0x30000ff;
    v = (v | v << 8) & 0x300f00f;
    v = (v | v << 4) & 0x30c30c3;
    return (v | v << 2) & 0x9249249;
}

/* The 30-bit code of p in the box [lo, lo + 1023 / scale] (scale: 1023
 * over the box's largest extent); coordinates outside are clamped. */
static inline uint64_t cdl_morton3(const float *p, const float *lo, float scale)
{
    uint64_t m = 0;
    for (int k = 0; k < 3; k++) {
        float f = (p[k] - lo[k]) * scale;
        uint32_t q = f > 0.0f ? (f < 1023.0f ? (uint32_t)f : 1023u) : 0u;
        m |= cdl_morton_spread3(q) << k;
    }
    return m;
}

#endif
