/* Scene files by extension: .obj (Wavefront OBJ + MTL through Assimp),
 * .pbrt (pbrt-v3/v4 scene description) and .xml (Mitsuba 0.6 / 3). */
#ifndef CDL_LOADER_H
#define CDL_LOADER_H

#include "core/common_params.h"
#include "scene/scene.h"

/* Loads path into an initialized, uncommitted scene; set may be NULL. */
int cdl_scene_load(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err);

/* The same with ndefs "name=value" parameters for a Mitsuba file's
 * <default>s (mitsuba -D); other formats warn that they do not read them. */
int cdl_scene_load_defined(cdl_scene *s, const char *path, const char (*defs)[CDL_DEFINE_LEN], int ndefs,
                           cdl_scene_settings *set, cdl_error *err);

#endif
