/* 4x4 affine/projective transforms in double precision, built exactly as
 * pbrt-v3 builds them (transform.cpp: Translate, Scale, Rotate, LookAt),
 * so that scene files place geometry where pbrt places it. Matrices are
 * row-major and act on column vectors: p' = M p. */
#ifndef CDL_TRANSFORM_H
#define CDL_TRANSFORM_H

#include "core/vec.h"

typedef struct cdl_mat4 {
    double m[4][4];
} cdl_mat4;

cdl_mat4 cdl_mat4_identity(void);
/* From 16 numbers in pbrt's file order (column-major: pbrt transposes
 * the list it reads in Transform/ConcatTransform). */
cdl_mat4 cdl_mat4_from_pbrt(const double v[16]);
cdl_mat4 cdl_mat4_mul(const cdl_mat4 *a, const cdl_mat4 *b); /* a * b */
cdl_mat4 cdl_mat4_transpose(const cdl_mat4 *a);
/* Returns 0 and fills *inv, or -1 if a is singular or not finite. */
int cdl_mat4_inverse(const cdl_mat4 *a, cdl_mat4 *inv);
double cdl_mat4_det3(const cdl_mat4 *a); /* determinant of the upper 3x3 */
/* pbrt's Transform::SwapsHandedness: the upper 3x3 has a negative determinant. */
int cdl_mat4_swaps_handedness(const cdl_mat4 *a);
int cdl_mat4_is_finite(const cdl_mat4 *a);

cdl_mat4 cdl_mat4_translate(double x, double y, double z);
cdl_mat4 cdl_mat4_scale(double x, double y, double z);
/* theta in degrees about axis (normalized here); -1 for a zero axis. */
int cdl_mat4_rotate(double theta, double ax, double ay, double az, cdl_mat4 *out);
/* pbrt-v3 LookAt(): the world-to-camera matrix (inverse of the camera
 * frame right = cross(up, dir), newUp = cross(dir, right), dir). Returns
 * -1 when up is parallel to the view direction or eye == look. */
int cdl_mat4_lookat(const double eye[3], const double look[3], const double up[3], cdl_mat4 *out);

/* Applying: points (with the homogeneous divide), vectors, and normals
 * (the caller passes the inverse; normals use its transpose, as pbrt). */
void cdl_mat4_point(const cdl_mat4 *a, const double p[3], double out[3]);
void cdl_mat4_vector(const cdl_mat4 *a, const double v[3], double out[3]);
void cdl_mat4_normal(const cdl_mat4 *inv, const double n[3], double out[3]);
cdl_vec3 cdl_mat4_point3(const cdl_mat4 *a, cdl_vec3 p);
cdl_vec3 cdl_mat4_vector3(const cdl_mat4 *a, cdl_vec3 v);

/* 1 if the transform is a similarity (rotation, uniform scale, translation,
 * possibly mirrored; no projective part) to relative tolerance tol; the
 * scale factor goes to *scale. Spheres stay analytic under these. */
int cdl_mat4_is_similarity(const cdl_mat4 *a, double tol, double *scale);

#endif
