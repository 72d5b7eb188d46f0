/* Wavefront OBJ + MTL import through Assimp, after cdl_obj_check. */
#ifndef CDL_OBJ_LOADER_H
#define CDL_OBJ_LOADER_H

#include "scene/mesh.h"
#include "scene/scene.h"

/* Adds the file's triangles and materials to s (not committed). */
int cdl_load_obj(cdl_scene *s, const char *path, cdl_error *err);

/* The file's triangles as one mesh without materials (a Mitsuba shape);
 * normals and uvs only when every part has them. */
int cdl_obj_read_mesh(const char *path, cdl_mesh *m, cdl_error *err);

#endif
