/* Scene files by extension: .obj (Wavefront OBJ + MTL through Assimp),
 * .pbrt (pbrt-v3/v4 scene description) and .xml (Mitsuba 0.6 / 3). */
#ifndef CDL_LOADER_H
#define CDL_LOADER_H

#include "scene/scene.h"

/* Loads path into an initialized, uncommitted scene; set may be NULL. */
int cdl_scene_load(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err);

#endif
