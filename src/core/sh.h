/* Real spherical harmonics up to band 3 (16 coefficients, orthonormal on
 * the sphere; index l (l + 1) + m), as splat's radiance maps store
 * incident radiance (Herzog et al. 2007, §6.1.2), and their rotation. */
#ifndef CDL_SH_H
#define CDL_SH_H

#include "core/vec.h"

#define CDL_SH_BANDS 4
#define CDL_SH_N 16

/* The 16 basis functions at unit direction d. */
void cdl_sh_eval(cdl_vec3 d, float y[CDL_SH_N]);

/* Rotation by interpolation: band l is fixed by its values at 2l + 1
 * directions, so the coefficients of g(M v) follow from g at M u_j. */
typedef struct cdl_sh_rot {
    cdl_vec3 u[CDL_SH_N];       /* band l's directions at l^2 .. l^2 + 2l */
    float inv[CDL_SH_N][7];      /* row l^2 + k: band l's inverse matrix row k */
} cdl_sh_rot;

/* Returns 0, or -1 if a band's directions were ill-conditioned (never for
 * the built-in ones; tested). */
int cdl_sh_rot_init(cdl_sh_rot *r);

/* out: the coefficients of v -> g(v.x t + v.y b + v.z n) where g has the
 * coefficients in (world to the frame (t, b, n)); nc channels, coefficient
 * k of channel c at [k * nc + c]. */
void cdl_sh_rotate(const cdl_sh_rot *r, cdl_frame f, const float *in, float *out, int nc);

#endif
