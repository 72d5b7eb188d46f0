/* Mitsuba 3's "sdfgrid" shape as a triangle mesh: a grid of signed
 * distances over the object-space cube [0, 1]^3 (sample (x, y, z) at
 * (x / (nx - 1), y / (ny - 1), z / (nz - 1))) whose surface is the zero set
 * of the trilinear interpolant, in the voxels whose corners do not all have
 * one strict sign (Mitsuba intersects only those). Mitsuba finds that zero
 * set per ray; here it is polygonized: every voxel is cut into levels^3
 * cells, each into six tetrahedra (Kuhn's, which match across faces), and
 * the surface crosses each tetrahedron edge at a root of the interpolant
 * found by bisection, so every vertex lies on Mitsuba's surface and the
 * mesh converges to it as levels grows. Positive distances are outside:
 * triangles face them, and shading normals are Mitsuba's ("smooth": the
 * blend of voxel gradients of Hansson-Soderlund, Evans and Akenine-Moller,
 * JCGT 11(3) 2022; "analytic": the interpolant's gradient). */
#ifndef CDL_SDFGRID_H
#define CDL_SDFGRID_H

#include <stddef.h>

#include "scene/mesh.h"

typedef enum { CDL_SDF_SMOOTH, CDL_SDF_ANALYTIC } cdl_sdf_normals;

typedef struct cdl_sdfgrid {
    int n[3];       /* samples along x, y, z; each >= 2 */
    const float *v; /* v[(z * n[1] + y) * n[0] + x], finite */
} cdl_sdfgrid;

/* The interpolant at object-space p (clamped to the cube) and its gradient
 * in object space (grad may be NULL). */
double cdl_sdfgrid_eval(const cdl_sdfgrid *g, const double p[3], double grad[3]);

/* Mitsuba's unit shading normal at object-space p; "analytic" uses the
 * voxel holding p. A zero vector where every gradient vanishes. */
void cdl_sdfgrid_normal(const cdl_sdfgrid *g, cdl_sdf_normals how, const double p[3], double out[3]);

/* Subdivisions per voxel edge that put about 128 cells along the grid's
 * longest axis (1 to 8). */
int cdl_sdfgrid_default_levels(const cdl_sdfgrid *g);

/* Polygonizes g into m (object space, normals, no uv). Errors (memory,
 * more than max_tris triangles, no surface at all) name file:line. */
int cdl_sdfgrid_polygonize(const cdl_sdfgrid *g, int levels, cdl_sdf_normals how, size_t max_tris, cdl_mesh *m,
                           const char *file, int line, cdl_error *err);

#endif
