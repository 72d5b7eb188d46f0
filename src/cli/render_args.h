/* The options shared by `candela render` and `candela photons`, and the
 * setup both do: parse, load the scene, place the camera. */
#ifndef CDL_RENDER_ARGS_H
#define CDL_RENDER_ARGS_H

#include "integrators/integrator.h"
#include "scene/loader.h"

#define MAX_OUT 8
#define MAX_POINT_LIGHTS 64

typedef struct render_args {
    const char *scene, *integrator;
    const char *out[MAX_OUT];
    int nout;
    long spp;
    double time;
    int width, height;
    int has_lookat;
    float lookat[9];
    double fov;
    long maxdepth, threads;
    unsigned long long seed;
    float lights[MAX_POINT_LIGHTS][6];
    int nlights;
    double exposure;
    cdl_sampler_kind sampler;
    cdl_mis_kind mis;
    long light_paths, interleave;
    double threshold, clamp;
    int strata_distance, single_shadow_rays;
    int aov_pathlength, aov_strata, aov_bandwidth, aov_records;
    cdl_pm_options pm;
    cdl_gkde_options gkde;
    cdl_splat_options splat;
    int photons_given, direct_given, gather_given; /* shared with pm: splat takes them only if given */
    /* given on the command line (else the scene file or the default decides) */
    int has_integrator, has_res, has_fov, has_maxdepth;
} render_args;

/* Parses argv; -1 after --help (help printed), else 0 or an error. */
int cdl_render_parse(int argc, char **argv, render_args *a, cdl_error *err);
/* Sets --threads, loads a->scene (with --point-light additions), applies the file's
 * settings, fills opt (camera included). defout receives the default
 * output name when no -o was given. */
int cdl_render_setup(render_args *a, cdl_scene *scene, cdl_scene_settings *set, cdl_options *opt,
                     char *defout, size_t ndefout, cdl_error *err);

#endif
