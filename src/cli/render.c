/* candela render SCENE [options]: load, render progressive passes until
 * the sample or time budget is met (or Ctrl-C), write the images. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <float.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/gkde_args.h"
#include "cli/splat_args.h"
#include "transport/light_select.h"
#include "cli/pm_args.h"
#include "cli/render_args.h"
#include "core/log.h"
#include "film/film.h"
#include "film/image.h"
#include "integrators/integrator.h"
#include "scene/loader.h"


static void render_help(void)
{
    printf("usage: candela render SCENE [options]\n"
           "\n"
           "SCENE is a Wavefront OBJ file (materials from its MTL files) or a pbrt-v3/v4\n"
           "scene file (.pbrt), whose camera, film, sampler and integrator settings apply\n"
           "unless the options below override them.\n"
           "\n"
           "  -i, --integrator NAME   light transport method (default path)\n"
           "  -o, --output FILE       .exr (32-bit float), .png (sRGB) or .pfm; repeatable\n"
           "                          (default: SCENE's name with .exr, in the current directory)\n"
           "      --spp N             samples per pixel, one per pass (default 64)\n"
           "      --time SEC          render whole passes until SEC seconds are spent\n"
           "      --res WxH           image size (default 512x512)\n"
           "      --lookat ex,ey,ez,tx,ty,tz,ux,uy,uz   camera position, target, up\n"
           "      --fov DEG           vertical field of view (default 40)\n"
           "                          without --lookat the camera frames the scene's bounds\n"
           "      --maxdepth N        maximum bounces (1 = direct light only; default 64)\n"
           "      --seed N            random seed (default 1); same seed, same image\n"
           "      --sampler NAME      sobol (Owen-scrambled, default) or independent\n"
           "      --threads N         worker threads (default: all cores)\n"
           "      --point-light x,y,z,r,g,b   add a point light of intensity (r,g,b) W/sr;\n"
           "                          repeatable\n"
           "      --exposure EV       PNG exposure in stops (default 0)\n"
           "\n"
           "Bidirectional and point-light methods (bdpt, ir, rigi):\n"
           "      --mis KIND          bdpt weights: balance, power (default), stratified, or\n"
           "                          light (light tracing alone: every path through t = 1)\n"
           "      --threshold t       stratification threshold on G (default: the scene's\n"
           "                          diagonal d gives t = 1 / (0.15 d)^2); printed when used\n"
           "      --light-paths K     K light paths per pass shared by all pixels, or\n"
           "                          'sample': an independent one per pixel sample\n"
           "                          (bdpt default: sample; ir/rigi default 256 paths\n"
           "                          in 4 x 4 interleaved sets)\n"
           "      --interleave N      N x N interleaved sets of the K paths (default 1)\n"
           "      --clamp c           ir: clamp G at c (default: 1 / (0.05 d)^2)\n"
           "      --strata KIND       rigi: geometry (threshold G, default) or distance\n"
           "      --aov NAME          rigi: extra EXR layers: pathlength (average eye path\n"
           "                          length, Fig. 4) or strata (the contribution of each\n"
           "                          eye path length as layers strata1..strata8, Fig. 5);\n"
           "                          splat: bandwidth (the kernel-weighted mean bandwidth of\n"
           "                          the photon rays of depth 2, 3 and any, as R, G, B) or,\n"
           "                          with --cache, records (R: 1 at the records, G: records\n"
           "                          a pixel gathered from, B: the irradiance gradient's\n"
           "                          magnitude)\n"
           "      --shadow-rays KIND  rigi/ir/gkde: bundle (one Embree ray stream per point\n"
           "                          light and tile, or per footprint; default) or single;\n"
           "                          pm: a number (below)\n"
           "  -q, --quiet             no warnings, no progress bar\n"
           "\n");
    cdl_pm_args_help();
    cdl_gkde_args_help();
    cdl_splat_args_help();
    printf("Integrators:\n");
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); *it; it++)
        printf("  %-8s %s\n", (*it)->name, (*it)->summary);
    printf("\nThe summary line gives wall time, samples per pixel and Mrays/s (all rays\n"
           "traced divided by the render time). Ctrl-C writes the image so far (exit 130).\n");
}

/* Output files are checked before rendering so a typo costs no render. */
static int check_output(const char *path, cdl_error *err)
{
    if (!cdl_image_has_ext(path, ".exr") && !cdl_image_has_ext(path, ".png") &&
        !cdl_image_has_ext(path, ".pfm"))
        return cdl_error_set(err, CDL_ERR_USAGE, "-o", 0,
                             "unknown image format '%s' (use .exr, .png or .pfm)", path);
    char dir[1024];
    const char *slash = strrchr(path, '/');
    if (!slash)
        return 0;
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    if (!dir[0])
        return 0;
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "output directory '%s' does not exist", dir);
    return 0;
}

int cdl_render_parse(int argc, char **argv, render_args *a, cdl_error *err)
{
    memset(a, 0, sizeof *a);
    cdl_options defaults;
    cdl_options_default(&defaults);
    a->pm = defaults.pm;
    a->gkde = defaults.gkde;
    a->splat = defaults.splat;
    a->integrator = "path";
    a->spp = 0;
    a->width = 512;
    a->height = 512;
    a->fov = 40.0;
    a->maxdepth = 64;
    a->seed = 1;
    a->mis = CDL_MIS_POWER;
    a->interleave = 1;
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            render_help();
            return -1;
        }
        if (!strcmp(o, "-q") || !strcmp(o, "--quiet")) {
            cdl_log_quiet = 1;
            continue;
        }
        if (o[0] != '-' || !o[1]) {
            if (a->scene)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "only one scene file may be given");
            a->scene = o;
            continue;
        }
        if (cdl_splat_arg_kind(o)) {
            if (i + 1 >= argc)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expects a value");
            int src = cdl_splat_arg(o, argv[++i], &a->splat, err);
            if (src)
                return src;
            continue;
        }
        if (!strcmp(o, "--photons"))
            a->photons_given = 1;
        if (!strcmp(o, "--direct"))
            a->direct_given = 1;
        if (!strcmp(o, "--gather"))
            a->gather_given = 1;
        if (cdl_gkde_arg_kind(o)) {
            if (i + 1 >= argc)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expects a value");
            int grc = cdl_gkde_arg(o, argv[++i], &a->gkde, err);
            if (grc)
                return grc;
            continue;
        }
        int pk = cdl_pm_arg_kind(o);
        if (pk == 2) {
            cdl_pm_arg(o, NULL, &a->pm, err);
            continue;
        }
        if (pk == 1) {
            if (i + 1 >= argc)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expects a value");
            int prc = cdl_pm_arg(o, argv[++i], &a->pm, err);
            if (prc)
                return prc;
            continue;
        }
        /* Every other option takes the next argument as its value, even
         * one that starts with '-' (so --spp -5 is an error about --spp). */
        static const char *valued[] = {"-i", "--integrator", "-o", "--output", "--spp", "--time",
                                       "--res", "--lookat", "--fov", "--maxdepth", "--seed",
                                       "--threads", "--point-light", "--exposure", "--sampler",
                                       "--mis", "--light-paths", "--interleave", "--threshold",
                                       "--clamp", "--strata", "--shadow-rays", "--aov"};
        int known = 0;
        for (size_t k = 0; k < sizeof valued / sizeof *valued; k++)
            known |= !strcmp(o, valued[k]);
        if (!known)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "unknown option (see candela render --help)");
        if (i + 1 >= argc)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expects a value");
        const char *v = argv[++i];
        long l;
        double d;
        int rc = 0;
        if (!strcmp(o, "-i") || !strcmp(o, "--integrator")) {
            if (!cdl_integrator_find(v))
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "unknown integrator '%s' (see --help)", v);
            a->integrator = v;
            a->has_integrator = 1;
        } else if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (a->nout == MAX_OUT)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "at most %d outputs", MAX_OUT);
            rc = check_output(v, err);
            a->out[a->nout++] = v;
        } else if (!strcmp(o, "--spp")) {
            rc = cdl_arg_int(o, v, 1, 1000000, &a->spp, err);
        } else if (!strcmp(o, "--time")) {
            rc = cdl_arg_float(o, v, 1e-3, 1e7, &a->time, err);
        } else if (!strcmp(o, "--res")) {
            rc = cdl_arg_res(o, v, 16384, &a->width, &a->height, err);
            a->has_res = 1;
        } else if (!strcmp(o, "--lookat")) {
            rc = cdl_arg_floats(o, v, 9, a->lookat, err);
            a->has_lookat = 1;
        } else if (!strcmp(o, "--fov")) {
            rc = cdl_arg_float(o, v, 1e-3, 179.999, &a->fov, err);
            a->has_fov = 1;
        } else if (!strcmp(o, "--maxdepth")) {
            rc = cdl_arg_int(o, v, 0, 1024, &a->maxdepth, err);
            a->has_maxdepth = 1;
        } else if (!strcmp(o, "--seed")) {
            rc = cdl_arg_int(o, v, 0, 2147483647L, &l, err);
            a->seed = (unsigned long long)l;
        } else if (!strcmp(o, "--threads")) {
            rc = cdl_arg_int(o, v, 1, 1024, &a->threads, err);
        } else if (!strcmp(o, "--point-light")) {
            if (a->nlights == MAX_POINT_LIGHTS)
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "at most %d point lights", MAX_POINT_LIGHTS);
            float *pl = a->lights[a->nlights++];
            rc = cdl_arg_floats(o, v, 6, pl, err);
            if (!rc && (pl[3] < 0.0f || pl[4] < 0.0f || pl[5] < 0.0f))
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "intensity must not be negative, got '%s'", v);
        } else if (!strcmp(o, "--sampler")) {
            if (!strcmp(v, "sobol"))
                a->sampler = CDL_SAMPLER_SOBOL;
            else if (!strcmp(v, "independent"))
                a->sampler = CDL_SAMPLER_INDEPENDENT;
            else
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected sobol or independent, got '%s'", v);
        } else if (!strcmp(o, "--mis")) {
            if (!strcmp(v, "balance"))
                a->mis = CDL_MIS_BALANCE;
            else if (!strcmp(v, "power"))
                a->mis = CDL_MIS_POWER;
            else if (!strcmp(v, "stratified"))
                a->mis = CDL_MIS_STRATIFIED;
            else if (!strcmp(v, "light"))
                a->mis = CDL_MIS_LIGHT_TRACING;
            else
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                     "expected balance, power, stratified or light, got '%s'", v);
        } else if (!strcmp(o, "--light-paths")) {
            /* "sample": an independent light path per pixel sample (-1) */
            if (!strcmp(v, "sample"))
                a->light_paths = -1;
            else
                rc = cdl_arg_int(o, v, 1, 100000000L, &a->light_paths, err);
        } else if (!strcmp(o, "--interleave")) {
            rc = cdl_arg_int(o, v, 1, 64, &a->interleave, err);
        } else if (!strcmp(o, "--threshold")) {
            rc = cdl_arg_float(o, v, 1e-12, 1e12, &a->threshold, err);
        } else if (!strcmp(o, "--clamp")) {
            rc = cdl_arg_float(o, v, 1e-12, 1e12, &a->clamp, err);
        } else if (!strcmp(o, "--strata")) {
            if (!strcmp(v, "geometry"))
                a->strata_distance = 0;
            else if (!strcmp(v, "distance"))
                a->strata_distance = 1;
            else
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected geometry or distance, got '%s'", v);
        } else if (!strcmp(o, "--aov")) {
            if (!strcmp(v, "pathlength"))
                a->aov_pathlength = 1;
            else if (!strcmp(v, "strata"))
                a->aov_strata = 1;
            else if (!strcmp(v, "bandwidth"))
                a->aov_bandwidth = 1;
            else if (!strcmp(v, "records"))
                a->aov_records = 1;
            else
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                     "expected pathlength, strata, bandwidth or records, got '%s'", v);
        } else if (!strcmp(o, "--shadow-rays")) {
            if (!strcmp(v, "bundle"))
                a->single_shadow_rays = 0;
            else if (!strcmp(v, "single"))
                a->single_shadow_rays = 1;
            else if (v[0] >= '0' && v[0] <= '9') { /* pm: rays per shading point */
                rc = cdl_arg_int(o, v, 1, 4096, &l, err);
                a->pm.shadow_rays = (uint32_t)l;
            } else
                return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected bundle, single or a ray count, got '%s'", v);
        } else if (!strcmp(o, "--exposure")) {
            rc = cdl_arg_float(o, v, -100.0, 100.0, &d, err);
            a->exposure = d;
        }
        if (rc)
            return rc;
    }
    if (!a->scene)
        return cdl_error_set(err, CDL_ERR_USAGE, "render", 0, "no scene file given (see candela render --help)");
    if (a->interleave > 1 && a->light_paths <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, "--interleave", 0, "needs --light-paths K (the paths to interleave)");
    if (a->light_paths > 0 && a->light_paths < a->interleave * a->interleave)
        return cdl_error_set(err, CDL_ERR_USAGE, "--light-paths", 0,
                             "%ld paths cannot fill %ld x %ld interleaved sets", a->light_paths,
                             a->interleave, a->interleave);
    if (a->aov_pathlength || a->aov_strata || a->aov_bandwidth || a->aov_records) {
        int exr = 0;
        for (int i = 0; i < a->nout; i++)
            exr |= cdl_image_has_ext(a->out[i], ".exr");
        if (!exr)
            return cdl_error_set(err, CDL_ERR_USAGE, "--aov", 0, "output layers need an .exr output (-o FILE.exr)");
    }
    if (a->spp && a->time > 0.0)
        return cdl_error_set(err, CDL_ERR_USAGE, "--time", 0, "give either --spp or --time, not both");
    return cdl_pm_args_check(&a->pm, err);
}

/* Scene-file settings fill in what the command line left open. */
static void apply_settings(render_args *a, const cdl_scene_settings *set)
{
    if (!a->has_integrator && set->integrator[0] && cdl_integrator_find(set->integrator))
        a->integrator = set->integrator;
    if (!a->has_res && set->width > 0 && set->height > 0) {
        a->width = set->width;
        a->height = set->height;
    }
    if (!a->has_maxdepth && set->maxdepth >= 0)
        a->maxdepth = set->maxdepth > 1024 ? 1024 : set->maxdepth;
    if (!a->spp && a->time <= 0.0)
        a->spp = set->spp > 0 ? set->spp : 64;
}

static void on_sigint(int sig)
{
    (void)sig;
    cdl_cancel = 1;
    signal(SIGINT, SIG_DFL); /* a second Ctrl-C ends at once */
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

/* Kollig & Keller's Figure 4 colours: green at the smallest value of the
 * layer, red at the largest (written linear, so the PNG shows them). */
static void false_colour(cdl_image *img)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    float lo = FLT_MAX, hi = -FLT_MAX;
    for (size_t i = 0; i < n; i++) {
        float v = img->rgb[3 * i];
        if (v > 0.0f) {
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
        }
    }
    for (size_t i = 0; i < n; i++) {
        float v = img->rgb[3 * i];
        float t = v > 0.0f && hi > lo ? (v - lo) / (hi - lo) : 0.0f;
        img->rgb[3 * i] = v > 0.0f ? t : 0.0f;
        img->rgb[3 * i + 1] = v > 0.0f ? 1.0f - t : 0.0f;
        img->rgb[3 * i + 2] = 0.0f;
    }
}

static void default_output(const char *scene, const cdl_scene_settings *set, char *buf, size_t n)
{
    if (set->filename[0] && (cdl_image_has_ext(set->filename, ".exr") ||
                             cdl_image_has_ext(set->filename, ".png") ||
                             cdl_image_has_ext(set->filename, ".pfm"))) {
        const char *b = strrchr(set->filename, '/');
        snprintf(buf, n, "%s", b ? b + 1 : set->filename);
        return;
    }
    const char *base = strrchr(scene, '/');
    base = base ? base + 1 : scene;
    const char *dot = strrchr(base, '.');
    int len = dot ? (int)(dot - base) : (int)strlen(base);
    snprintf(buf, n, "%.*s.exr", len, base);
}

int cdl_render_setup(render_args *a, cdl_scene *scene, cdl_scene_settings *set, cdl_options *opt,
                     char *defout, size_t ndefout, cdl_error *err)
{
    if (a->threads > 0)
        omp_set_num_threads((int)a->threads);
    int rc = cdl_scene_init(scene, a->scene, err);
    if (!rc)
        rc = cdl_scene_load(scene, a->scene, set, err);
    for (int i = 0; !rc && i < a->nlights; i++)
        rc = cdl_scene_add_point_light(scene, cdl_v3(a->lights[i][0], a->lights[i][1], a->lights[i][2]),
                                       cdl_v3(a->lights[i][3], a->lights[i][4], a->lights[i][5]), err);
    if (!rc)
        rc = cdl_scene_commit(scene, err);
    if (!rc) {
        apply_settings(a, set);
        if (a->nout == 0) {
            default_output(a->scene, set, defout, ndefout);
            a->out[a->nout++] = defout;
        }
    }
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
    if (!rc && a->has_lookat)
        rc = cdl_camera_init(&opt->camera, cdl_v3(a->lookat[0], a->lookat[1], a->lookat[2]),
                             cdl_v3(a->lookat[3], a->lookat[4], a->lookat[5]),
                             cdl_v3(a->lookat[6], a->lookat[7], a->lookat[8]), (float)a->fov, a->width,
                             a->height, err);
    else if (!rc && set->has_camera)
        rc = cdl_camera_init_frame(&opt->camera, set->eye, set->right, set->up, set->fwd,
                                   a->has_fov ? (float)a->fov : set->fov, a->width, a->height, err);
    else if (!rc)
        rc = frame_scene(scene, a->fov, a->width, a->height, &opt->camera, err);
    return rc;
}

int cdl_cmd_render(int argc, char **argv)
{
    render_args a;
    cdl_error err;
    int rc = cdl_render_parse(argc, argv, &a, &err);
    if (rc < 0)
        return 0;
    if (rc)
        return cdl_report(&err);

    double t_load = cdl_time_now();
    cdl_scene scene;
    cdl_scene_settings set;
    cdl_options opt;
    char defout[1024];
    cdl_integrator integ = {0};
    cdl_film film = {0};
    cdl_image img = {0};
    rc = cdl_render_setup(&a, &scene, &set, &opt, defout, sizeof defout, &err);
    t_load = cdl_time_now() - t_load;
    /* a method's preprocessing (photons, importons) is part of its render time */
    double t0 = cdl_time_now();
    if (!rc)
        rc = cdl_integrator_create(a.integrator, &integ, &err);
    if (!rc)
        rc = integ.vt->prepare(integ.self, &scene, &opt, &err);
    if (!rc)
        rc = cdl_film_init(&film, a.width, a.height, &err);
    if (!rc && a.aov_pathlength && cdl_film_add_aov(&film, "pathlength", 1, &err) < 0)
        rc = err.code;
    if (!rc && a.aov_records && cdl_film_add_aov(&film, "records", 3, &err) < 0)
        rc = err.code;
    if (!rc && a.aov_bandwidth && cdl_film_add_aov(&film, "bandwidth", 3, &err) < 0)
        rc = err.code;
    for (int k = 1; !rc && a.aov_strata && k <= CDL_STRATA; k++) {
        char nm[32];
        snprintf(nm, sizeof nm, "strata%d", k);
        if (cdl_film_add_aov(&film, nm, 3, &err) < 0)
            rc = err.code;
    }
    if (rc) {
        int status = cdl_report(&err);
        cdl_integrator_destroy(&integ);
        cdl_scene_free(&scene);
        return status;
    }

    signal(SIGINT, on_sigint);
    cdl_progress prog;
    cdl_progress_begin(&prog);
    uint32_t pass = 0;
    int pass_failed = 0;
    char label[64];
    double t_loop = cdl_time_now();
    for (;;) {
        double now = cdl_time_now(), el = now - t0;
        if (a.spp ? pass >= (uint32_t)a.spp : (pass > 0 && el + (now - t_loop) / pass > a.time))
            break;
        if (cdl_cancel)
            break;
        if (integ.vt->render_pass(integ.self, &film, pass, &err)) {
            cdl_progress_end(&prog);
            pass_failed = cdl_report(&err); /* the passes done so far are still written */
            break;
        }
        if (cdl_cancel)
            break; /* the interrupted pass left some pixels with one more sample */
        pass++;
        snprintf(label, sizeof label, "%u spp", pass);
        el = cdl_time_now() - t0;
        cdl_progress_update(&prog, a.spp ? (double)pass / a.spp : el / a.time, label);
    }
    double t_render = cdl_time_now() - t0;
    cdl_progress_end(&prog);
    signal(SIGINT, SIG_DFL);

    char s_spp[32], s_seed[32], s_time[32], cmdline[4096] = "candela";
    snprintf(s_spp, sizeof s_spp, "%u", pass);
    snprintf(s_seed, sizeof s_seed, "%llu", a.seed);
    snprintf(s_time, sizeof s_time, "%.3f", t_render);
    for (int i = 0; i < argc; i++) {
        size_t len = strlen(cmdline);
        snprintf(cmdline + len, sizeof cmdline - len, " %s", argv[i]);
    }
    cdl_kv meta[] = {{"integrator", a.integrator}, {"spp", s_spp}, {"seed", s_seed},
                     {"renderTime", s_time},       {"commandLine", cmdline}};
    if (pass_failed && pass == 0) { /* nothing rendered: no image to write */
        cdl_film_free(&film);
        cdl_integrator_destroy(&integ);
        cdl_scene_free(&scene);
        return pass_failed;
    }
    rc = cdl_film_resolve(&film, &img, &err);
    cdl_image aov_img[CDL_MAX_AOVS];
    cdl_layer layers[CDL_MAX_AOVS];
    int nl = 0;
    for (int i = 0; !rc && i < film.naovs; i++) {
        memset(&aov_img[i], 0, sizeof aov_img[i]);
        rc = cdl_film_resolve_aov(&film, i, &aov_img[i], &err);
        layers[i] = (cdl_layer){film.aovs[i].name, &aov_img[i], film.aovs[i].channels == 1};
        nl = i + 1;
    }
    for (int i = 0; !rc && i < nl; i++) {
        /* statistics of one-channel layers (e.g. the eye path length),
         * before the PNG false colours overwrite them */
        if (!layers[i].grey)
            continue;
        double sum = 0.0, mx = 0.0;
        size_t n = (size_t)img.width * (size_t)img.height;
        for (size_t k = 0; k < n; k++) {
            sum += aov_img[i].rgb[3 * k];
            mx = aov_img[i].rgb[3 * k] > mx ? aov_img[i].rgb[3 * k] : mx;
        }
        printf("%s: mean %.4f, max %.4f per pixel\n", layers[i].name, sum / (double)n, mx);
    }
    for (int i = 0; !rc && i < a.nout; i++) {
        rc = nl && cdl_image_has_ext(a.out[i], ".exr")
                 ? cdl_image_write_layers(a.out[i], &img, layers, nl, meta, 5, &err)
                 : cdl_image_write(a.out[i], &img, meta, 5, (float)a.exposure, &err);
        /* a PNG output also gets one PNG per layer: OUT.png -> OUT.NAME.png */
        for (int l = 0; !rc && l < nl && cdl_image_has_ext(a.out[i], ".png"); l++) {
            char path[1100];
            snprintf(path, sizeof path, "%.*s.%s.png", (int)(strlen(a.out[i]) - 4), a.out[i], layers[l].name);
            cdl_image view = aov_img[l];
            if (layers[l].grey) { /* false colours on a copy: other outputs keep the values */
                rc = cdl_image_alloc(&view, img.width, img.height, &err);
                if (rc)
                    break;
                memcpy(view.rgb, aov_img[l].rgb, sizeof(float) * 3 * (size_t)img.width * (size_t)img.height);
                false_colour(&view);
            }
            rc = cdl_image_write(path, &view, meta, 5, layers[l].grey ? 0.0f : (float)a.exposure, &err);
            if (layers[l].grey)
                cdl_image_free(&view);
        }
    }
    for (int i = 0; i < nl; i++)
        cdl_image_free(&aov_img[i]);
    int status = rc ? cdl_report(&err) : 0;
    if (!rc) {
        double mrays = t_render > 0.0 ? (double)film.rays / t_render * 1e-6 : 0.0;
        printf("%s: %s %dx%d, %u spp in %.2f s (load %.2f s), %.2f Mrays/s, %d threads, "
               "%llu non-finite samples%s -> %s%s\n",
               a.scene, a.integrator, a.width, a.height, pass, t_render, t_load, mrays,
               omp_get_max_threads(), (unsigned long long)film.nonfinite,
               cdl_cancel ? " (interrupted)" : "", a.out[0], a.nout > 1 ? " ..." : "");
    }
    if (!rc && integ.vt->report)
        integ.vt->report(integ.self);
    if (film.nonfinite && !cdl_log_quiet)
        cdl_warn(a.scene, 0, "%llu samples were NaN or infinite and counted as black",
                 (unsigned long long)film.nonfinite);
    cdl_image_free(&img);
    cdl_film_free(&film);
    cdl_integrator_destroy(&integ);
    cdl_scene_free(&scene);
    if (!status && pass_failed)
        status = pass_failed;
    if (!status && cdl_cancel)
        return 130;
    return status;
}
