/* A material's BSDF in spherical harmonics (Herzog et al. 2007, eq. 6.1):
 * for outgoing directions at discrete angles theta_o in the local frame
 * (normal z, x towards the outgoing direction: isotropic BSDFs need no
 * azimuth), the coefficients c_lm = int f(w_o, w) Y_lm(w) dw over the
 * sphere, f extended evenly below the surface (incident radiance is zero
 * there, so any extension integrates the same; the even one is smooth,
 * and makes a Lambertian BSDF a constant: a single coefficient, exact).
 * Reflected radiance is then sum c_lm lambda_lm with lambda the
 * coefficients of L cos(theta) (eq. 6.4). f is affine in the diffuse
 * albedo kd, so a table holds c at kd = 0 and its slope per unit kd;
 * textures scale per eye sample. */
#ifndef CDL_BSDF_SH_H
#define CDL_BSDF_SH_H

#include "core/error.h"
#include "core/sh.h"
#include "scene/material.h"

#define CDL_BSDF_SH_BINS 32 /* cos(theta_o) = 0 .. 1 */

typedef struct cdl_bsdf_sh {
    /* [bin][k][channel]: coefficient k at kd = 0, and its change per unit kd */
    float c0[CDL_BSDF_SH_BINS][CDL_SH_N][3], dc[CDL_BSDF_SH_BINS][CDL_SH_N][3];
} cdl_bsdf_sh;

/* Projects material m (not a delta one) numerically: BSDF sampling and a
 * uniform hemisphere grid, combined by the balance heuristic. */
void cdl_bsdf_sh_build(cdl_bsdf_sh *t, const cdl_material *m);

/* Coefficients (RGB interleaved, [k * 3 + c]) for outgoing cos(theta_o)
 * and diffuse albedo kd, interpolated between bins. */
void cdl_bsdf_sh_lookup(const cdl_bsdf_sh *t, float cos_o, cdl_vec3 kd, float out[CDL_SH_N * 3]);

#endif
