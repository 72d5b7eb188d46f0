/* BSDFs: a material evaluated at a surface point. Directions are world
 * space unit vectors pointing away from the surface; f excludes the cosine.
 * `adjoint` selects importance transport (light paths): refraction then
 * carries no 1/eta^2 radiance scaling. Opaque materials are two-sided;
 * dielectrics are entered through the front (CCW) face. */
#ifndef CDL_BSDF_H
#define CDL_BSDF_H

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

/* Every component is Dirac (a mask adds one more: passing through). */
static inline int cdl_bsdf_is_delta(const cdl_bsdf *b)
{
    return cdl_mat_is_delta(b->type);
}

/* eval and pdf cover the non-Dirac components only; a sample reports
 * which kind it drew in cdl_scatter.delta. */

cdl_vec3 cdl_bsdf_eval(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint);
float cdl_bsdf_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi);
/* Both at once, equal to the two calls (cheaper for opaque materials). */
cdl_vec3 cdl_bsdf_eval_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint, float *pdf);
/* Returns 0 when no direction could be sampled (the path ends). */
int cdl_bsdf_sample(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2,
                    int adjoint, cdl_scatter *s);

/* Fresnel reflectance of a smooth dielectric; cos_i > 0 on the side of
 * the incident direction, eta = eta_t / eta_i. */
float cdl_fresnel_dielectric(float cos_i, float eta);

#endif
