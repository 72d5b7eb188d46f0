/* Loop subdivision (Loop 1987) of a triangle mesh to its limit surface, as
 * pbrt's "loopsubdiv" shape asks for. */
#ifndef CDL_SUBDIV_H
#define CDL_SUBDIV_H

#include "scene/mesh.h"

/* Replaces m (positions and triangles; normals and uv are dropped) by its
 * levels-fold Loop subdivision with every vertex moved to its limit
 * position, and gives it vertex normals (area-weighted, counter-clockwise
 * faces). Boundary edges use the boundary (cubic B-spline) rules; an edge
 * shared by more than two triangles is treated as a boundary. Errors
 * (memory, a mesh that would pass 2^31 triangles) name file:line. */
int cdl_mesh_loop_subdivide(cdl_mesh *m, int levels, const char *file, int line, cdl_error *err);

#endif
