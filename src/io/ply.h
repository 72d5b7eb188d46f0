/* Stanford PLY triangle meshes, as referenced by pbrt's Shape "plymesh".
 *
 * Reads ascii 1.0, binary_little_endian 1.0 and binary_big_endian 1.0.
 * From the "vertex" element it takes x y z, optionally nx ny nz and a
 * texture coordinate pair (u v, s t, texture_u texture_v or texture_s
 * texture_t); from the "face" element the vertex_indices (or vertex_index)
 * list, fan-triangulating polygons. The other scalar properties of those
 * two elements become the mesh's attributes, named and grouped as Mitsuba
 * does ("vertex_color" from color_0..2 or r g b, "face_weight" from
 * weight_0; a face's values go to each triangle of its fan); integer
 * ones are normalized and decoded from sRGB. Other elements are skipped. The whole file is read into memory and parsed there.
 *
 * Errors name the file and, for the header and ASCII bodies, the 1-based
 * text line; binary bodies have no lines, so their errors give line 0 and
 * say which element is bad ("face 17: ..."). Element numbers in messages
 * are 0-based, like the indices that refer to them. ASCII bodies must hold
 * one element per line, as the PLY format describes. */
#ifndef CDL_PLY_H
#define CDL_PLY_H

#include <stdint.h>

#include "core/error.h"
#include "scene/mesh.h"

typedef cdl_mesh cdl_ply_mesh; /* polygons with n > 3 vertices are fan-triangulated */

/* Fills m (all fields zero on failure). A file without faces is an error.
 * Every stored number is finite with |x| <= CDL_MAX_COORD and every index
 * is < nverts. */
int cdl_ply_read(const char *path, cdl_ply_mesh *m, cdl_error *err);

/* Frees the arrays and zeroes m; safe on a zeroed or already freed mesh. */
void cdl_ply_free(cdl_ply_mesh *m);

#endif
