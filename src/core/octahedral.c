#include "core/octahedral.h"

#include <math.h>

uint32_t cdl_oct_encode_bits(cdl_vec3 d, int bits)
{
    float s = fabsf(d.x) + fabsf(d.y) + fabsf(d.z);
    float u = s > 0.0f ? d.x / s : 0.0f, v = s > 0.0f ? d.y / s : 0.0f;
    if (d.z < 0.0f) {
        float pu = (1.0f - fabsf(v)) * (u >= 0.0f ? 1.0f : -1.0f);
        float pv = (1.0f - fabsf(u)) * (v >= 0.0f ? 1.0f : -1.0f);
        u = pu;
        v = pv;
    }
    float m = (float)((1u << bits) - 1u);
    uint32_t a = (uint32_t)lrintf((u * 0.5f + 0.5f) * m);
    uint32_t b = (uint32_t)lrintf((v * 0.5f + 0.5f) * m);
    return a << bits | b;
}

cdl_vec3 cdl_oct_decode_bits(uint32_t e, int bits) { return cdl_normalize(cdl_oct_decode_raw(e, bits)); }
