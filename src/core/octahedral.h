/* Unit vectors in 2 x `bits` bits by the octahedral map (Meyer et al.
 * 2010): photon directions and normals, the eye-sample tree's culling
 * nodes. */
#ifndef CDL_OCTAHEDRAL_H
#define CDL_OCTAHEDRAL_H

#include <math.h>
#include <stdint.h>

#include "core/vec.h"

uint32_t cdl_oct_encode_bits(cdl_vec3 d, int bits);
cdl_vec3 cdl_oct_decode_bits(uint32_t e, int bits);
/* The decoded direction before normalization (its signs are exact);
 * inline: the splat tree's culling nodes decode in the traversal. */
static inline cdl_vec3 cdl_oct_decode_raw(uint32_t e, int bits)
{
    uint32_t mask = (1u << bits) - 1u;
    float m = (float)mask;
    float u = (float)((e >> bits) & mask) / m * 2.0f - 1.0f;
    float v = (float)(e & mask) / m * 2.0f - 1.0f;
    float z = 1.0f - fabsf(u) - fabsf(v);
    if (z < 0.0f) {
        float pu = (1.0f - fabsf(v)) * (u >= 0.0f ? 1.0f : -1.0f);
        float pv = (1.0f - fabsf(u)) * (v >= 0.0f ? 1.0f : -1.0f);
        u = pu;
        v = pv;
    }
    return cdl_v3(u, v, z);
}

#endif
