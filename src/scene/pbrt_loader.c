/* Placeholder until the pbrt reader lands. */
#include "scene/pbrt_loader.h"

int cdl_load_pbrt(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err)
{
    (void)s;
    (void)set;
    return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "pbrt scene files are not supported yet");
}
