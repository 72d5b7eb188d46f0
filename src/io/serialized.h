/* Mitsuba ".serialized" triangle meshes (Mitsuba 0.4-0.6 and 3, <shape
 * type="serialized"> with filename and shape_index).
 *
 * A file is a sequence of shapes followed by a dictionary. Each shape is a
 * 4-byte header (uint16 format id 0x041C, uint16 version 3 or 4) and a zlib
 * stream holding: uint32 flags, [version 4: NUL-terminated name], uint64
 * vertex and triangle counts, positions, optional normals, texture
 * coordinates and colors (float or double, as flagged), then uint32 vertex
 * indices. The dictionary at the end is the byte offset of every shape
 * (uint32 in version 3 files, uint64 in version 4) and a uint32 shape
 * count. Everything is little-endian.
 *
 * Only the requested shape's bytes are read, so reading every shape of a
 * large file costs one pass over it. Colors, the shape name and the face
 * normal flag are read past and dropped. Errors name the file, give line 0
 * and say which shape is bad ("shape 3: ..."); shape and element numbers
 * are 0-based. */
#ifndef CDL_SERIALIZED_H
#define CDL_SERIALIZED_H

#include <stdint.h>

#include "core/error.h"
#include "scene/mesh.h"

typedef cdl_mesh cdl_serialized_mesh;

/* Reads shape shape_index of path into m (all fields zero on failure).
 * Doubles are converted to float. Every position is finite with |x| <=
 * CDL_MAX_COORD, normals and uvs are finite, every index is < nverts, and
 * the shape has at least one triangle. */
int cdl_serialized_read(const char *path, uint32_t shape_index, cdl_serialized_mesh *m, cdl_error *err);

/* Frees the arrays and zeroes m; safe on a zeroed or already freed mesh. */
void cdl_serialized_free(cdl_serialized_mesh *m);

#endif
