/* Mitsuba scene files (Mitsuba 0.6 and Mitsuba 3 XML, the common subset):
 * see mitsuba_internal.h for what is read and how names are matched. */
#ifndef CDL_MITSUBA_LOADER_H
#define CDL_MITSUBA_LOADER_H

#include "core/common_params.h"
#include "io/settings.h"

/* Loads path into an initialized, uncommitted scene; set may be NULL.
 * defs: ndefs "name=value" parameters set before the file's <default>s. */
int cdl_load_mitsuba(cdl_scene *s, const char *path, const char (*defs)[CDL_DEFINE_LEN], int ndefs,
                     cdl_scene_settings *set, cdl_error *err);

#endif
