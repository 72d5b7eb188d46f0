#include "scene/loader.h"

#include <stdlib.h>
#include <strings.h>
#include <string.h>

#include "scene/obj_check.h"
#include "scene/obj_loader.h"

int cdl_scene_load(cdl_scene *s, const char *path, cdl_error *err)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (dot && (!slash || dot > slash) && !strcasecmp(dot, ".obj"))
        return cdl_load_obj(s, path, err);
    /* A missing file is a clearer message than an unknown format. */
    char *data;
    size_t size;
    int rc = cdl_read_text_file(path, &data, &size, err);
    if (rc)
        return rc;
    free(data);
    return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "unknown scene format (expected .obj)");
}
