/* From settings and a scene to the options a method runs with: the scene
 * file's settings fill in what was not given, and the camera is placed. */
#include <math.h>
#include <string.h>

#include "api/resolve.h"
#include "core/log.h"
#include "transport/light_select.h"

/* Scene-file settings fill in what the settings left open. */
static void apply_file(cdl_settings *a, const cdl_scene_settings *set)
{
    cdl_common_params *c = &a->c;
    if (!cdl_settings_given(a, "integrator") && set->integrator[0]) {
        if (cdl_integrator_find(set->integrator))
            memcpy(c->integrator, set->integrator, sizeof c->integrator);
        else
            cdl_warn(set->integrator_file, set->integrator_line, "integrator \"%s\" is not one of candela's: %s is used",
                     set->integrator, c->integrator);
    }
    if (!cdl_settings_given(a, "res") && set->width > 0 && set->height > 0) {
        c->res[0] = set->width;
        c->res[1] = set->height;
    }
    if (!cdl_settings_given(a, "maxdepth") && set->maxdepth >= 0)
        c->maxdepth = set->maxdepth > 1024 ? 1024 : set->maxdepth;
    if (cdl_settings_given(a, "time"))
        c->spp = 0;
    else if (!cdl_settings_given(a, "spp") && set->spp > 0)
        c->spp = set->spp;
}

/* The file's integrator parameters that the method reads and the settings
 * leave open; a warning with file and line for the others. */
static void apply_file_params(const cdl_settings *a, const cdl_scene_settings *set, const cdl_integrator_vtbl *vt,
                              cdl_options *opt)
{
    for (int i = 0; i < set->nparams; i++) {
        const cdl_scene_param *fp = &set->params[i];
        const cdl_param *p = cdl_method_param(vt, fp->name);
        int given = 0;
        for (int k = 0; k < a->nmethod; k++)
            given |= !strcmp(a->method[k].name, fp->name);
        cdl_error e;
        if (!p)
            cdl_warn(fp->file, fp->line, "integrator parameter \"%s\": %s does not read it (ignored)", fp->name,
                     vt->name);
        else if (!given && cdl_param_set(p, fp->value, opt, &e))
            cdl_warn(fp->file, fp->line, "integrator parameter \"%s\": %s (ignored)", fp->name, e.msg);
    }
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
    const cdl_common_params *c = &a->c;
    opt->maxdepth = (int)c->maxdepth;
    opt->seed = (uint64_t)c->seed;
    opt->sampler = (cdl_sampler_kind)c->sampler;
    const cdl_integrator_vtbl *vt = cdl_integrator_find(c->integrator);
    apply_file_params(a, set, vt, opt);
    if ((rc = cdl_settings_apply(a, vt, opt, err)))
        return rc;
    int w = c->res[0], h = c->res[1];
    const float *la = c->lookat;
    if (cdl_settings_given(a, "lookat"))
        rc = cdl_camera_init(&opt->camera, cdl_v3(la[0], la[1], la[2]), cdl_v3(la[3], la[4], la[5]),
                             cdl_v3(la[6], la[7], la[8]), (float)c->fov, w, h, err);
    else if (set->has_camera && set->ortho)
        rc = cdl_camera_init_ortho(&opt->camera, set->eye, set->right, set->up, set->fwd, set->ortho_half_w,
                                   set->ortho_half_w * (float)h / (float)w, set->ortho_near, w, h, err);
    else if (set->has_camera)
        rc = cdl_camera_init_frame(&opt->camera, set->eye, set->right, set->up, set->fwd,
                                   cdl_settings_given(a, "fov") ? (float)c->fov : set->fov, w, h, err);
    else
        rc = frame_scene(scene, c->fov, w, h, &opt->camera, err);
    if (rc)
        return rc;
    if (set->has_filter && c->filter == 0) {
        /* the methods that accumulate per pixel outside cdl_camera_sample keep the box */
        if (!set->filter.wide || !strcmp(vt->name, "path") || !strcmp(vt->name, "bdpt") || !strcmp(vt->name, "pm"))
            opt->camera.filter = set->filter;
        else
            cdl_warn(set->filter_file, set->filter_line, "%s filters with the one-pixel box: the pixel filter is ignored",
                     vt->name);
    }
    /* the methods that trace eye subpaths or connect to the camera need a pinhole */
    if (opt->camera.ortho && strcmp(vt->name, "path"))
        return cdl_error_set(err, CDL_ERR_USAGE, set->integrator_file, set->integrator_line,
                             "the orthographic camera is rendered by path only, not by %s", vt->name);
    return 0;
}
