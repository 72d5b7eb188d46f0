#include "scene/bsdf.h"

#include "core/sampling.h"

void cdl_bsdf_init(cdl_bsdf *b, const cdl_material *m, cdl_vec3 kd,
                   cdl_vec3 ns, cdl_vec3 ng)
{
    b->type = m->type;
    b->kd = kd;
    b->ks = m->ks;
    b->ns = m->ns;
    b->eta = m->eta;
    b->ng = ng;
    /* Shading normal on the geometric normal's side: interpolated normals
     * of a mesh with flipped winding must not turn the frame inside out. */
    if (cdl_dot(ns, ng) < 0.0f)
        ns = cdl_neg(ns);
    b->frame = cdl_frame_from(ns);
    b->p_spec = 0.0f;
    if (b->type == CDL_MAT_PHONG) {
        /* the lobe's weight reaches ks (n+2)/(n+1): choosing it in that
         * proportion keeps every sample's weight within Kd + Ks (n+2)/(n+1) */
        float d = cdl_luminance(kd), s = cdl_luminance(b->ks) * (b->ns + 2.0f) / (b->ns + 1.0f);
        b->p_spec = d + s > 0.0f ? s / (d + s) : 0.0f;
    }
}

float cdl_fresnel_dielectric(float cos_i, float eta)
{
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
    }
    float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f)
        return 1.0f; /* total internal reflection */
    float cos_t = sqrtf(1.0f - sin2_t);
    float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5f * (rs * rs + rp * rp);
}

/* Opaque materials are two-sided: both directions are mirrored to the
 * side wo is on. Returns 0 if wo and wi lie on different geometric sides
 * (light leaking through a surface is never reflected). */
static int opaque_local(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi,
                        cdl_vec3 *lo, cdl_vec3 *li)
{
    float go = cdl_dot(wo, b->ng), gi = cdl_dot(wi, b->ng);
    if (go * gi <= 0.0f)
        return 0;
    *lo = cdl_to_local(&b->frame, wo);
    *li = cdl_to_local(&b->frame, wi);
    if (go < 0.0f) {
        lo->z = -lo->z;
        li->z = -li->z;
    }
    return lo->z > 0.0f && li->z > 0.0f;
}

/* Normalized Phong: (n+2)/(2 pi) cos^n(alpha) reflects at most all energy
 * at normal incidence (Lafortune & Willems 1994). */
static float phong_lobe(float ns, cdl_vec3 lo, cdl_vec3 li, float *pdf)
{
    cdl_vec3 r = cdl_v3(-lo.x, -lo.y, lo.z);
    float c = cdl_dot(r, li);
    if (c <= 0.0f) {
        *pdf = 0.0f;
        return 0.0f;
    }
    float cn = powf(c, ns);
    *pdf = (ns + 1.0f) * (0.5f * CDL_INV_PI) * cn;
    return (ns + 2.0f) * (0.5f * CDL_INV_PI) * cn;
}

cdl_vec3 cdl_bsdf_eval(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    cdl_vec3 lo, li;
    if (cdl_bsdf_is_delta(b) || !opaque_local(b, wo, wi, &lo, &li))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_vec3 f = cdl_scale(b->kd, CDL_INV_PI);
    if (b->type == CDL_MAT_PHONG) {
        float pdf;
        f = cdl_madd(f, b->ks, phong_lobe(b->ns, lo, li, &pdf));
    }
    return f;
}

float cdl_bsdf_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    cdl_vec3 lo, li;
    if (cdl_bsdf_is_delta(b) || !opaque_local(b, wo, wi, &lo, &li))
        return 0.0f;
    float pd = li.z * CDL_INV_PI;
    if (b->type != CDL_MAT_PHONG)
        return pd;
    float ps;
    phong_lobe(b->ns, lo, li, &ps);
    return (1.0f - b->p_spec) * pd + b->p_spec * ps;
}

static int sample_opaque(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1,
                         float u2, cdl_scatter *s)
{
    float go = cdl_dot(wo, b->ng);
    if (go == 0.0f)
        return 0;
    cdl_vec3 lo = cdl_to_local(&b->frame, wo);
    float side = go < 0.0f ? -1.0f : 1.0f;
    lo.z *= side;
    if (lo.z <= 0.0f)
        return 0;
    cdl_vec3 li;
    if (u0 < b->p_spec) {
        /* cos^n lobe around the mirror direction */
        float cos_a = powf(u1, 1.0f / (b->ns + 1.0f));
        float sin_a = sqrtf(cdl_maxf(0.0f, 1.0f - cos_a * cos_a));
        float phi = 2.0f * CDL_PI * u2;
        cdl_frame rf = cdl_frame_from(cdl_v3(-lo.x, -lo.y, lo.z));
        li = cdl_to_world(&rf, cdl_v3(sin_a * cosf(phi), sin_a * sinf(phi), cos_a));
        if (li.z <= 0.0f)
            return 0;
    } else {
        li = cdl_sample_cosine_hemisphere(u1, u2);
        if (li.z <= 0.0f)
            return 0;
    }
    cdl_vec3 wi = cdl_to_world(&b->frame, cdl_v3(li.x, li.y, li.z * side));
    /* The shading frame may send wi below the geometric surface. */
    if (cdl_dot(wi, b->ng) * go <= 0.0f)
        return 0;
    s->wi = wi;
    s->delta = 0;
    cdl_vec3 f = cdl_scale(b->kd, CDL_INV_PI);
    float pdf = li.z * CDL_INV_PI;
    if (b->type == CDL_MAT_PHONG) {
        float ps;
        f = cdl_madd(f, b->ks, phong_lobe(b->ns, lo, li, &ps));
        pdf = (1.0f - b->p_spec) * pdf + b->p_spec * ps;
    }
    if (!(pdf > 0.0f))
        return 0;
    s->pdf = pdf;
    s->weight = cdl_scale(f, li.z / pdf);
    return 1;
}

int cdl_bsdf_sample(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2,
                    int adjoint, cdl_scatter *s)
{
    (void)u2;
    if (b->type == CDL_MAT_MIRROR) {
        cdl_vec3 n = b->frame.n;
        if (cdl_dot(wo, b->ng) < 0.0f)
            n = cdl_neg(n);
        s->wi = cdl_reflect(wo, n);
        s->weight = b->ks;
        s->pdf = 1.0f;
        s->delta = 1;
        return cdl_dot(s->wi, b->ng) * cdl_dot(wo, b->ng) > 0.0f;
    }
    if (b->type == CDL_MAT_DIELECTRIC) {
        /* Entering through the front (CCW) face means going into index eta. */
        cdl_vec3 n = b->frame.n;
        float cos_o = cdl_dot(wo, n);
        int entering = cdl_dot(wo, b->ng) > 0.0f;
        float eta = entering ? b->eta : 1.0f / b->eta;
        if (!entering) {
            n = cdl_neg(n);
            cos_o = -cos_o;
        }
        float fr = cos_o > 0.0f ? cdl_fresnel_dielectric(cos_o, eta) : 1.0f;
        s->delta = 1;
        if (u0 < fr) {
            s->wi = cdl_reflect(wo, n);
            s->pdf = fr;
            s->weight = cdl_v3(1.0f, 1.0f, 1.0f);
            return 1;
        }
        float sin2_t = (1.0f - cos_o * cos_o) / (eta * eta);
        float cos_t = sqrtf(cdl_maxf(0.0f, 1.0f - sin2_t));
        s->wi = cdl_sub(cdl_scale(cdl_neg(wo), 1.0f / eta),
                        cdl_scale(n, cos_t - cos_o / eta));
        s->wi = cdl_normalize(s->wi);
        s->pdf = 1.0f - fr;
        /* Radiance is compressed into the denser medium (Veach 1997, 5.2). */
        float scale = adjoint ? 1.0f : 1.0f / (eta * eta);
        s->weight = cdl_v3(scale, scale, scale);
        return 1;
    }
    return sample_opaque(b, wo, u0, u1, u2, s);
}
