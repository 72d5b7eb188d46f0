/* Environment maps: radiance from every direction as an image, either
 * equirectangular (pbrt-v3's InfiniteAreaLight: in the light's frame, z up,
 * u = phi / 2 pi with phi = atan2(y, x), v = theta / pi from +z, the image's
 * top row at v = 0) or a square in Clarberg's equal-area octahedral mapping
 * (pbrt-v4's ImageInfiniteLight: every texel the same solid angle),
 * importance-sampled by a piecewise-constant 2D distribution of luminance
 * (x sin(theta) for equirectangular maps). A texel's radiance is constant
 * over it, so evaluation and sampling density agree exactly. */
#ifndef CDL_ENVMAP_H
#define CDL_ENVMAP_H

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_envmap {
    int w, h;
    int equal_area; /* pbrt-v4's square equal-area mapping, else equirectangular */
    float *rgb;     /* 3 per texel, radiance (scale applied) */
    float *func;    /* w * h sampling function: luminance * sin(theta) (+ a floor) */
    float *cdf_row; /* h + 1: marginal over rows */
    float *cdf_col; /* h * (w + 1): conditional per row */
    float mean;     /* mean of func over the texels */
    cdl_vec3 ex, ey, ez; /* the light frame's axes in world space */
    cdl_vec3 flux;  /* integral of the radiance over the sphere (W / m^2 / sr * sr) */
} cdl_envmap;

/* Reads path (EXR, PFM, PNG by content; Radiance .hdr by extension),
 * scaled by scale; frame: world images of the light's x, y, z axes
 * (orthonormalized here; a mirrored frame stays mirrored). */
int cdl_envmap_load(cdl_envmap *m, const char *path, cdl_vec3 scale, const cdl_vec3 frame[3], int equal_area,
                    cdl_error *err);
/* A map from given texels (tests and generated maps); takes rgb over. */
int cdl_envmap_init(cdl_envmap *m, int w, int h, float *rgb, const cdl_vec3 frame[3], int equal_area,
                    cdl_error *err);

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
