/* Scene files by extension: .obj (Wavefront OBJ + MTL through Assimp). */
#ifndef CDL_LOADER_H
#define CDL_LOADER_H

#include "scene/scene.h"

/* Loads path into an initialized, uncommitted scene. */
int cdl_scene_load(cdl_scene *s, const char *path, cdl_error *err);

#endif
