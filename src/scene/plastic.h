/* Mitsuba 3's plastic and roughplastic (its bsdfs/plastic.cpp and
 * roughplastic.cpp): a diffuse base under a dielectric coat of relative
 * index eta. The coat reflects ks F (a mirror for plastic, a Beckmann or
 * GGX microfacet lobe with separable Smith masking for roughplastic); the
 * base is seen through it, weighted by the coat's transmittance in and out,
 * divided by eta^2 and by 1 - (kd) Ri for the light the coat sends back
 * down (Ri its diffuse reflectance from inside; kd Ri with `nonlinear`).
 * The smooth coat's transmittance is 1 - F; the rough one's is Mitsuba's
 * table over cos theta, integrated at load with Mitsuba's quadrature.
 * pbrt's plastic (a Lambert lobe beside a microfacet lobe) stays
 * CDL_MAT_PLASTIC in bsdf.c. */
#ifndef CDL_PLASTIC_H
#define CDL_PLASTIC_H

#include "scene/bsdf.h"

/* Fills coat_ri and coat_t of a CDL_MAT_COATED / CDL_MAT_ROUGH_COATED
 * material from eta, mf and alpha_x (roughly 0.1 s for a rough coat);
 * spec_weight is the reader's (it knows the textures' means). */
void cdl_coat_prepare(cdl_material *m);

/* Mitsuba's fresnel_diffuse_reflectance: the share of diffuse light a
 * dielectric boundary of relative index eta reflects (fits by Egan &
 * Hilgeman and d'Eon & Irving). */
float cdl_fresnel_diffuse_reflectance(float eta);

/* f (without cosine) and pdf of the non-Dirac part, in the local frame
 * mirrored to wo's side (lo.z > 0, li.z > 0). */
cdl_vec3 cdl_coat_eval(const cdl_bsdf *b, cdl_vec3 lo, cdl_vec3 li, float *pdf);

/* Chooses a direction in the same frame. Returns 1 with *li set; *delta
 * set (and *weight, *pdf as the discrete probability) when the smooth
 * coat's mirror was chosen; else the caller evaluates cdl_coat_eval. */
int cdl_coat_sample(const cdl_bsdf *b, cdl_vec3 lo, float u0, float u1, float u2, cdl_vec3 *li,
                    int *delta, cdl_vec3 *weight, float *pdf);

#endif
