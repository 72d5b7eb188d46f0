/* Materials as stored in the scene (an MTL `newmtl`, a pbrt `Material`),
 * before any texture lookup; cdl_bsdf (bsdf.h) is a material evaluated at
 * a hit. Emission is not a material property: see cdl_scene_add_emitter. */
#ifndef CDL_MATERIAL_H
#define CDL_MATERIAL_H

#include "core/vec.h"
#include "scene/bsdf_principled.h"

typedef enum cdl_mat_type {
    CDL_MAT_DIFFUSE,         /* Lambert: kd */
    CDL_MAT_PHONG,           /* Lambert kd + normalized Phong lobe ks, exponent ns (MTL) */
    CDL_MAT_MIRROR,          /* ideal specular reflection, reflectance ks (times the conductor
                              * Fresnel term of eta3 + i k3 with `fresnel`) */
    CDL_MAT_DIELECTRIC,      /* smooth glass of index eta; reflectance ks, transmittance kt */
    CDL_MAT_CONDUCTOR,       /* GGX microfacet metal: complex index eta3 + i k3, roughness alpha */
    CDL_MAT_PLASTIC,         /* Lambert kd + GGX dielectric reflection ks (index eta), as pbrt-v3 */
    CDL_MAT_ROUGH_DIELECTRIC, /* GGX microfacet glass of index eta; ks, kt */
    CDL_MAT_PRINCIPLED       /* Mitsuba 3's principled(thin): base colour kd, the rest in pr */
} cdl_mat_type;

/* Scatters only in Dirac directions (mirror, smooth glass): never connected
 * to, never stores photons. */
static inline int cdl_mat_is_delta(cdl_mat_type t) { return t == CDL_MAT_MIRROR || t == CDL_MAT_DIELECTRIC; }

typedef struct cdl_material {
    cdl_mat_type type;
    cdl_vec3 kd;      /* diffuse reflectance, multiplied by the texture */
    int kd_tex;       /* texture index or -1 */
    cdl_vec3 ks;      /* specular reflectance (Phong, mirror, plastic, glass Kr; conductor: a factor) */
    cdl_vec3 kt;      /* specular transmittance (glass Kt) */
    float ns;         /* Phong exponent */
    float eta;        /* index of refraction (dielectric, plastic coat) */
    cdl_vec3 eta3, k3; /* conductor: complex index of refraction per channel */
    float alpha_x, alpha_y; /* GGX roughness (alpha, not pbrt's "roughness") */
    int fresnel;      /* mirror: reflectance ks times the conductor Fresnel term */
    cdl_principled pr; /* principled: parameters other than the base colour */
    char name[64];
} cdl_material;

/* Phong's sampling weight stays <= 1 only if kd + ks (n+2)/(n+1) <= 1 per
 * channel: the factor (<= 1) that brings the worst channel there. */
static inline float cdl_phong_energy_scale(const cdl_material *m)
{
    float lobe = (m->ns + 2.0f) / (m->ns + 1.0f);
    float worst = m->kd.x + m->ks.x * lobe;
    worst = worst > m->kd.y + m->ks.y * lobe ? worst : m->kd.y + m->ks.y * lobe;
    worst = worst > m->kd.z + m->ks.z * lobe ? worst : m->kd.z + m->ks.z * lobe;
    return worst > 1.0f ? 1.0f / worst : 1.0f;
}

/* Below this GGX alpha a conductor is a mirror (pbrt-v4's "effectively
 * smooth"): a lobe that narrow is reached by BSDF sampling alone, and a
 * method that connects to it (point lights, splats, merges) would see it
 * black or as fireflies. */
#define CDL_SMOOTH_ALPHA 1e-3f

/* A material as the scene stores it: an effectively smooth conductor
 * becomes a mirror with the conductor's Fresnel term. */
static inline cdl_material cdl_material_canonical(cdl_material m)
{
    if (m.type == CDL_MAT_CONDUCTOR && m.alpha_x < CDL_SMOOTH_ALPHA && m.alpha_y < CDL_SMOOTH_ALPHA) {
        m.type = CDL_MAT_MIRROR;
        m.fresnel = 1;
    }
    return m;
}

/* A material with every field at its neutral default. */
static inline cdl_material cdl_material_default(cdl_mat_type type)
{
    cdl_material m = {0};
    m.type = type;
    m.kd = cdl_v3(0.5f, 0.5f, 0.5f);
    m.kd_tex = -1;
    m.ks = cdl_v3(1.0f, 1.0f, 1.0f);
    m.kt = cdl_v3(1.0f, 1.0f, 1.0f);
    m.eta = 1.5f;
    m.eta3 = cdl_v3(0.2f, 0.92f, 1.1f); /* copper-like, pbrt's default metal */
    m.k3 = cdl_v3(3.91f, 2.45f, 2.14f);
    m.alpha_x = m.alpha_y = 0.1f;
    return m;
}

#endif
