/* Scene files by extension: .obj (Wavefront OBJ + MTL through Assimp) and
 * .pbrt (pbrt-v3/v4 scene description). */
#ifndef CDL_LOADER_H
#define CDL_LOADER_H

#include "scene/scene.h"

/* What a scene file says about rendering; the command line overrides it. */
typedef struct cdl_scene_settings {
    int has_camera;                 /* eye/right/up/fwd/fov are set */
    cdl_vec3 eye, right, up, fwd;   /* world images of camera origin and axes (pbrt) */
    float fov;                      /* degrees, on the shorter image axis */
    int width, height;              /* 0 = not given */
    int spp;                        /* 0 = not given */
    int maxdepth;                   /* -1 = not given */
    char integrator[32];            /* candela integrator name, "" = not given */
    char filename[1024];            /* the file's output image name, "" = not given */
} cdl_scene_settings;

void cdl_scene_settings_init(cdl_scene_settings *set);

/* Loads path into an initialized, uncommitted scene; set may be NULL. */
int cdl_scene_load(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err);

#endif
