/* Oren & Nayar's rough diffuse reflectance (1994): pbrt's matte with sigma
 * (the qualitative model) and Mitsuba 0.6's roughdiffuse (the full model
 * with interreflection unless useFastApprox). */
#ifndef CDL_OREN_NAYAR_H
#define CDL_OREN_NAYAR_H

#include <math.h>

#include "core/vec.h"

/* The BRDF (without the cosine) for reflectance rho, slope deviation sigma
 * (radians), directions lo, li in the local frame (z up, both above). */
static inline cdl_vec3 cdl_oren_nayar(cdl_vec3 rho, float sigma, int full, cdl_vec3 lo, cdl_vec3 li)
{
    float s2 = sigma * sigma;
    float sin_o = sqrtf(fmaxf(0.0f, 1.0f - lo.z * lo.z)), sin_i = sqrtf(fmaxf(0.0f, 1.0f - li.z * li.z));
    float cos_dphi = 0.0f;
    if (sin_o > 1e-4f && sin_i > 1e-4f)
        cos_dphi = (lo.x * li.x + lo.y * li.y) / (sin_o * sin_i);
    cos_dphi = fmaxf(-1.0f, fminf(1.0f, cos_dphi));
    /* alpha the larger polar angle, beta the smaller */
    float sin_a, sin_b, tan_b;
    if (li.z > lo.z) {
        sin_a = sin_o, sin_b = sin_i, tan_b = sin_i / li.z;
    } else {
        sin_a = sin_i, sin_b = sin_o, tan_b = sin_o / lo.z;
    }
    float a = 1.0f - 0.5f * s2 / (s2 + 0.33f);
    if (!full) {
        float b = 0.45f * s2 / (s2 + 0.09f);
        return cdl_scale(rho, CDL_INV_PI * (a + b * fmaxf(cos_dphi, 0.0f) * sin_a * tan_b));
    }
    float alpha = acosf(fminf(lo.z, li.z)), beta = acosf(fmaxf(lo.z, li.z));
    float t = s2 / (s2 + 0.09f), t2 = 4.0f * CDL_INV_PI * CDL_INV_PI * alpha * beta, t3 = 2.0f * beta * CDL_INV_PI;
    float c2 = 0.45f * t * (cos_dphi > 0.0f ? sin_a : sin_a - t3 * t3 * t3);
    float c3 = 0.125f * t * t2 * t2, c4 = 0.17f * s2 / (s2 + 0.13f);
    float cos_a = sqrtf(fmaxf(0.0f, 1.0f - sin_a * sin_a)), cos_b = sqrtf(fmaxf(0.0f, 1.0f - sin_b * sin_b));
    float tan_half = (sin_a + sin_b) / (cos_a + cos_b); /* tan((alpha + beta) / 2) */
    float single = a + cos_dphi * c2 * tan_b + (1.0f - fabsf(cos_dphi)) * c3 * tan_half;
    float twice = c4 * (1.0f - cos_dphi * t3 * t3);
    return cdl_scale(cdl_add(cdl_scale(rho, single), cdl_scale(cdl_mul(rho, rho), twice)), CDL_INV_PI);
}

#endif
