#include "io/loader.h"

#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "io/mitsuba_loader.h"
#include "io/obj_check.h"
#include "io/obj_loader.h"
#include "io/pbrt_loader.h"
#include "io/settings.h"
#include "core/log.h"

static int has_ext(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) && !strcasecmp(dot, ext);
}

int cdl_scene_load(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err)
{
    return cdl_scene_load_defined(s, path, NULL, 0, set, err);
}

int cdl_scene_load_defined(cdl_scene *s, const char *path, const char (*defs)[CDL_DEFINE_LEN], int ndefs,
                           cdl_scene_settings *set, cdl_error *err)
{
    cdl_scene_settings dummy;
    if (!set)
        set = &dummy;
    cdl_scene_settings_init(set);
    if (has_ext(path, ".xml"))
        return cdl_load_mitsuba(s, path, defs, ndefs, set, err);
    for (int i = 0; i < ndefs; i++)
        cdl_warn(path, 0, "define \"%s\": only Mitsuba files have parameters to set (ignored)", defs[i]);
    if (has_ext(path, ".obj"))
        return cdl_load_obj(s, path, err);
    if (has_ext(path, ".pbrt"))
        return cdl_load_pbrt(s, path, set, err);
    /* A missing file is a clearer message than an unknown format. */
    char *data;
    size_t size;
    int rc = cdl_read_text_file(path, &data, &size, err);
    if (rc)
        return rc;
    free(data);
    return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "unknown scene format (expected .obj, .pbrt or Mitsuba .xml)");
}
