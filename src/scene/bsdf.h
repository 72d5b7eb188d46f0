/* BSDFs: a material evaluated at a surface point. Directions are world
 * space unit vectors pointing away from the surface; f excludes the cosine.
 * `adjoint` selects importance transport (light paths): refraction then
 * carries no 1/eta^2 radiance scaling. Opaque materials are two-sided;
 * dielectrics are entered through the front (CCW) face. */
#ifndef CDL_BSDF_H
#define CDL_BSDF_H

#include "core/sampling.h"
#include "scene/material.h"

typedef struct cdl_bsdf {
    cdl_mat_type type;
    cdl_vec3 kd, ks, kt;
    float ns, eta;
    cdl_vec3 eta3, k3;  /* conductor */
    float ax, ay;       /* GGX roughness */
    float p_spec;    /* probability of sampling the specular lobe (Phong, plastic) */
    int fresnel;     /* mirror: ks times the conductor Fresnel term of eta3, k3 */
    int mf, nonlinear;           /* coated (plastic.h) */
    float spec_weight, coat_ri;
    float sigma;        /* rough diffuse */
    int on_full;
    const float *coat_t;         /* the material's table: it outlives the bsdf */
    float opacity;   /* < 1: the rest passes straight through (Mitsuba's mask) */
    cdl_principled_at pr; /* principled: parameters at the hit */
    cdl_frame frame; /* shading frame; n = shading normal, front side */
    cdl_vec3 ng;     /* geometric normal, same side as the CCW front face */
    cdl_vec3 nb;     /* shading normal before a bump/normal map (frame.n without) */
    int perturbed;   /* frame.n differs from nb: Mitsuba's checks and shadowing term apply */
    int one_sided;   /* opaque: black unless wo and wi lie on the front (ng's) side */
} cdl_bsdf;

typedef struct cdl_scatter {
    cdl_vec3 wi;
    cdl_vec3 weight; /* f * |cos(wi, n)| / pdf */
    float pdf;       /* solid angle; for delta events the discrete probability */
    int delta;       /* 1 if wi came from a specular (Dirac) component */
} cdl_scatter;

/* Builds the BSDF at a hit: kd already includes the texture; the opacity
 * is the material's, to be multiplied by its texture by the caller. */
void cdl_bsdf_init(cdl_bsdf *b, const cdl_material *m, cdl_vec3 kd,
                   cdl_vec3 ns, cdl_vec3 ng);

static inline int cdl_mat_is_opaque(cdl_mat_type t)
{
    return t == CDL_MAT_DIFFUSE || t == CDL_MAT_PHONG || t == CDL_MAT_CONDUCTOR || t == CDL_MAT_PLASTIC ||
           t == CDL_MAT_COATED || t == CDL_MAT_ROUGH_COATED || t == CDL_MAT_ROUGH_DIFFUSE;
}

/* The part of cdl_bsdf_init every material needs, and all a Lambertian
 * one needs (inline: path calls it at every vertex). */
static inline void cdl_bsdf_init_common(cdl_bsdf *b, const cdl_material *m, cdl_vec3 kd, cdl_vec3 ns,
                                        cdl_vec3 ng)
{
    b->type = m->type;
    b->kd = kd;
    b->opacity = m->masked ? cdl_minf(1.0f, cdl_maxf(0.0f, m->opacity)) : 1.0f;
    b->ng = ng;
    /* Shading normal on the geometric normal's side: interpolated normals
     * of a mesh with flipped winding must not turn the frame inside out. */
    if (cdl_dot(ns, ng) < 0.0f)
        ns = cdl_neg(ns);
    b->frame = cdl_frame_from(ns);
    b->nb = ns;
    b->perturbed = 0;
    b->one_sided = m->one_sided && cdl_mat_is_opaque(b->type);
    b->p_spec = 0.0f;
}

/* Every component is Dirac (a mask adds one more: passing through). */
static inline int cdl_bsdf_is_delta(const cdl_bsdf *b)
{
    return cdl_mat_is_delta(b->type);
}

/* Opaque materials are two-sided: both directions are mirrored to the
 * side wo is on. Returns 0 if wo and wi lie on different geometric sides
 * (light leaking through a surface is never reflected) or either grazes
 * it. */
static inline int cdl_bsdf_opaque_local(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, cdl_vec3 *lo, cdl_vec3 *li)
{
    float go = cdl_dot(wo, b->ng), gi = cdl_dot(wi, b->ng);
    /* within 1e-6 of the plane the side is rounding: two points of one
     * sheet of zero thickness, one on each side, must not connect */
    if (go * gi <= 0.0f || fabsf(go) < 1e-6f || fabsf(gi) < 1e-6f || (b->one_sided && go < 0.0f))
        return 0;
    *lo = cdl_to_local(&b->frame, wo);
    *li = cdl_to_local(&b->frame, wi);
    if (go < 0.0f) {
        lo->z = -lo->z;
        li->z = -li->z;
    }
    return lo->z > 0.0f && li->z > 0.0f;
}

/* eval and pdf cover the non-Dirac components only; a sample reports
 * which kind it drew in cdl_scatter.delta. */

cdl_vec3 cdl_bsdf_eval(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint);
float cdl_bsdf_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi);
/* The _any call takes every material; the inline one below does an
 * unperturbed Lambertian surface itself (the common case: path spent as
 * long in the calls as in the arithmetic, issue 29). */
cdl_vec3 cdl_bsdf_eval_pdf_any(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint, float *pdf);
/* Returns 0 when no direction could be sampled (the path ends). */
int cdl_bsdf_sample(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2, int adjoint, cdl_scatter *s);

/* Both at once, equal to the two calls (cheaper for opaque materials). */
static inline cdl_vec3 cdl_bsdf_eval_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint, float *pdf)
{
    if (b->type != CDL_MAT_DIFFUSE || b->perturbed)
        return cdl_bsdf_eval_pdf_any(b, wo, wi, adjoint, pdf);
    cdl_vec3 lo, li;
    *pdf = 0.0f;
    if (!cdl_bsdf_opaque_local(b, wo, wi, &lo, &li))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    *pdf = li.z * CDL_INV_PI * b->opacity;
    return cdl_scale(cdl_scale(b->kd, CDL_INV_PI), b->opacity);
}

/* The scatter of a Lambertian surface towards li, a cosine-weighted
 * direction in the local frame flipped to wo's side: go = wo . ng,
 * side = its sign. */
static inline int cdl_bsdf_sample_lambert(const cdl_bsdf *b, float go, float side, cdl_vec3 li, cdl_scatter *s)
{
    if (li.z <= 0.0f)
        return 0;
    cdl_vec3 wi = cdl_to_world(&b->frame, cdl_v3(li.x, li.y, li.z * side));
    /* The shading frame may send wi below the geometric surface; grazing
     * as cdl_bsdf_opaque_local (eval and pdf) defines it */
    float gi = cdl_dot(wi, b->ng);
    if (gi * go <= 0.0f || fabsf(gi) < 1e-6f)
        return 0;
    /* kd/pi cos over cos/pi: no division to wait for */
    s->wi = wi;
    s->delta = 0;
    s->pdf = li.z * CDL_INV_PI;
    s->weight = b->kd;
    return 1;
}

/* cdl_bsdf_sample with an unperturbed Lambertian surface inline, for
 * path's every vertex. Inlined, the same arithmetic may round otherwise
 * (-ffp-contract=fast fuses what its context allows): photon tracing
 * through it moved pm's and splat's images by 5e-8 in a few pixels, so
 * the other methods keep the call and their bits. */
static inline int cdl_bsdf_sample_inline(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2,
                                         int adjoint, cdl_scatter *s)
{
    if (b->type != CDL_MAT_DIFFUSE || b->perturbed || b->opacity < 1.0f) {
        /* through a copy: *s, whose address the call does not take, can
         * stay in registers (path read wi back through memory, and the
         * 8-byte load of 4-byte stores stalled: 3 % of its time) */
        cdl_scatter t;
        int ok = cdl_bsdf_sample(b, wo, u0, u1, u2, adjoint, &t);
        *s = t;
        return ok;
    }
    float go = cdl_dot(wo, b->ng);
    if (fabsf(go) < 1e-6f || (b->one_sided && go < 0.0f))
        return 0;
    float side = go < 0.0f ? -1.0f : 1.0f;
    if (cdl_to_local(&b->frame, wo).z * side <= 0.0f)
        return 0;
    if (!cdl_bsdf_sample_lambert(b, go, side, cdl_sample_cosine_hemisphere(u1, u2), s))
        return 0;
    s->pdf *= b->opacity;
    return 1;
}

/* Fresnel reflectance of a smooth dielectric; cos_i > 0 on the side of
 * the incident direction, eta = eta_t / eta_i. */
float cdl_fresnel_dielectric(float cos_i, float eta);

#endif
