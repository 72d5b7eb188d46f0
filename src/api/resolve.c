/* From settings and a scene to the options a method runs with: the scene
 * file's settings fill in what was not given, and the camera is placed. */
#include <math.h>
#include <string.h>

#include "api/resolve.h"
#include "transport/light_select.h"

/* Scene-file settings fill in what the settings left open. */
static void apply_file(cdl_settings *a, const cdl_scene_settings *set)
{
    if (!a->has_integrator && set->integrator[0] && cdl_integrator_find(set->integrator))
        memcpy(a->integrator, set->integrator, sizeof a->integrator);
    if (!a->has_res && set->width > 0 && set->height > 0) {
        a->width = set->width;
        a->height = set->height;
    }
    if (!a->has_maxdepth && set->maxdepth >= 0)
        a->maxdepth = set->maxdepth > 1024 ? 1024 : set->maxdepth;
    if (!a->spp && a->time <= 0.0)
        a->spp = set->spp > 0 ? set->spp : 64;
}

/* Default camera: looks down -z at the bounds' centre from far enough
 * that the bounding sphere fills the vertical field of view. */
static int frame_scene(const cdl_scene *s, double fov, int w, int h, cdl_camera *cam, cdl_error *err)
{
    cdl_vec3 c = cdl_scale(cdl_add(s->bmin, s->bmax), 0.5f);
    float r = 0.5f * cdl_length(cdl_sub(s->bmax, s->bmin));
    float dist = r / sinf(0.5f * (float)fov * CDL_PI / 180.0f);
    cdl_vec3 eye = cdl_add(c, cdl_v3(0.0f, 0.0f, dist));
    return cdl_camera_init(cam, eye, c, cdl_v3(0.0f, 1.0f, 0.0f), (float)fov, w, h, err);
}

int cdl_settings_resolve(const cdl_settings *in, const cdl_scene *scene, cdl_settings *a, cdl_options *opt,
                         cdl_error *err)
{
    *a = *in;
    int rc = cdl_settings_check(a, err);
    if (rc)
        return rc;
    const cdl_scene_settings *set = &scene->settings;
    apply_file(a, set);
    cdl_options_default(opt);
    opt->maxdepth = (int)a->maxdepth;
    opt->seed = a->seed;
    opt->sampler = a->sampler;
    opt->mis = a->mis;
    opt->light_paths = a->light_paths < 0 ? CDL_LIGHT_PATHS_PER_SAMPLE : (uint32_t)a->light_paths;
    opt->interleave = (uint32_t)a->interleave;
    opt->threshold = (float)a->threshold;
    opt->clamp = (float)a->clamp;
    opt->strata_distance = a->strata_distance;
    opt->single_shadow_rays = a->single_shadow_rays;
    opt->progressive = a->progressive;
    opt->alpha = (float)a->alpha;
    opt->pm = a->pm;
    opt->gkde = a->gkde;
    opt->splat = a->splat;
    if (a->photons_given)
        opt->splat.photons = a->pm.photons;
    if (a->gather_given)
        opt->splat.gather = a->pm.gather;
    if (a->direct_given)
        opt->splat.direct_sample = !a->pm.direct_photons && a->pm.direct != CDL_DIRECT_NONE;
    opt->splat.direct_none = a->direct_given && a->pm.direct == CDL_DIRECT_NONE;
    if (a->has_lookat)
        return cdl_camera_init(&opt->camera, cdl_v3(a->lookat[0], a->lookat[1], a->lookat[2]),
                               cdl_v3(a->lookat[3], a->lookat[4], a->lookat[5]),
                               cdl_v3(a->lookat[6], a->lookat[7], a->lookat[8]), (float)a->fov, a->width,
                               a->height, err);
    if (set->has_camera)
        return cdl_camera_init_frame(&opt->camera, set->eye, set->right, set->up, set->fwd,
                                     a->has_fov ? (float)a->fov : set->fov, a->width, a->height, err);
    return frame_scene(scene, a->fov, a->width, a->height, &opt->camera, err);
}
