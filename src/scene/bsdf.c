#include "scene/bsdf.h"

#include "core/sampling.h"
#include "scene/bsdf_principled.h"
#include "scene/microfacet.h"
#include "scene/oren_nayar.h"
#include "scene/microfacet_mts.h"
#include "scene/plastic.h"

void cdl_bsdf_init(cdl_bsdf *b, const cdl_material *m, cdl_vec3 kd,
                   cdl_vec3 ns, cdl_vec3 ng)
{
    cdl_bsdf_init_common(b, m, kd, ns, ng);
    /* Lambert reads none of the other constants: not copying them at every
     * vertex was a tenth of path's shading time (issue 29). Textured
     * roughness (cdl_scene_bsdf_maps) may still set ax, ay. */
    if (b->type == CDL_MAT_DIFFUSE)
        return;
    b->ks = m->ks;
    b->kt = m->kt;
    b->ns = m->ns;
    b->eta = m->eta;
    b->eta3 = m->eta3;
    b->k3 = m->k3;
    b->fresnel = m->fresnel;
    b->mf = m->mf;
    b->nonlinear = m->nonlinear;
    b->spec_weight = m->spec_weight;
    b->coat_ri = m->coat_ri;
    b->sigma = m->sigma;
    b->on_full = m->on_full;
    b->coat_t = m->coat_t;
    /* below ~1e-4 the GGX lobe underflows in float */
    b->ax = cdl_maxf(m->alpha_x, 1e-4f);
    b->ay = cdl_maxf(m->alpha_y, 1e-4f);
    if (b->type == CDL_MAT_PRINCIPLED) /* constants; cdl_scene_bsdf adds textures */
        cdl_principled_at_init(&b->pr, &m->pr, NULL, 0.0f, 0.0f);
    if (b->type == CDL_MAT_PHONG) {
        /* the lobe's weight reaches ks (n+2)/(n+1): choosing it in that
         * proportion keeps every sample's weight within Kd + Ks (n+2)/(n+1) */
        float d = cdl_luminance(kd), s = cdl_luminance(b->ks) * (b->ns + 2.0f) / (b->ns + 1.0f);
        b->p_spec = d + s > 0.0f ? s / (d + s) : 0.0f;
    } else if (b->type == CDL_MAT_PLASTIC) {
        float d = cdl_luminance(kd), s = cdl_luminance(b->ks);
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

/* GGX reflection lobe of conductors and plastic, without Fresnel: returns
 * D G / (4 cos_o cos_i) and its VNDF density over wi; *cos_h = wi . h. */
static float ggx_reflect(const cdl_bsdf *b, cdl_vec3 lo, cdl_vec3 li, float *pdf, float *cos_h)
{
    cdl_vec3 h = cdl_add(lo, li);
    float len = cdl_length(h);
    *pdf = 0.0f;
    *cos_h = 0.0f;
    if (!(len > 0.0f))
        return 0.0f;
    h = cdl_scale(h, 1.0f / len);
    float d = cdl_dot(lo, h);
    if (d <= 0.0f)
        return 0.0f;
    *pdf = cdl_ggx_pdf_vndf(lo, h, b->ax, b->ay) / (4.0f * d);
    *cos_h = cdl_dot(li, h);
    return cdl_ggx_D(h, b->ax, b->ay) * cdl_ggx_G(lo, li, b->ax, b->ay) / (4.0f * lo.z * li.z);
}

/* f and pdf of an opaque material in the flipped local frame. */
static cdl_vec3 opaque_eval(const cdl_bsdf *b, cdl_vec3 lo, cdl_vec3 li, float *pdf)
{
    float pd = li.z * CDL_INV_PI, ps, cos_h;
    cdl_vec3 f = cdl_scale(b->kd, CDL_INV_PI);
    switch (b->type) {
    case CDL_MAT_ROUGH_DIFFUSE: /* sampled as Lambert: by the cosine */
        *pdf = pd;
        return cdl_oren_nayar(b->kd, b->sigma, b->on_full, lo, li);
    case CDL_MAT_PHONG:
        f = cdl_madd(f, b->ks, phong_lobe(b->ns, lo, li, &ps));
        *pdf = (1.0f - b->p_spec) * pd + b->p_spec * ps;
        return f;
    case CDL_MAT_CONDUCTOR: {
        if (b->mf != CDL_MF_PBRT) { /* Mitsuba's roughconductor */
            cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ay);
            cdl_vec3 h = cdl_normalize(cdl_add(lo, li));
            float D = cdl_mf_D(&d, h), g1o = cdl_mf_G1(&d, lo, h);
            *pdf = D * g1o / (4.0f * lo.z);
            float v = D * g1o * cdl_mf_G1(&d, li, h) / (4.0f * lo.z * li.z);
            return cdl_scale(cdl_mul(b->ks, cdl_fresnel_conductor(cdl_dot(lo, h), b->eta3, b->k3)), v);
        }
        float m = ggx_reflect(b, lo, li, pdf, &cos_h);
        /* ks: Mitsuba's specular_reflectance factor (1 for pbrt's metals) */
        return cdl_scale(cdl_mul(b->ks, cdl_fresnel_conductor(cos_h, b->eta3, b->k3)), m);
    }
    case CDL_MAT_PLASTIC: {
        float m = ggx_reflect(b, lo, li, &ps, &cos_h);
        f = cdl_madd(f, b->ks, m * cdl_fresnel_dielectric(cos_h, b->eta));
        *pdf = (1.0f - b->p_spec) * pd + b->p_spec * ps;
        return f;
    }
    case CDL_MAT_COATED:
    case CDL_MAT_ROUGH_COATED:
        return cdl_coat_eval(b, lo, li, pdf);
    default:
        *pdf = pd;
        return f;
    }
}

/* Rough dielectric (Walter et al. 2007, as pbrt-v4's DielectricBxDF):
 * f and pdf in the unflipped local frame (z = front side). */
static cdl_vec3 rough_glass_eval(const cdl_bsdf *b, cdl_vec3 lo, cdl_vec3 li, int adjoint, float *pdf)
{
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    *pdf = 0.0f;
    float co = lo.z, ci = li.z;
    if (co == 0.0f || ci == 0.0f)
        return zero;
    int reflect = co * ci > 0.0f;
    float etap = reflect ? 1.0f : (co > 0.0f ? b->eta : 1.0f / b->eta);
    cdl_vec3 wm = cdl_add(cdl_scale(li, etap), lo);
    float len = cdl_length(wm);
    if (!(len > 0.0f))
        return zero;
    wm = cdl_scale(wm, (wm.z < 0.0f ? -1.0f : 1.0f) / len);
    float dio = cdl_dot(wm, lo), dii = cdl_dot(wm, li);
    if (dii * ci < 0.0f || dio * co < 0.0f)
        return zero; /* back-facing microfacet */
    float F = cdl_fresnel_dielectric(dio, b->eta);
    cdl_vec3 v = co > 0.0f ? lo : cdl_neg(lo); /* the viewer, on the +z side */
    float pm, D, G;
    if (b->mf != CDL_MF_PBRT) { /* Mitsuba's distributions, separable G */
        cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ay);
        pm = cdl_mf_pdf_vndf(&d, v, wm);
        D = cdl_mf_D(&d, wm);
        G = cdl_mf_G1(&d, lo, wm) * cdl_mf_G1(&d, li, wm);
    } else {
        pm = cdl_ggx_pdf_vndf(v, wm, b->ax, b->ay);
        D = cdl_ggx_D(wm, b->ax, b->ay);
        G = cdl_ggx_G(lo, li, b->ax, b->ay);
    }
    if (reflect) {
        *pdf = pm / (4.0f * fabsf(dio)) * F;
        return cdl_scale(b->ks, D * G * F / fabsf(4.0f * ci * co));
    }
    float denom = dii + dio / etap;
    denom *= denom;
    *pdf = pm * fabsf(dii) / denom * (1.0f - F);
    float ft = D * G * (1.0f - F) * fabsf(dii * dio / (ci * co * denom));
    if (!adjoint)
        ft /= etap * etap;
    return cdl_scale(b->kt, ft);
}

static cdl_vec3 eval_unperturbed(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint)
{
    cdl_vec3 lo, li;
    float pdf;
    if (b->type == CDL_MAT_PRINCIPLED)
        return cdl_principled_eval(b, wo, wi, adjoint);
    if (b->type == CDL_MAT_ROUGH_DIELECTRIC) {
        /* the geometric sides decide reflection vs transmission */
        if (cdl_dot(wo, b->ng) * cdl_dot(wi, b->ng) * (cdl_to_local(&b->frame, wo).z *
                                                       cdl_to_local(&b->frame, wi).z) < 0.0f)
            return cdl_v3(0.0f, 0.0f, 0.0f);
        return rough_glass_eval(b, cdl_to_local(&b->frame, wo), cdl_to_local(&b->frame, wi), adjoint, &pdf);
    }
    if (!cdl_mat_is_opaque(b->type) || !cdl_bsdf_opaque_local(b, wo, wi, &lo, &li))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    return opaque_eval(b, lo, li, &pdf);
}

static float pdf_unperturbed(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    cdl_vec3 lo, li;
    float pdf = 0.0f;
    if (b->type == CDL_MAT_PRINCIPLED)
        return cdl_principled_pdf(b, wo, wi);
    if (b->type == CDL_MAT_ROUGH_DIELECTRIC) {
        lo = cdl_to_local(&b->frame, wo);
        li = cdl_to_local(&b->frame, wi);
        if (cdl_dot(wo, b->ng) * cdl_dot(wi, b->ng) * (lo.z * li.z) < 0.0f)
            return 0.0f; /* the same side rule as eval and sample */
        rough_glass_eval(b, lo, li, 0, &pdf);
        return pdf;
    }
    if (!cdl_mat_is_opaque(b->type) || !cdl_bsdf_opaque_local(b, wo, wi, &lo, &li))
        return 0.0f;
    opaque_eval(b, lo, li, &pdf);
    return pdf;
}

static int sample_opaque(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1,
                         float u2, cdl_scatter *s)
{
    float go = cdl_dot(wo, b->ng);
    if (fabsf(go) < 1e-6f || (b->one_sided && go < 0.0f))
        return 0;
    cdl_vec3 lo = cdl_to_local(&b->frame, wo);
    float side = go < 0.0f ? -1.0f : 1.0f;
    lo.z *= side;
    if (lo.z <= 0.0f)
        return 0;
    cdl_vec3 li;
    if (b->type == CDL_MAT_COATED || b->type == CDL_MAT_ROUGH_COATED) {
        int delta;
        cdl_vec3 w;
        float p;
        cdl_coat_sample(b, lo, u0, u1, u2, &li, &delta, &w, &p);
        if (delta) {
            if (li.z <= 0.0f)
                return 0;
            s->wi = cdl_to_world(&b->frame, cdl_v3(li.x, li.y, li.z * side));
            float gi = cdl_dot(s->wi, b->ng);
            if (gi * go <= 0.0f || fabsf(gi) < 1e-6f)
                return 0;
            s->delta = 1;
            s->pdf = p;
            s->weight = w;
            return 1;
        }
    } else if (b->type == CDL_MAT_CONDUCTOR && b->mf != CDL_MF_PBRT) {
        cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ay);
        cdl_vec3 h = cdl_mf_sample_vndf(&d, lo, u1, u2);
        li = cdl_sub(cdl_scale(h, 2.0f * cdl_dot(lo, h)), lo);
    } else if (b->type == CDL_MAT_CONDUCTOR || (b->type == CDL_MAT_PLASTIC && u0 < b->p_spec)) {
        cdl_vec3 h = cdl_ggx_sample_vndf(lo, b->ax, b->ay, u1, u2);
        li = cdl_sub(cdl_scale(h, 2.0f * cdl_dot(lo, h)), lo);
    } else if (b->type == CDL_MAT_PHONG && u0 < b->p_spec) {
        /* cos^n lobe around the mirror direction */
        float cos_a = powf(u1, 1.0f / (b->ns + 1.0f));
        float sin_a = sqrtf(cdl_maxf(0.0f, 1.0f - cos_a * cos_a));
        float phi = 2.0f * CDL_PI * u2;
        cdl_frame rf = cdl_frame_from(cdl_v3(-lo.x, -lo.y, lo.z));
        li = cdl_to_world(&rf, cdl_v3(sin_a * cosf(phi), sin_a * sinf(phi), cos_a));
    } else {
        li = cdl_sample_cosine_hemisphere(u1, u2);
    }
    if (b->type == CDL_MAT_DIFFUSE)
        return cdl_bsdf_sample_lambert(b, go, side, li, s);
    if (li.z <= 0.0f)
        return 0;
    cdl_vec3 wi = cdl_to_world(&b->frame, cdl_v3(li.x, li.y, li.z * side));
    /* The shading frame may send wi below the geometric surface; grazing
     * as cdl_bsdf_opaque_local (eval and pdf) defines it */
    float gi = cdl_dot(wi, b->ng);
    if (gi * go <= 0.0f || fabsf(gi) < 1e-6f)
        return 0;
    float pdf;
    cdl_vec3 f = opaque_eval(b, lo, li, &pdf);
    if (!(pdf > 0.0f))
        return 0;
    s->wi = wi;
    s->delta = 0;
    s->pdf = pdf;
    s->weight = cdl_scale(f, li.z / pdf);
    return 1;
}

static int sample_rough_glass(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2,
                              int adjoint, cdl_scatter *s)
{
    cdl_vec3 lo = cdl_to_local(&b->frame, wo);
    if (lo.z == 0.0f)
        return 0;
    cdl_vec3 v = lo.z > 0.0f ? lo : cdl_neg(lo), wm;
    if (b->mf != CDL_MF_PBRT) {
        cdl_mf d = cdl_mf_make((cdl_mf_type)b->mf, b->ax, b->ay);
        wm = cdl_mf_sample_vndf(&d, v, u1, u2);
    } else {
        wm = cdl_ggx_sample_vndf(v, b->ax, b->ay, u1, u2);
    }
    float dio = cdl_dot(lo, wm);
    float F = cdl_fresnel_dielectric(dio, b->eta);
    cdl_vec3 li;
    if (u0 < F) {
        li = cdl_sub(cdl_scale(wm, 2.0f * dio), lo);
        if (li.z * lo.z <= 0.0f)
            return 0;
    } else {
        /* refraction through wm; eta relative to the side wo is on */
        float eta = dio > 0.0f ? b->eta : 1.0f / b->eta;
        cdl_vec3 n = dio > 0.0f ? wm : cdl_neg(wm);
        float ci = fabsf(dio);
        float sin2_t = (1.0f - ci * ci) / (eta * eta);
        if (sin2_t >= 1.0f)
            return 0;
        float ct = sqrtf(1.0f - sin2_t);
        li = cdl_sub(cdl_scale(cdl_neg(lo), 1.0f / eta), cdl_scale(n, ct - ci / eta));
        if (li.z * lo.z >= 0.0f)
            return 0;
    }
    float pdf;
    cdl_vec3 f = rough_glass_eval(b, lo, li, adjoint, &pdf);
    if (!(pdf > 0.0f) || cdl_is_black(f))
        return 0;
    cdl_vec3 wi = cdl_normalize(cdl_to_world(&b->frame, li));
    /* geometric and shading sides must agree on reflection vs transmission */
    if ((cdl_dot(wi, b->ng) * cdl_dot(wo, b->ng) > 0.0f) != (li.z * lo.z > 0.0f))
        return 0;
    s->wi = wi;
    s->delta = 0;
    s->pdf = pdf;
    s->weight = cdl_scale(f, fabsf(li.z) / pdf);
    return 1;
}

static int sample_unperturbed(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2, int adjoint,
                              cdl_scatter *s)
{
    if (b->type == CDL_MAT_MIRROR) {
        cdl_vec3 n = b->frame.n;
        if (cdl_dot(wo, b->ng) < 0.0f)
            n = cdl_neg(n);
        s->wi = cdl_reflect(wo, n);
        s->weight = b->fresnel ? cdl_mul(b->ks, cdl_fresnel_conductor(fabsf(cdl_dot(wo, n)), b->eta3, b->k3)) : b->ks;
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
            s->weight = b->ks;
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
        s->weight = cdl_scale(b->kt, scale);
        return 1;
    }
    if (b->type == CDL_MAT_ROUGH_DIELECTRIC)
        return sample_rough_glass(b, wo, u0, u1, u2, adjoint, s);
    if (b->type == CDL_MAT_PRINCIPLED)
        return cdl_principled_sample(b, wo, u0, u1, u2, adjoint, s);
    return sample_opaque(b, wo, u0, u1, u2, s);
}

/* A frame perturbed by a bump or normal map (Mitsuba's bumpmap and
 * normalmap): wi must lie on the same side of the unperturbed and the
 * perturbed normal, and the response is shadowed by Conty Estevez et al.'s
 * microfacet term (Ray Tracing Gems, 2019, ch. 12) with alpha^2 =
 * tan^2(perturbation) / 8, as Mitsuba's use_shadowing_function. Returns
 * the factor on f (0: blocked). */
static float perturbation_factor(const cdl_bsdf *b, cdl_vec3 wi)
{
    float cb = cdl_dot(wi, b->nb), cp = cdl_dot(wi, b->frame.n);
    if (!(cb * cp > 0.0f))
        return 0.0f;
    float cn = cdl_dot(b->frame.n, b->nb);
    float tn = cn != 0.0f ? (1.0f - cn * cn) / (cn * cn) : INFINITY;
    float a2 = cdl_minf(0.125f * tn, 1.0f);
    float tw = (1.0f - cb * cb) / (cb * cb);
    float g = 2.0f / (1.0f + sqrtf(1.0f + a2 * tw));
    return isfinite(g) ? g : 0.0f;
}

/* Mitsuba's mask: the material scatters with probability opacity and
 * lets the rest pass straight on (a Dirac component, weight 1). */
cdl_vec3 cdl_bsdf_eval(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint)
{
    cdl_vec3 f = cdl_scale(eval_unperturbed(b, wo, wi, adjoint), b->opacity);
    if (!b->perturbed)
        return f;
    float k = perturbation_factor(b, wi);
    return k > 0.0f ? cdl_scale(f, k) : cdl_v3(0.0f, 0.0f, 0.0f);}

/* eval and pdf in one call: one change of frame and one lobe evaluation
 * where the two calls would make them twice (next-event estimation). */
cdl_vec3 cdl_bsdf_eval_pdf_any(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint, float *pdf)
{
    cdl_vec3 lo, li, zero = cdl_v3(0.0f, 0.0f, 0.0f);
    *pdf = 0.0f;
    if (!cdl_mat_is_opaque(b->type) || b->perturbed) {
        *pdf = cdl_bsdf_pdf(b, wo, wi);
        return cdl_bsdf_eval(b, wo, wi, adjoint);
    }
    if (!cdl_bsdf_opaque_local(b, wo, wi, &lo, &li))
        return zero;
    cdl_vec3 f = opaque_eval(b, lo, li, pdf);
    *pdf *= b->opacity;
    return cdl_scale(f, b->opacity);
}

float cdl_bsdf_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    if (b->perturbed && !(perturbation_factor(b, wi) > 0.0f))
        return 0.0f;
    return pdf_unperturbed(b, wo, wi) * b->opacity;
}

int cdl_bsdf_sample(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2, int adjoint, cdl_scatter *s)
{
    if (b->opacity < 1.0f) {
        if (u0 >= b->opacity) { /* through the mask */
            s->wi = cdl_neg(wo);
            s->weight = cdl_v3(1.0f, 1.0f, 1.0f);
            s->pdf = 1.0f - b->opacity;
            s->delta = 1;
            return 1;
        }
        u0 /= b->opacity;
    }
    if (!sample_unperturbed(b, wo, u0, u1, u2, adjoint, s))
        return 0;
    s->pdf *= b->opacity; /* the weight keeps opacity f / (opacity pdf) */
    if (!b->perturbed)
        return 1;
    float k = perturbation_factor(b, s->wi);
    s->weight = cdl_scale(s->weight, k);
    return k > 0.0f;}
