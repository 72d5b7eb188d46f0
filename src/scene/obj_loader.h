/* Wavefront OBJ + MTL import through Assimp, after cdl_obj_check. */
#ifndef CDL_OBJ_LOADER_H
#define CDL_OBJ_LOADER_H

#include "scene/scene.h"

/* Adds the file's triangles and materials to s (not committed). */
int cdl_load_obj(cdl_scene *s, const char *path, cdl_error *err);

#endif
