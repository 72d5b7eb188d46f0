/* Mitsuba scene files (Mitsuba 0.6 and Mitsuba 3 XML, the common subset):
 * see mitsuba_internal.h for what is read and how names are matched. */
#ifndef CDL_MITSUBA_LOADER_H
#define CDL_MITSUBA_LOADER_H

#include "io/settings.h"

/* Loads path into an initialized, uncommitted scene; set may be NULL. */
int cdl_load_mitsuba(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err);

#endif
