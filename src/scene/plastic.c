#include "scene/plastic.h"

#include "core/sampling.h"
#include "scene/microfacet_mts.h"

float cdl_fresnel_diffuse_reflectance(float eta)
{
    float inv = 1.0f / eta;
    if (eta < 1.0f) /* Egan & Hilgeman 1973 */
        return 0.0636f * inv + eta * (eta * -1.4399f + 0.7099f) + 0.6681f;
    /* d'Eon & Irving 2011 */
    return 0.919317f + inv * (-3.4793f + inv * (6.75335f + inv * (-7.80989f + inv * (4.98554f + inv * -1.36881f))));
}

/* Mitsuba's eval_transmittance (refract = 1) and eval_reflectance: the
 * share of light from wi that leaves the rough boundary of index eta
 * downwards (or back up), by Gauss-Legendre quadrature over the visible
 * normals' sample square (res^2 nodes, res = 32 if eta > 1 else 128). */
static float rough_boundary(const cdl_mf *d, cdl_vec3 wi, float eta, int refract)
{
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
    int res = 8; /* the same code on fewer nodes: a fuzz input with a rough coat ran 1.4 s */
#else
    int res = eta > 1.0f ? 32 : 128;
#endif
    double x[128], w[128];
    cdl_gauss_legendre(res, x, w);
    double acc = 0.0;
    for (int i = 0; i < res; i++)
        for (int j = 0; j < res; j++) {
            cdl_vec3 m = cdl_mf_sample_vndf(d, wi, (float)(0.5 * x[i] + 0.5), (float)(0.5 * x[j] + 0.5));
            float ci = cdl_dot(wi, m), f = cdl_fresnel_dielectric(ci, eta), v;
            if (refract) {
                /* Mitsuba's refract(wi, m, cos_t, eta_ti) */
                float eta_ti = ci >= 0.0f ? 1.0f / eta : eta;
                float ct2 = 1.0f - (1.0f - ci * ci) * eta_ti * eta_ti;
                float ct = sqrtf(cdl_maxf(0.0f, ct2));
                ct = ci >= 0.0f ? -ct : ct;
                cdl_vec3 wo = cdl_sub(cdl_scale(m, ci * eta_ti + ct), cdl_scale(wi, eta_ti));
                v = wo.z * wi.z >= 0.0f ? 0.0f : cdl_mf_G1(d, wo, m) * (1.0f - f);
            } else {
                cdl_vec3 wo = cdl_sub(cdl_scale(m, 2.0f * ci), wi);
                v = (wo.z <= 0.0f || wi.z <= 0.0f) ? 0.0f : cdl_mf_G1(d, wo, m) * f;
            }
            acc += v * w[i] * w[j] * 0.25;
        }
    return (float)acc;
}

void cdl_coat_prepare(cdl_material *m)
{
    if (m->type == CDL_MAT_COATED) {
        m->coat_ri = cdl_fresnel_diffuse_reflectance(1.0f / m->eta);
        return;
    }
    cdl_mf d = cdl_mf_make((cdl_mf_type)m->mf, m->alpha_x, m->alpha_x);
    double ri = 0.0;
    /* 64 x 17k visible normals: on every core, a large scene has many */
#pragma omp parallel for reduction(+ : ri) schedule(dynamic)
    for (int k = 0; k < CDL_COAT_RES; k++) {
        float mu = cdl_maxf(1e-6f, (float)k / (CDL_COAT_RES - 1));
        cdl_vec3 wi = cdl_v3(sqrtf(1.0f - mu * mu), 0.0f, mu);
        m->coat_t[k] = rough_boundary(&d, wi, m->eta, 1);
        ri += rough_boundary(&d, wi, 1.0f / m->eta, 0) * mu;
    }
    /* Mitsuba's 2 mean(R mu) over the same nodes */
    m->coat_ri = (float)(2.0 * ri / CDL_COAT_RES);
}

/* Mitsuba's lerp_gather over the table. */
static float coat_transmittance(const cdl_bsdf *b, float c)
{
    float x = c * (CDL_COAT_RES - 1);
    int i = (int)x;
    i = i < 0 ? 0 : i > CDL_COAT_RES - 2 ? CDL_COAT_RES - 2 : i;
    float w = x - (float)i;
    return b->coat_t[i] * (1.0f - w) + b->coat_t[i + 1] * w;
}

/* Probability of choosing the coat's lobe seen from cos_o, from the
 * coat's reflectance there and the specular sampling weight. */
static float p_coat(const cdl_bsdf *b, float cos_o)
{
    float r = b->type == CDL_MAT_COATED ? cdl_fresnel_dielectric(cos_o, b->eta)
                                        : 1.0f - coat_transmittance(b, cos_o);
    float ps = r * b->spec_weight, pd = (1.0f - r) * (1.0f - b->spec_weight);
    return ps + pd > 0.0f ? ps / (ps + pd) : 1.0f;
}

/* The base as seen through the coat, before the transmittances. */
static cdl_vec3 base(const cdl_bsdf *b)
{
    cdl_vec3 d = b->kd;
    float ri = b->coat_ri, s = CDL_INV_PI / (b->eta * b->eta);
    if (b->nonlinear)
        return cdl_v3(d.x * s / (1.0f - d.x * ri), d.y * s / (1.0f - d.y * ri), d.z * s / (1.0f - d.z * ri));
    return cdl_scale(d, s / (1.0f - ri));
}

cdl_vec3 cdl_coat_eval(const cdl_bsdf *b, cdl_vec3 lo, cdl_vec3 li, float *pdf)
{
    float ps = p_coat(b, lo.z), pd = 1.0f - ps;
    if (b->type == CDL_MAT_COATED) {
        float t = (1.0f - cdl_fresnel_dielectric(lo.z, b->eta)) * (1.0f - cdl_fresnel_dielectric(li.z, b->eta));
        *pdf = pd * li.z * CDL_INV_PI;
        return cdl_scale(base(b), t);
    }
    cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ax);
    cdl_vec3 h = cdl_normalize(cdl_add(lo, li));
    float D = cdl_mf_D(&d, h), g1o = cdl_mf_G1(&d, lo, h);
    float spec = cdl_fresnel_dielectric(cdl_dot(lo, h), b->eta) * D * g1o * cdl_mf_G1(&d, li, h) /
                 (4.0f * lo.z * li.z);
    *pdf = ps * D * g1o / (4.0f * lo.z) + pd * li.z * CDL_INV_PI;
    float t = coat_transmittance(b, lo.z) * coat_transmittance(b, li.z);
    return cdl_madd(cdl_scale(base(b), t), b->ks, spec);
}

int cdl_coat_sample(const cdl_bsdf *b, cdl_vec3 lo, float u0, float u1, float u2, cdl_vec3 *li,
                    int *delta, cdl_vec3 *weight, float *pdf)
{
    float ps = p_coat(b, lo.z);
    *delta = 0;
    if (u0 >= ps) {
        *li = cdl_sample_cosine_hemisphere(u1, u2);
        return 1;
    }
    if (b->type == CDL_MAT_COATED) {
        *li = cdl_v3(-lo.x, -lo.y, lo.z);
        *delta = 1;
        *pdf = ps;
        *weight = cdl_scale(b->ks, cdl_fresnel_dielectric(lo.z, b->eta) / ps);
        return 1;
    }
    cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ax);
    cdl_vec3 m = cdl_mf_sample_vndf(&d, lo, u1, u2);
    *li = cdl_sub(cdl_scale(m, 2.0f * cdl_dot(lo, m)), lo);
    return 1;
}
