/* Warping of uniform samples to the distributions the BSDFs and lights need. */
#ifndef CDL_SAMPLING_H
#define CDL_SAMPLING_H

#include "core/vec.h"

/* sin and cos of t in [-pi/4, pi/4] by their Taylor series to t^9 and
 * t^8 (truncation below 3e-8, under float rounding): the concentric
 * mapping needs no other angles, and libm's sincosf was 3 % of path. */
static inline void cdl_sincos_quarter(float t, float *s, float *c)
{
    float t2 = t * t;
    *s = t * (1.0f + t2 * (-1.0f / 6.0f + t2 * (1.0f / 120.0f + t2 * (-1.0f / 5040.0f + t2 * (1.0f / 362880.0f)))));
    *c = 1.0f + t2 * (-0.5f + t2 * (1.0f / 24.0f + t2 * (-1.0f / 720.0f + t2 * (1.0f / 40320.0f))));
}

static inline cdl_vec3 cdl_sample_cosine_hemisphere(float u1, float u2)
{
    /* Concentric disk mapping (Shirley-Chiu) keeps strata compact. */
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f, sn, cs;
    if (a == 0.0f && b == 0.0f)
        return cdl_v3(0.0f, 0.0f, 1.0f);
    /* |a| > |b|: phi = pi/4 b/a; else phi = pi/2 - pi/4 a/b (cos and sin
     * swap). Selects, not branches: the side is a coin flip per sample */
    int wide = fabsf(a) > fabsf(b);
    float r = wide ? a : b, q = wide ? b : a;
    cdl_sincos_quarter((CDL_PI / 4.0f) * (q / r), &sn, &cs);
    float x = r * (wide ? cs : sn), y = r * (wide ? sn : cs);
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
