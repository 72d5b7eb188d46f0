#include "scene/microfacet_mts.h"

#include <math.h>

float cdl_mf_D(const cdl_mf *d, cdl_vec3 m)
{
    float c2 = m.z * m.z, r;
    float sx = m.x / d->ax, sy = m.y / d->ay;
    if (d->type == CDL_MF_BECKMANN) {
        if (!(c2 > 0.0f))
            return 0.0f;
        r = expf(-(sx * sx + sy * sy) / c2) / (CDL_PI * d->ax * d->ay * c2 * c2);
    } else {
        float e = sx * sx + sy * sy + c2;
        r = 1.0f / (CDL_PI * d->ax * d->ay * e * e);
    }
    return r * m.z > 1e-20f ? r : 0.0f;
}

float cdl_mf_G1(const cdl_mf *d, cdl_vec3 v, cdl_vec3 m)
{
    if (cdl_dot(v, m) * v.z <= 0.0f)
        return 0.0f;
    float xy = (d->ax * v.x) * (d->ax * v.x) + (d->ay * v.y) * (d->ay * v.y);
    if (xy == 0.0f)
        return 1.0f;
    float t2 = xy / (v.z * v.z);
    if (d->type == CDL_MF_BECKMANN) {
        /* Mitsuba's rational fit (< 0.35 % off) */
        float a = 1.0f / sqrtf(t2), a2 = a * a;
        return a >= 1.6f ? 1.0f : (3.535f * a + 2.181f * a2) / (1.0f + 2.276f * a + 2.577f * a2);
    }
    return 2.0f / (1.0f + sqrtf(1.0f + t2));
}

float cdl_mf_pdf_vndf(const cdl_mf *d, cdl_vec3 wi, cdl_vec3 m)
{
    if (!(wi.z > 0.0f))
        return 0.0f;
    return cdl_mf_D(d, m) * cdl_mf_G1(d, wi, m) * fabsf(cdl_dot(wi, m)) / wi.z;
}

float cdl_erfinvf(float x)
{
    float w = -logf((1.0f - x) * (1.0f + x)), p;
    if (w < 5.0f) {
        w -= 2.5f;
        p = 2.81022636e-08f;
        p = 3.43273939e-07f + p * w;
        p = -3.5233877e-06f + p * w;
        p = -4.39150654e-06f + p * w;
        p = 0.00021858087f + p * w;
        p = -0.00125372503f + p * w;
        p = -0.00417768164f + p * w;
        p = 0.246640727f + p * w;
        p = 1.50140941f + p * w;
    } else {
        w = sqrtf(w) - 3.0f;
        p = -0.000200214257f;
        p = 0.000100950558f + p * w;
        p = 0.00134934322f + p * w;
        p = -0.00367342844f + p * w;
        p = 0.00573950773f + p * w;
        p = -0.0076224613f + p * w;
        p = 0.00943887047f + p * w;
        p = 1.00167406f + p * w;
        p = 2.83297682f + p * w;
    }
    return p * x;
}

/* Shirley-Chiu's concentric map of the square onto the unit disk. */
static void concentric_disk(float u1, float u2, float *x, float *y)
{
    float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    if (a == 0.0f && b == 0.0f) {
        *x = *y = 0.0f;
        return;
    }
    int q13 = fabsf(a) < fabsf(b);
    float r = q13 ? b : a, rp = q13 ? a : b;
    float phi = 0.25f * CDL_PI * rp / r;
    if (q13)
        phi = 0.5f * CDL_PI - phi;
    *x = r * cosf(phi);
    *y = r * sinf(phi);
}

/* A slope of the visible normals of the alpha = 1 distribution seen at
 * cos_i (in the plane of incidence along +x). */
static void sample_visible_11(cdl_mf_type type, float cos_i, float u1, float u2, float *sx, float *sy)
{
    if (type == CDL_MF_BECKMANN) {
        /* Jakob 2014: Newton iterations in the erf() domain, continuous
         * in the samples */
        float tan_i = sqrtf(cdl_maxf(0.0f, 1.0f - cos_i * cos_i)) / cos_i, cot_i = 1.0f / tan_i;
        float maxval = erff(cot_i);
        u1 = cdl_maxf(cdl_minf(u1, 1.0f - 1e-6f), 1e-6f);
        u2 = cdl_maxf(cdl_minf(u2, 1.0f - 1e-6f), 1e-6f);
        float x = maxval - (maxval + 1.0f) * erff(sqrtf(-logf(u1)));
        u1 *= 1.0f + maxval + 0.56418958354775628695f * tan_i * expf(-cot_i * cot_i);
        for (int i = 0; i < 3; i++) {
            float slope = cdl_erfinvf(x);
            float value = 1.0f + x + 0.56418958354775628695f * tan_i * expf(-slope * slope) - u1;
            float deriv = 1.0f - slope * tan_i;
            x -= value / deriv;
        }
        *sx = cdl_erfinvf(x);
        *sy = cdl_erfinvf(2.0f * u2 - 1.0f);
        return;
    }
    float px, py;
    concentric_disk(u1, u2, &px, &py);
    float s = 0.5f * (1.0f + cos_i);
    py = sqrtf(cdl_maxf(0.0f, 1.0f - px * px)) * (1.0f - s) + py * s;
    float z = sqrtf(cdl_maxf(0.0f, 1.0f - px * px - py * py));
    float sin_i = sqrtf(cdl_maxf(0.0f, 1.0f - cos_i * cos_i));
    float norm = 1.0f / (sin_i * py + cos_i * z);
    *sx = (cos_i * py - sin_i * z) * norm;
    *sy = px * norm;
}

cdl_vec3 cdl_mf_sample_vndf(const cdl_mf *d, cdl_vec3 wi, float u1, float u2)
{
    /* stretch wi to the alpha = 1 configuration */
    cdl_vec3 w = cdl_normalize(cdl_v3(d->ax * wi.x, d->ay * wi.y, wi.z));
    float s2 = 1.0f - w.z * w.z, sin_phi = 0.0f, cos_phi = 1.0f;
    if (s2 > 4.0f * 1.1920929e-7f) {
        float inv = 1.0f / sqrtf(s2);
        sin_phi = cdl_maxf(-1.0f, cdl_minf(1.0f, w.y * inv));
        cos_phi = cdl_maxf(-1.0f, cdl_minf(1.0f, w.x * inv));
    }
    float sx, sy;
    sample_visible_11(d->type, w.z, u1, u2, &sx, &sy);
    /* rotate back and unstretch */
    float tx = (cos_phi * sx - sin_phi * sy) * d->ax;
    float ty = (sin_phi * sx + cos_phi * sy) * d->ay;
    return cdl_normalize(cdl_v3(-tx, -ty, 1.0f));
}

void cdl_gauss_legendre(int n, double *nodes, double *weights)
{
    /* Newton on P_n from Chebyshev guesses; nodes ascending */
    for (int i = 0; i < n; i++) {
        double x = -cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = x;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1.0);
            double dx = p1 / dp;
            x -= dx;
            if (fabs(dx) < 1e-16)
                break;
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
}
