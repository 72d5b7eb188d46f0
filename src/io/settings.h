/* The rendering settings a scene file gives (cdl_scene_settings), as the
 * readers fill them. */
#ifndef CDL_IO_SETTINGS_H
#define CDL_IO_SETTINGS_H

#include "scene/scene.h"

/* Nothing given: no camera, size, spp, depth or integrator. */
void cdl_scene_settings_init(cdl_scene_settings *set);

/* Adds a parameter of the file's integrator block (for the method's table
 * to read); past CDL_MAX_SCENE_PARAMS, a warning. */
void cdl_scene_settings_param(cdl_scene_settings *set, const char *name, const char *value, const char *file,
                              int line);

#endif
