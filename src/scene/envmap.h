/* Environment maps: radiance from every direction as an image, in one of
 * three layouts:
 *  - equirectangular (pbrt-v3's InfiniteAreaLight: in the light's frame, z
 *    up, u = phi / 2 pi with phi = atan2(y, x), v = theta / pi from +z, the
 *    image's top row at v = 0), a texel constant over its 1/w x 1/h of (u, v);
 *  - a square in Clarberg's equal-area octahedral mapping (pbrt-v4's
 *    ImageInfiniteLight: every texel the same solid angle), texels constant;
 *  - Mitsuba 3's envmap: the same (u, v) as the first, but the texels are
 *    the nodes of a bilinear interpolation, texel (x, y) at
 *    u = (x + 1/2) / w (periodic in u) and v = y / (h - 1) (the first and
 *    last rows at the poles).
 * Importance-sampled by a piecewise-constant 2D distribution of luminance
 * (x sin(theta) for the lat-long layouts) over the texels, or for Mitsuba's
 * layout over the cells between four nodes (their mean luminance, so that
 * the density is positive wherever the interpolated radiance is). The
 * sampling density and cdl_envmap_pdf agree exactly. */
#ifndef CDL_ENVMAP_H
#define CDL_ENVMAP_H

#include "core/error.h"
#include "core/vec.h"

/* The layouts (values of cdl_envmap.layout). */
enum {
    CDL_ENVMAP_EQUIRECT = 0,   /* pbrt-v3 */
    CDL_ENVMAP_EQUAL_AREA = 1, /* pbrt-v4 */
    CDL_ENVMAP_MITSUBA = 2     /* Mitsuba 3, bilinear */
};

typedef struct cdl_envmap {
    int w, h;
    int layout;     /* CDL_ENVMAP_... */
    int cols, rows; /* the sampling grid: w x h texels, or Mitsuba's w x (h - 1) cells */
    float *rgb;     /* 3 per texel, radiance (scale applied) */
    float *func;    /* cols * rows sampling function: luminance * sin(theta) */
    float *cdf_row; /* rows + 1: marginal over rows */
    float *cdf_col; /* rows * (cols + 1): conditional per row */
    float mean;     /* mean of func over the grid */
    cdl_vec3 ex, ey, ez; /* the light frame's axes in world space */
    cdl_vec3 flux;  /* integral of the radiance over the sphere (W / m^2 / sr * sr) */
} cdl_envmap;

/* Reads path (EXR, PFM, PNG by content; Radiance .hdr by extension),
 * scaled by scale; frame: world images of the light's x, y, z axes
 * (orthonormalized here; a mirrored frame stays mirrored); layout:
 * CDL_ENVMAP_... */
int cdl_envmap_load(cdl_envmap *m, const char *path, cdl_vec3 scale, const cdl_vec3 frame[3], int layout,
                    cdl_error *err);
/* A map from given texels (tests and generated maps); takes rgb over. */
int cdl_envmap_init(cdl_envmap *m, int w, int h, float *rgb, const cdl_vec3 frame[3], int layout, cdl_error *err);

/* Clarberg's equal-area mapping between [0,1]^2 and the unit sphere (pbrt-v4). */
cdl_vec3 cdl_equal_area_square_to_sphere(float u, float v);
void cdl_equal_area_sphere_to_square(cdl_vec3 d, float *u, float *v);
void cdl_envmap_free(cdl_envmap *m);

/* Radiance arriving from world direction w (unit, pointing away from the scene). */
cdl_vec3 cdl_envmap_eval(const cdl_envmap *m, cdl_vec3 w);
/* A direction w by the map's distribution; returns its radiance, *pdf the
 * solid-angle density (0: nothing to sample). */
cdl_vec3 cdl_envmap_sample(const cdl_envmap *m, float u1, float u2, cdl_vec3 *w, float *pdf);
float cdl_envmap_pdf(const cdl_envmap *m, cdl_vec3 w);

#endif
