/* Materials as stored in the scene (an MTL `newmtl`, a pbrt `Material`),
 * before any texture lookup; cdl_bsdf (bsdf.h) is a material evaluated at
 * a hit. Emission is not a material property: see cdl_scene_add_emitter. */
#ifndef CDL_MATERIAL_H
#define CDL_MATERIAL_H

#include <math.h>

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
    CDL_MAT_COATED,          /* Mitsuba's plastic: diffuse base kd under a smooth dielectric coat of
                              * index eta reflecting ks F (a Dirac lobe); see plastic.h */
    CDL_MAT_ROUGH_COATED,    /* Mitsuba's roughplastic: the same under a rough coat (mf, alpha_x) */
    CDL_MAT_ROUGH_DIFFUSE,   /* Oren-Nayar of reflectance kd, slope deviation sigma (oren_nayar.h) */
    CDL_MAT_PRINCIPLED,      /* Mitsuba 3's principled(thin): base colour kd, the rest in pr */
    CDL_MAT_BLEND            /* Mitsuba's blendbsdf: material blend[0] or blend[1] by weight,
                              * decided at each hit (scene/attr.h); never a BSDF itself */
} cdl_mat_type;

/* Entries of the rough coat's transmittance table (Mitsuba's
 * MI_ROUGH_TRANSMITTANCE_RES), over cos theta in [0, 1]. */
#define CDL_COAT_RES 64

/* Scatters only in Dirac directions (mirror, smooth glass): never connected
 * to, never stores photons. */
static inline int cdl_mat_is_delta(cdl_mat_type t) { return t == CDL_MAT_MIRROR || t == CDL_MAT_DIELECTRIC; }

/* How a textured roughness becomes GGX alpha at each lookup: as it is
 * (Mitsuba's alpha), pbrt-v3's RoughnessToAlpha, pbrt-v4's sqrt. */
typedef enum cdl_rough_remap { CDL_ROUGH_ALPHA, CDL_ROUGH_PBRT3, CDL_ROUGH_PBRT4 } cdl_rough_remap;

/* The surface partials a bump map displaces (p' = p + h n, dp'/du =
 * S + dh/du n, dp'/dv = T + dh/dv n). PARTIALS: S, T = dp/du, dp/dv made
 * perpendicular to n (Mitsuba; pbrt on shapes without vertex normals).
 * pbrt's meshes with vertex normals displace its shading frame instead,
 * with s = dp/du made perpendicular and normalized, t = n x s: pbrt-v3
 * S, T = -s, -t (its triangle's ts = ss x ns, reversed and unit length:
 * its issues #188, #261), pbrt-v4 S, T = |dp/du| s, |dp/du| t. */
typedef enum cdl_bump_frame { CDL_BUMP_PARTIALS, CDL_BUMP_PBRT3_VN, CDL_BUMP_PBRT4_VN } cdl_bump_frame;

/* Textures that vary a material over its surface beyond kd (texture
 * indices, -1 = none). bump: Mitsuba's bumpmap (the height's uv gradient
 * times bump_scale tilts the shading frame), pbrt's bumpmap/displacement
 * (bump_scale 1); normal: Mitsuba's normalmap and pbrt-v4's (2 rgb - 1 is
 * the normal in the unperturbed shading frame: s along dp/du, t = n x s).
 * Read only when `on`, so that a zeroed material has none. */
typedef struct cdl_mat_maps {
    int on;
    int alpha_tex[2]; /* alpha_x, alpha_y from the textures' scalar values */
    int alpha_remap;  /* cdl_rough_remap of those values */
    int bump_tex;
    float bump_scale;
    int bump_frame;   /* cdl_bump_frame */
    int normal_tex;
} cdl_mat_maps;

/* A roughness r as GGX alpha (cdl_rough_remap): pbrt-v3's
 * TrowbridgeReitzDistribution::RoughnessToAlpha (log r, r clamped to
 * 1e-3) or pbrt-v4's sqrt(r). */
static inline float cdl_roughness_to_alpha(double r, int remap)
{
    if (remap == CDL_ROUGH_PBRT4)
        return (float)sqrt(r > 0.0 ? r : 0.0);
    if (remap != CDL_ROUGH_PBRT3)
        return (float)r;
    double x = log(r > 1e-3 ? r : 1e-3);
    return (float)(1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x + 0.000640711 * x * x * x * x);
}

/* The shading frame of this material follows dp/du (Mitsuba's): its
 * roughness is anisotropic or a map perturbs the frame. */
static inline int cdl_mat_uses_tangent(const cdl_mat_maps *mm, float ax, float ay)
{
    return ax != ay ||
           (mm->on && (mm->alpha_tex[0] >= 0 || mm->alpha_tex[1] >= 0 || mm->bump_tex >= 0 || mm->normal_tex >= 0));
}

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
    /* coated (Mitsuba's plastics), filled by cdl_coat_prepare but spec_weight */
    int mf;            /* microfacet model of rough coats and conductors (cdl_mf_type; 0 = pbrt's) */
    int nonlinear;     /* internal reflections tint the base (Mitsuba's `nonlinear`) */
    float spec_weight; /* Mitsuba's specular_sampling_weight: ks / (kd + ks) in means */
    float coat_ri;     /* diffuse reflectance of the coat seen from inside */
    float coat_t[CDL_COAT_RES]; /* rough coat: transmittance from outside against cos theta */
    /* Mitsuba's mask: where opacity (times the texture's luminance) < 1 the
     * surface lets light pass straight through, as a Dirac component */
    float sigma;       /* rough diffuse: Oren-Nayar's sigma in radians */
    int on_full;       /* rough diffuse: the full model (Mitsuba 0.6), else the qualitative (pbrt) */
    int masked;
    float opacity;
    int opacity_tex;  /* texture index or -1 */
    cdl_mat_maps maps; /* textured roughness, bump and normal maps */
    cdl_principled pr; /* principled: parameters other than the base colour */
    /* blend: (1 - w) blend[0] + w blend[1], w = blend_w times texture blend_tex;
     * blend_as >= 0: both are plain diffuse and the hit becomes that diffuse
     * material with the blended reflectance (exact, not a random choice) */
    int blend[2], blend_tex, blend_as;
    float blend_w;
    int hit_kd;        /* kd times the surface's kdh (set at the hit), not the kd texture */
    int one_sided;     /* opaque: reflects on the front (CCW) side only, black behind (Mitsuba's
                        * bsdfs outside a twosided wrapper); else on both sides */
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
    if (m.type == CDL_MAT_CONDUCTOR && m.alpha_x < CDL_SMOOTH_ALPHA && m.alpha_y < CDL_SMOOTH_ALPHA &&
        !(m.maps.on && (m.maps.alpha_tex[0] >= 0 || m.maps.alpha_tex[1] >= 0))) {
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
    m.maps.alpha_tex[0] = m.maps.alpha_tex[1] = m.maps.bump_tex = m.maps.normal_tex = -1;
    m.maps.bump_scale = 1.0f;
    m.blend_tex = m.blend_as = -1;
    return m;
}

#endif
