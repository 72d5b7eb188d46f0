/* Clearance of a surface point x (unit normal n on the side of interest):
 * the distance from x to the nearest geometry that reaches into the
 * half-space in front of x's tangent plane, at most rmax. Geometry on or
 * behind the plane (x's own surface, the rest of a convex object) does
 * not count: a segment from x (lifted off its surface by a ray offset) to
 * a point of that half-space within the clearance passes nothing, so a
 * visibility test needs no shadow ray for it. */
#ifndef CDL_CLEARANCE_H
#define CDL_CLEARANCE_H

#include "scene/scene.h"

float cdl_clearance(const cdl_scene *s, cdl_vec3 x, cdl_vec3 n, float rmax);

#endif
