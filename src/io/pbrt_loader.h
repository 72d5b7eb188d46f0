/* pbrt-v3 / pbrt-v4 scene files (the subset listed in README.md). */
#ifndef CDL_PBRT_LOADER_H
#define CDL_PBRT_LOADER_H

#include "io/settings.h"

int cdl_load_pbrt(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err);

#endif
