/* Pinhole perspective or orthographic camera, with its pixel filter.
 * Raster (0,0) is the top-left corner of the image; +x of the raster is
 * the camera's right = forward x up. */
#ifndef CDL_CAMERA_H
#define CDL_CAMERA_H

#include "core/error.h"
#include "core/vec.h"
#include "film/filter.h"

typedef struct cdl_camera {
    cdl_vec3 eye, fwd, right, up; /* world images of camera z, x, y (orthonormal for lookat) */
    float tan_half;               /* tan(vertical fov / 2) */
    float aspect;                 /* width / height */
    int width, height;
    /* orthographic: rays leave eye + sx right + sy up + near fwd along fwd,
     * sx in [-half_w, half_w] across the image, sy in [-half_h, half_h] */
    int ortho;
    float half_w, half_h, near;
    cdl_filter filter; /* the one-pixel box unless a scene file asks otherwise */
} cdl_camera;

/* fov_deg is the vertical field of view; fails on degenerate frames. */
int cdl_camera_init(cdl_camera *c, cdl_vec3 eye, cdl_vec3 target, cdl_vec3 up,
                    float fov_deg, int width, int height, cdl_error *err);

/* A camera-to-world frame as pbrt gives it: eye and the world images of
 * the camera's +x (image right), +y (image up) and +z (view) axes, which
 * may form a left- or right-handed, even non-orthonormal, frame; the field
 * of view applies to the shorter image axis, as in pbrt. */
int cdl_camera_init_frame(cdl_camera *c, cdl_vec3 eye, cdl_vec3 right, cdl_vec3 up, cdl_vec3 fwd,
                          float fov_deg, int width, int height, cdl_error *err);

/* Orthographic (Mitsuba's orthographic sensor): the frame as above, the
 * image spanning [-half_w, half_w] x [-half_h, half_h] of right and up,
 * rays starting at distance near along fwd. */
int cdl_camera_init_ortho(cdl_camera *c, cdl_vec3 eye, cdl_vec3 right, cdl_vec3 up, cdl_vec3 fwd, float half_w,
                          float half_h, float near, int width, int height, cdl_error *err);

/* Unit direction through raster position (x, y) in pixels (pinhole). */
static inline cdl_vec3 cdl_camera_ray(const cdl_camera *c, float x, float y)
{
    float sx = (2.0f * x / (float)c->width - 1.0f) * c->tan_half * c->aspect;
    float sy = (1.0f - 2.0f * y / (float)c->height) * c->tan_half;
    return cdl_normalize(cdl_add(c->fwd, cdl_add(cdl_scale(c->right, sx), cdl_scale(c->up, sy))));
}

/* The ray through raster position (x, y): origin and unit direction. */
static inline void cdl_camera_gen(const cdl_camera *c, float x, float y, cdl_vec3 *o, cdl_vec3 *d)
{
    if (!c->ortho) {
        *o = c->eye;
        *d = cdl_camera_ray(c, x, y);
        return;
    }
    float sx = (2.0f * x / (float)c->width - 1.0f) * c->half_w;
    float sy = (1.0f - 2.0f * y / (float)c->height) * c->half_h;
    *o = cdl_add(cdl_madd(c->eye, c->fwd, c->near), cdl_add(cdl_scale(c->right, sx), cdl_scale(c->up, sy)));
    *d = cdl_normalize(c->fwd);
}

/* A camera sample of pixel (px, py) from two uniform numbers: its raster
 * position and the weight of its radiance (the pixel filter's). */
static inline void cdl_camera_sample(const cdl_camera *c, int px, int py, float u1, float u2, float *x, float *y,
                                     float *weight)
{
    cdl_filter_sample(&c->filter, px, py, c->width, c->height, u1, u2, x, y, weight);
}

/* Raster position where direction d (from the eye) lands; 0 when it
 * points outside the image or backwards (always for the orthographic
 * camera, which no point can be connected to). Used by light tracing. */
static inline int cdl_camera_raster(const cdl_camera *c, cdl_vec3 d, float *x, float *y)
{
    if (c->ortho)
        return 0;
    float z = cdl_dot(d, c->fwd);
    if (z <= 0.0f)
        return 0;
    float sx = cdl_dot(d, c->right) / (z * cdl_dot(c->right, c->right));
    float sy = cdl_dot(d, c->up) / (z * cdl_dot(c->up, c->up));
    *x = 0.5f * (sx / (c->tan_half * c->aspect) + 1.0f) * (float)c->width;
    *y = 0.5f * (1.0f - sy / c->tan_half) * (float)c->height;
    return *x >= 0.0f && *x < (float)c->width && *y >= 0.0f && *y < (float)c->height;
}

/* Importance of the pinhole camera for unit direction d leaving the eye,
 * normalized over the whole image: 1 / (A cos^4) with A the image's area on
 * the plane at distance 1 (pbrt-v3's We); *pdf_dir = 1 / (A cos^3) is the
 * density of camera rays in solid angle. Assumes a rigid camera frame. */
static inline float cdl_camera_We(const cdl_camera *c, cdl_vec3 d, float *pdf_dir)
{
    float x, y;
    *pdf_dir = 0.0f;
    if (!cdl_camera_raster(c, d, &x, &y))
        return 0.0f;
    float cos_t = cdl_dot(d, c->fwd) / cdl_length(c->fwd);
    float A = 4.0f * c->tan_half * c->tan_half * c->aspect;
    float c2 = cos_t * cos_t;
    *pdf_dir = 1.0f / (A * c2 * cos_t);
    return 1.0f / (A * c2 * c2);
}

#endif
