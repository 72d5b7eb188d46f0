/* Mitsuba 3's principled and principledthin BSDFs (Burley 2012 and 2015 as
 * Mitsuba's src/bsdfs/principled*.cpp define them): the parameters as a
 * material stores them (constants, or scales of scene textures) and as
 * evaluated at a hit, and the lobes, their sampling and densities.
 * The base colour is the material's kd (and kd_tex). */
#ifndef CDL_BSDF_PRINCIPLED_H
#define CDL_BSDF_PRINCIPLED_H

#include <stddef.h>

#include "core/vec.h"

struct cdl_bsdf;
struct cdl_scatter;
struct cdl_texture;

/* The scalar parameters; Mitsuba's defaults are in cdl_principled_default. */
typedef enum cdl_pr_param {
    CDL_PR_ROUGHNESS,
    CDL_PR_ANISOTROPIC,
    CDL_PR_METALLIC,   /* principled only */
    CDL_PR_SPEC_TRANS,
    CDL_PR_SPEC_TINT,
    CDL_PR_SHEEN,
    CDL_PR_SHEEN_TINT,
    CDL_PR_FLATNESS,
    CDL_PR_CLEARCOAT,  /* principled only */
    CDL_PR_CC_GLOSS,   /* principled only: clearcoat_gloss */
    CDL_PR_DIFF_TRANS, /* principledthin only, in [0, 2] as Mitsuba reads it */
    CDL_PR_ETA,        /* relative index (principled: from eta or specular) */
    CDL_PR_NPARAMS
} cdl_pr_param;

/* Sampling rates (Mitsuba's *_sampling_rate), by slot:
 *   principled:     diffuse_reflectance, main_specular, clearcoat, -
 *   principledthin: diffuse_reflectance, specular_reflectance,
 *                   specular_transmittance, diffuse_transmittance */
#define CDL_PR_NRATES 4

typedef struct cdl_principled {
    int thin;                      /* principledthin */
    float value[CDL_PR_NPARAMS];   /* the constant, or the texture's scale */
    int tex[CDL_PR_NPARAMS];       /* scene texture or -1 */
    float rate[CDL_PR_NRATES];
} cdl_principled;

/* The parameters at one surface point. */
typedef struct cdl_principled_at {
    int thin;
    float p[CDL_PR_NPARAMS];
    float rate[CDL_PR_NRATES];
} cdl_principled_at;

/* Mitsuba's defaults: roughness 0.5, specular 0.5 (eta 1.4905...) or thin
 * eta 1.5, every other parameter 0, every sampling rate 1. */
cdl_principled cdl_principled_default(int thin);

/* Parameters at (u, v): each constant times its texture's value there
 * (texs may be NULL: constants only), clamped to Mitsuba's documented
 * ranges so that no lobe weight turns negative. */
void cdl_principled_at_init(cdl_principled_at *p, const cdl_principled *m, const struct cdl_texture *texs,
                            float u, float v);

/* Mitsuba's shading tangent is dp/du: the frame's first axis is dpdu made
 * orthogonal to the normal (unchanged when dpdu is zero or along it). */
void cdl_principled_tangent(struct cdl_bsdf *b, cdl_vec3 dpdu);

/* World-space entry points behind cdl_bsdf_eval, _pdf and _sample. */
cdl_vec3 cdl_principled_eval(const struct cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint);
float cdl_principled_pdf(const struct cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi);
int cdl_principled_sample(const struct cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2, int adjoint,
                          struct cdl_scatter *s);

/* Local-frame model (z = shading normal), with Mitsuba's names: wi is the
 * direction the path arrived from (candela's wo), wo the scattered one.
 * Returns f |cos(wo)| (Mitsuba's BSDF::eval) and sets *pdf. */
cdl_vec3 cdl_principled_local(const cdl_principled_at *p, cdl_vec3 base, cdl_vec3 wi, cdl_vec3 wo, int adjoint,
                              float *pdf);
/* Samples wo for wi in the local frame; 0 when no direction results. */
int cdl_principled_sample_local(const cdl_principled_at *p, cdl_vec3 wi, float u0, float u1, float u2,
                                cdl_vec3 *wo);

#endif
