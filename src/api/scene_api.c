/* The public scene handle: a loaded, committed scene and what its file
 * says about rendering. */
#include <stdlib.h>

#include "api/settings.h"
#include "io/loader.h"

int cdl_scene_open(const char *path, const cdl_settings *settings, cdl_scene **out, cdl_error *err)
{
    if (!out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_scene_open: no place for the scene");
    *out = NULL;
    if (!path || !path[0])
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "no scene file given");
    cdl_scene *s = malloc(sizeof *s);
    if (!s)
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    const cdl_log_sink *prev = cdl_log_push(settings ? &settings->sink : NULL);
    int rc = cdl_scene_init(s, path, err);
    if (!rc)
        rc = cdl_scene_load_defined(s, path, settings ? settings->c.defines : NULL, settings ? settings->c.ndefines : 0,
                                    &s->settings, err);
    for (int i = 0; !rc && settings && i < settings->c.nlights; i++) {
        const float *l = settings->c.lights[i];
        rc = cdl_scene_add_point_light(s, cdl_v3(l[0], l[1], l[2]), cdl_v3(l[3], l[4], l[5]), err);
    }
    if (!rc)
        rc = cdl_scene_commit(s, err);
    cdl_log_pop(prev);
    if (rc) {
        cdl_scene_free(s);
        free(s);
        return rc;
    }
    *out = s;
    return 0;
}

void cdl_scene_release(cdl_scene *s)
{
    if (!s)
        return;
    cdl_scene_free(s);
    free(s);
}

void cdl_scene_get_info(const cdl_scene *s, cdl_scene_info *info)
{
    *info = (cdl_scene_info){0};
    info->output = "";
    if (!s)
        return;
    info->triangles = s->ntris;
    info->spheres = s->nspheres;
    info->lights = s->nlights;
    info->materials = s->nmats;
    const float *mn = &s->bmin.x, *mx = &s->bmax.x;
    for (int k = 0; k < 3; k++) {
        info->bounds_min[k] = mn[k];
        info->bounds_max[k] = mx[k];
    }
    info->has_camera = s->settings.has_camera;
    info->width = s->settings.width;
    info->height = s->settings.height;
    info->spp = s->settings.spp;
    info->output = s->settings.filename;
}
