/* Spectra to the linear sRGB candela renders with: the CIE 1931 observer
 * and D65, 380..780 nm in 10 nm steps. */
#ifndef CDL_SPECTRUM_H
#define CDL_SPECTRUM_H

#include "core/vec.h"

#define CDL_CIE_N 41 /* 380, 390, ..., 780 nm */

extern const double cdl_cie_xyz[CDL_CIE_N][3];

/* XYZ to linear sRGB (sRGB primaries, D65 white). */
cdl_vec3 cdl_xyz_to_srgb(double x, double y, double z);

/* The piecewise-linear spectrum (lambda[i] nm, value[i]), n >= 1, lambda
 * increasing, held at its end values outside its range, as linear sRGB.
 * reflectance: under D65, so that a constant c gives (c, c, c) (Mitsuba
 * 3's bounded spectra); else integrated against the observer alone and
 * divided by the integral of y-bar (an emitter's). */
cdl_vec3 cdl_spectrum_to_srgb(const double *lambda, const double *value, int n, int reflectance);

#endif
