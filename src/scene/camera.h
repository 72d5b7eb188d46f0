/* Pinhole perspective camera. Raster (0,0) is the top-left corner of the
 * image; +x of the raster is the camera's right = forward x up. */
#ifndef CDL_CAMERA_H
#define CDL_CAMERA_H

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_camera {
    cdl_vec3 eye, fwd, right, up; /* world images of camera z, x, y (orthonormal for --lookat) */
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

#endif
