/* Warping of uniform samples to the distributions the BSDFs and lights need. */
#ifndef CDL_SAMPLING_H
#define CDL_SAMPLING_H

#include "core/vec.h"

static inline cdl_vec3 cdl_sample_cosine_hemisphere(float u1, float u2)
{
    /* Concentric disk mapping (Shirley-Chiu) keeps strata compact. */
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f, r, phi;
    if (a == 0.0f && b == 0.0f)
        return cdl_v3(0.0f, 0.0f, 1.0f);
    if (fabsf(a) > fabsf(b)) {
        r = a;
        phi = (CDL_PI / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (CDL_PI / 2.0f) - (CDL_PI / 4.0f) * (a / b);
    }
    float x = r * cosf(phi), y = r * sinf(phi);
    return cdl_v3(x, y, sqrtf(cdl_maxf(0.0f, 1.0f - x * x - y * y)));
}

static inline cdl_vec3 cdl_sample_uniform_sphere(float u1, float u2)
{
    float z = 1.0f - 2.0f * u1;
    float r = sqrtf(cdl_maxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * CDL_PI * u2;
    return cdl_v3(r * cosf(phi), r * sinf(phi), z);
}

/* Barycentrics uniform over a triangle (Heitz 2019, area preserving). */
static inline void cdl_sample_triangle(float u1, float u2, float *b1, float *b2)
{
    if (u1 < u2) {
        *b1 = u1 * 0.5f;
        *b2 = u2 - *b1;
    } else {
        *b2 = u2 * 0.5f;
        *b1 = u1 - *b2;
    }
}

static inline float cdl_power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 / (a2 + b2);
}

#endif
