/* Trowbridge-Reitz (GGX) microfacet distribution, anisotropic, in the
 * local shading frame (z = normal), with Smith's height-correlated masking
 * (as pbrt-v3) and visible-normal sampling (Heitz 2018). */
#ifndef CDL_MICROFACET_H
#define CDL_MICROFACET_H

#include "core/vec.h"

static inline float cdl_ggx_D(cdl_vec3 h, float ax, float ay)
{
    float c2 = h.z * h.z;
    if (c2 <= 0.0f)
        return 0.0f;
    float e = (h.x * h.x) / (ax * ax) + (h.y * h.y) / (ay * ay) + c2;
    return 1.0f / (CDL_PI * ax * ay * e * e);
}

/* Smith's Lambda for direction w. */
static inline float cdl_ggx_lambda(cdl_vec3 w, float ax, float ay)
{
    float c2 = w.z * w.z;
    float s2 = w.x * w.x + w.y * w.y;
    if (s2 <= 0.0f)
        return 0.0f;
    if (c2 <= 0.0f)
        return 1e30f;
    float a2 = (w.x * w.x * ax * ax + w.y * w.y * ay * ay) / s2;
    float t2 = s2 / c2;
    return 0.5f * (-1.0f + sqrtf(1.0f + a2 * t2));
}

static inline float cdl_ggx_G1(cdl_vec3 w, float ax, float ay)
{
    return 1.0f / (1.0f + cdl_ggx_lambda(w, ax, ay));
}

static inline float cdl_ggx_G(cdl_vec3 wo, cdl_vec3 wi, float ax, float ay)
{
    return 1.0f / (1.0f + cdl_ggx_lambda(wo, ax, ay) + cdl_ggx_lambda(wi, ax, ay));
}

/* Density of cdl_ggx_sample_vndf choosing h, seen from wo (wo.z > 0). */
static inline float cdl_ggx_pdf_vndf(cdl_vec3 wo, cdl_vec3 h, float ax, float ay)
{
    float d = cdl_dot(wo, h);
    if (d <= 0.0f || wo.z <= 0.0f)
        return 0.0f;
    return cdl_ggx_G1(wo, ax, ay) * d * cdl_ggx_D(h, ax, ay) / wo.z;
}

/* A microfacet normal visible from wo (wo.z > 0), Heitz 2018. */
static inline cdl_vec3 cdl_ggx_sample_vndf(cdl_vec3 wo, float ax, float ay, float u1, float u2)
{
    cdl_vec3 vh = cdl_normalize(cdl_v3(ax * wo.x, ay * wo.y, wo.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    cdl_vec3 t1 = len2 > 0.0f ? cdl_scale(cdl_v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(len2))
                              : cdl_v3(1.0f, 0.0f, 0.0f);
    cdl_vec3 t2 = cdl_cross(vh, t1);
    float r = sqrtf(u1), phi = 2.0f * CDL_PI * u2;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * sqrtf(cdl_maxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    float p3 = sqrtf(cdl_maxf(0.0f, 1.0f - p1 * p1 - p2 * p2));
    cdl_vec3 nh = cdl_add(cdl_add(cdl_scale(t1, p1), cdl_scale(t2, p2)), cdl_scale(vh, p3));
    return cdl_normalize(cdl_v3(ax * nh.x, ay * nh.y, cdl_maxf(1e-7f, nh.z)));
}

/* Fresnel reflectance of a conductor, per channel (pbrt-v3 FrConductor,
 * from a medium of index 1). */
static inline float cdl_fresnel_conductor1(float cos_i, float eta, float k)
{
    cos_i = cdl_minf(1.0f, cdl_maxf(-1.0f, cos_i));
    float c2 = cos_i * cos_i, s2 = 1.0f - c2;
    float eta2 = eta * eta, k2 = k * k;
    float t0 = eta2 - k2 - s2;
    float a2b2 = sqrtf(cdl_maxf(0.0f, t0 * t0 + 4.0f * eta2 * k2));
    float t1 = a2b2 + c2;
    float a = sqrtf(cdl_maxf(0.0f, 0.5f * (a2b2 + t0)));
    float t2 = 2.0f * cos_i * a;
    float rs = (t1 - t2) / (t1 + t2);
    float t3 = c2 * a2b2 + s2 * s2;
    float t4 = t2 * s2;
    float rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5f * (rp + rs);
}

static inline cdl_vec3 cdl_fresnel_conductor(float cos_i, cdl_vec3 eta, cdl_vec3 k)
{
    return cdl_v3(cdl_fresnel_conductor1(cos_i, eta.x, k.x), cdl_fresnel_conductor1(cos_i, eta.y, k.y),
                  cdl_fresnel_conductor1(cos_i, eta.z, k.z));
}

#endif
