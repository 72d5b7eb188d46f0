/* Pinhole perspective camera. Raster (0,0) is the top-left corner of the
 * image; +x of the raster is the camera's right = forward x up. */
#ifndef CDL_CAMERA_H
#define CDL_CAMERA_H

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_camera {
    cdl_vec3 eye, fwd, right, up; /* world images of camera z, x, y (orthonormal for lookat) */
    float tan_half;               /* tan(vertical fov / 2) */
    float aspect;                 /* width / height */
    int width, height;
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

/* Unit direction through raster position (x, y) in pixels. */
static inline cdl_vec3 cdl_camera_ray(const cdl_camera *c, float x, float y)
{
    float sx = (2.0f * x / (float)c->width - 1.0f) * c->tan_half * c->aspect;
    float sy = (1.0f - 2.0f * y / (float)c->height) * c->tan_half;
    return cdl_normalize(cdl_add(c->fwd, cdl_add(cdl_scale(c->right, sx), cdl_scale(c->up, sy))));
}

/* Raster position where direction d (from the eye) lands; 0 when it
 * points outside the image or backwards. Used by light tracing. */
static inline int cdl_camera_raster(const cdl_camera *c, cdl_vec3 d, float *x, float *y)
{
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
