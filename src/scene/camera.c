#include "scene/camera.h"

#include <string.h>

int cdl_camera_init(cdl_camera *c, cdl_vec3 eye, cdl_vec3 target, cdl_vec3 up,
                    float fov_deg, int width, int height, cdl_error *err)
{
    if (!(fov_deg > 0.0f && fov_deg < 180.0f))
        return cdl_error_set(err, CDL_ERR_USAGE, "fov", 0,
                             "field of view must be in (0, 180) degrees, got %g", (double)fov_deg);
    if (width <= 0 || height <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, "res", 0, "resolution must be positive");
    cdl_vec3 f = cdl_sub(target, eye);
    float fl = cdl_length(f);
    if (!(fl > 0.0f) || !isfinite(fl))
        return cdl_error_set(err, CDL_ERR_USAGE, "lookat", 0, "eye and target must differ");
    f = cdl_scale(f, 1.0f / fl);
    cdl_vec3 r = cdl_cross(f, up);
    float rl = cdl_length(r);
    if (!(rl > 1e-6f * cdl_length(up)) || !isfinite(rl))
        return cdl_error_set(err, CDL_ERR_USAGE, "lookat", 0,
                             "up vector must not be parallel to the view direction");
    memset(c, 0, sizeof *c);
    cdl_filter_box(&c->filter);
    c->eye = eye;
    c->fwd = f;
    c->right = cdl_scale(r, 1.0f / rl);
    c->up = cdl_cross(c->right, f);
    c->tan_half = tanf(0.5f * fov_deg * CDL_PI / 180.0f);
    c->width = width;
    c->height = height;
    c->aspect = (float)width / (float)height;
    return 0;
}

int cdl_camera_init_frame(cdl_camera *c, cdl_vec3 eye, cdl_vec3 right, cdl_vec3 up, cdl_vec3 fwd,
                          float fov_deg, int width, int height, cdl_error *err)
{
    if (!(fov_deg > 0.0f && fov_deg < 180.0f))
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "field of view must be in (0, 180) degrees, got %g",
                             (double)fov_deg);
    if (width <= 0 || height <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, "res", 0, "resolution must be positive");
    cdl_vec3 det = cdl_cross(right, up);
    if (!cdl_is_finite3(eye) || !cdl_is_finite3(fwd) || !(fabsf(cdl_dot(det, fwd)) > 1e-12f))
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "camera transform is singular or not finite");
    memset(c, 0, sizeof *c);
    cdl_filter_box(&c->filter);
    c->eye = eye;
    c->fwd = fwd;
    c->right = right;
    c->up = up;
    c->width = width;
    c->height = height;
    c->aspect = (float)width / (float)height;
    float t = tanf(0.5f * fov_deg * CDL_PI / 180.0f);
    c->tan_half = width >= height ? t : t / c->aspect;
    return 0;
}

int cdl_camera_init_ortho(cdl_camera *c, cdl_vec3 eye, cdl_vec3 right, cdl_vec3 up, cdl_vec3 fwd, float half_w,
                          float half_h, float near, int width, int height, cdl_error *err)
{
    /* a 90 degree field of view keeps the pinhole fields meaningful */
    int rc = cdl_camera_init_frame(c, eye, right, up, fwd, 90.0f, width, height, err);
    if (rc)
        return rc;
    if (!(half_w > 0.0f) || !(half_h > 0.0f) || !isfinite(half_w) || !isfinite(half_h) || !(near >= 0.0f) ||
        !isfinite(near))
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "orthographic camera: extent and near clip must be positive");
    c->ortho = 1;
    c->half_w = half_w;
    c->half_h = half_h;
    c->near = near;
    return 0;
}
