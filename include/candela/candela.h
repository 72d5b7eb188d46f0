/* candela: physically based global illumination, its public C API.
 *
 * This header is the whole interface of libcandela: the `candela` command,
 * the Python package and the benchmarks use nothing else. It compiles as
 * C11 and C++17.
 *
 * Objects are opaque handles made by a create/open function and given back
 * with the matching release function; whoever created a handle releases it.
 * Functions that can fail return a status (CDL_OK = 0 or a CDL_ERR_* code)
 * and fill the caller's cdl_error (which may be NULL) with the file, the line
 * and the problem. The library never exits, aborts or prints an error; its
 * only output is warnings about input it uses anyway, sent to the message
 * callback of the settings in use (stderr by default).
 *
 * There is no process-wide state: scenes, settings and renderers are
 * independent, and any number of renders may run in one process at once
 * (each on its own thread; one render uses OpenMP threads of its own). A
 * scene may be shared by renderers on several threads once opened; a
 * renderer or settings object is used by one thread at a time, except for
 * cdl_renderer_cancel, which any thread or a signal handler may call.
 *
 * A render:
 *     cdl_settings *s = cdl_settings_create();
 *     cdl_settings_set(s, "integrator", "bdpt", &err);
 *     cdl_settings_set(s, "spp", "16", &err);
 *     cdl_scene_open("box.obj", s, &scene, &err);
 *     cdl_renderer_create(scene, s, &r, &err);
 *     cdl_renderer_render(r, NULL, NULL, &err);
 *     cdl_renderer_write(r, "box.exr", NULL, &err);
 *     cdl_renderer_release(r); cdl_scene_release(scene); cdl_settings_release(s);
 */
#ifndef CANDELA_CANDELA_H
#define CANDELA_CANDELA_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define CDL_API __attribute__((visibility("default")))
#else
#define CDL_API
#endif

#define CDL_VERSION_MAJOR 0
#define CDL_VERSION_MINOR 2
#define CDL_VERSION_PATCH 0

/* "0.2.0": the version of the library actually loaded. */
CDL_API const char *cdl_version(void);

/* ---- status and errors ------------------------------------------------ */

enum {
    CDL_OK = 0,
    CDL_ERR_INPUT = 1, /* a bad scene file, image or value read from a file */
    CDL_ERR_USAGE = 2, /* a bad option, value or call */
    CDL_ERR_SYSTEM = 3 /* out of memory, I/O failure, device failure */
};

typedef struct cdl_error {
    int code;        /* one of the codes above */
    int line;        /* 1-based line in file, 0 when there is none */
    char file[1024]; /* the file (or option) the problem is in, "" if none */
    char msg[512];
} cdl_error;

/* "file:line: msg", "file: msg" or "msg" into buf (n bytes, terminated). */
CDL_API void cdl_error_format(const cdl_error *err, char *buf, size_t n);

/* Warnings (input used anyway): file may be "" and line 0. */
typedef void (*cdl_message_fn)(void *user, const char *file, int line, const char *msg);

/* ---- settings: every option of `candela render`, by name -------------- */

/* Parameters are set by name and string value. Names are the library's
 * ("spp", "res", "lookat", "photons", "max_radius"; "-" may stand for "_"
 * and leading dashes are dropped, so the command line's "--max-radius" and
 * "-C" work too). Values are written as on the command line ("512x256",
 * "0,1,4,0,1,0,0,1,0", "2/3"); switches (e.g. "importance") take "on"/"off"
 * (or "1"/"0", "true"/"false", or NULL for on). Each value is checked when
 * set; a parameter the chosen method does not read is a usage error (when
 * set once the integrator is, else from cdl_settings_check or when the
 * renderer is created). Repeatable ones ("point_light", "aov") add one
 * entry per call. Unset parameters take their default, or what the scene
 * file says (camera, resolution, spp, max depth, integrator).
 * cdl_option_* below lists them all with their types and ranges. */
typedef struct cdl_settings cdl_settings;

CDL_API cdl_settings *cdl_settings_create(void); /* NULL when out of memory */
CDL_API void cdl_settings_release(cdl_settings *s);
CDL_API int cdl_settings_set(cdl_settings *s, const char *name, const char *value, cdl_error *err);
/* Checks what single values cannot (e.g. --interleave without --light-paths). */
CDL_API int cdl_settings_check(const cdl_settings *s, cdl_error *err);
/* Warnings of the scene loads and renders that use s go to fn (NULL: to
 * stderr as "candela: warning: file:line: msg"); "quiet" "on" drops them. */
CDL_API void cdl_settings_set_message_fn(cdl_settings *s, cdl_message_fn fn, void *user);

typedef struct cdl_option_info {
    const char *name;          /* "max_radius" (the command line's --max-radius) */
    const char *value;         /* what it takes: "N", "WxH", "KIND", "" for a bare switch */
    const char *integrators;   /* the methods that read it: "pm", "bdpt,ir,rigi", ...; "" for every method */
    const char *default_value; /* as text; "" when the method derives it (the help says how) */
    const char *help;          /* one line, unwrapped */
    const char *section;       /* the --help section it is listed in */
    const char *type;          /* "int", "float", "switch", "choice", "floats", "res" or "name" */
    double min, max;           /* int, float, floats: the range (each value's) */
    int min_open, max_open;    /* the range excludes min or max */
    const char *choices;       /* choice: "box|cone|epanechnikov"; int: a word also taken ("sample"); else "" */
    const char *unit;          /* "s", "deg", "MiB" or "" */
    int repeatable;            /* each setting adds one (point_light, aov) */
} cdl_option_info;

CDL_API int cdl_option_count(void);
/* NULL unless 0 <= i < cdl_option_count(). The common parameters first,
 * then each method's tables in turn; a row several methods read (photons:
 * pm and splat) is listed once, a name two methods define apart (gather:
 * pm's and splat's) once per definition. */
CDL_API const cdl_option_info *cdl_option_get(int i);

CDL_API int cdl_integrator_count(void);
CDL_API const char *cdl_integrator_name(int i);    /* "path", "bdpt", ...; NULL out of range */
CDL_API const char *cdl_integrator_summary(int i); /* one line */

/* ---- scenes ----------------------------------------------------------- */

typedef struct cdl_scene cdl_scene;

/* Loads a Wavefront OBJ (+ MTL) or pbrt-v3/v4 file. settings (may be NULL)
 * adds its "point-light" entries and routes the warnings. */
CDL_API int cdl_scene_open(const char *path, const cdl_settings *settings, cdl_scene **out, cdl_error *err);
CDL_API void cdl_scene_release(cdl_scene *scene);

typedef struct cdl_scene_info {
    uint32_t triangles, spheres, lights, materials;
    float bounds_min[3], bounds_max[3];
    int has_camera;         /* the file sets a camera */
    int width, height, spp; /* the file's film and sampler; 0 when not given */
    const char *output;     /* the file's output image name, "" when not given */
} cdl_scene_info;
CDL_API void cdl_scene_get_info(const cdl_scene *scene, cdl_scene_info *info);

/* ---- images ----------------------------------------------------------- */

/* Linear RGB, 3 floats per pixel, row-major, top row first. */
typedef struct cdl_image cdl_image;

CDL_API int cdl_image_create(int width, int height, cdl_image **out, cdl_error *err); /* zeroed */
/* EXR (half/float/uint), PFM or PNG (sRGB decoded), by the file's magic bytes. */
CDL_API int cdl_image_load(const char *path, cdl_image **out, cdl_error *err);
CDL_API void cdl_image_release(cdl_image *img);
CDL_API int cdl_image_width(const cdl_image *img);
CDL_API int cdl_image_height(const cdl_image *img);
CDL_API float *cdl_image_pixels(cdl_image *img); /* 3 * width * height floats */
/* .exr (32-bit float), .png (8-bit sRGB of rgb * 2^exposure) or .pfm, by the
 * extension; written to a temporary file and renamed over path. */
CDL_API int cdl_image_save(const cdl_image *img, const char *path, float exposure, cdl_error *err);
/* Pixels [x0, x1) x [y0, y1) as a new image. */
CDL_API int cdl_image_crop(const cdl_image *img, int x0, int y0, int x1, int y1, cdl_image **out,
                           cdl_error *err);

/* `candela diff` metrics of test against ref (same size). */
typedef struct cdl_diff {
    double rmse;               /* sqrt of the mean squared difference, all channels */
    double relmse;             /* mean of (t - r)^2 / (r^2 + 0.01) */
    double mae;                /* mean absolute difference */
    double mean_ratio;         /* mean(test) / mean(ref) */
    double relmse_trimmed;     /* relmse without the largest 0.1 % of per-pixel terms */
    double block_median_ratio; /* median over 16x16 blocks of the ratio of block means */
    double block_dev32;        /* RMS over 32x32 blocks of (block mean ratio - 1): bias */
    double mean_test, mean_ref;
} cdl_diff;
CDL_API int cdl_image_diff(const cdl_image *test, const cdl_image *ref, cdl_diff *out, cdl_error *err);
/* False-colour map of the per-pixel relative error (log scale, 1e-4 blue to 1 red). */
CDL_API int cdl_image_diff_heatmap(const cdl_image *test, const cdl_image *ref, cdl_image **out,
                                   cdl_error *err);
/* FLIP (Andersson et al. 2020) of test against ref: *mean the mean of the
 * per-pixel error in [0, 1]. hdr = 0: LDR-FLIP of the linear RGB pixels
 * clamped to [0, 1] (a PNG as loaded); hdr = 1: HDR-FLIP (Andersson et al.
 * 2021), the largest LDR-FLIP over ACES-tone-mapped exposures chosen from
 * ref's median and largest luminance. ppd: pixels per degree of visual
 * angle, in [1, 1000]; <= 0 means 67.02 (0.7 m from a 0.7 m wide 3840-pixel
 * monitor). map may be NULL, else it receives the per-pixel error coloured
 * with magma (black 0 to pale yellow 1), stored linear so that
 * cdl_image_save(.png, exposure 0) writes the map's colours. */
CDL_API int cdl_image_flip(const cdl_image *test, const cdl_image *ref, int hdr, double ppd, double *mean,
                           cdl_image **map, cdl_error *err);

/* ---- renders ---------------------------------------------------------- */

typedef struct cdl_renderer cdl_renderer;

/* Sets up a render of scene with settings (may be NULL: all defaults) and
 * checks them: unknown combinations fail here, before any work. The
 * settings are copied; the scene must outlive the renderer. */
CDL_API int cdl_renderer_create(cdl_scene *scene, const cdl_settings *settings, cdl_renderer **out,
                                cdl_error *err);
CDL_API void cdl_renderer_release(cdl_renderer *r);

typedef struct cdl_progress {
    uint32_t passes;  /* passes done (samples per pixel) */
    double seconds;   /* since the render began (the method's preprocessing included) */
    double fraction;  /* of the budget, in [0, 1] */
} cdl_progress;
/* Called after each pass; a non-zero return stops the render there. */
typedef int (*cdl_progress_fn)(void *user, const cdl_progress *p);

/* Renders passes until the settings' budget ("spp" passes in all, or "time"
 * seconds; else the scene file's spp, else 64) is met or the render is
 * cancelled. The first call runs the method's preprocessing (photon maps,
 * importons), which counts as render time. A cancelled render keeps its
 * passes: its image is that of the passes done. progress may be NULL. */
CDL_API int cdl_renderer_render(cdl_renderer *r, cdl_progress_fn progress, void *user, cdl_error *err);
/* Renders n more passes (whatever the budget), for callers that read the
 * image between them. */
CDL_API int cdl_renderer_render_passes(cdl_renderer *r, uint32_t n, cdl_progress_fn progress, void *user,
                                       cdl_error *err);
/* Renders the pass with this index (0-based; a pass is deterministic given
 * the seed and its index) and counts it as one more pass. Distributed
 * drivers render disjoint sets of a render's passes in several processes
 * and add their accumulators (below). */
CDL_API int cdl_renderer_render_pass(cdl_renderer *r, uint32_t index, cdl_error *err);
/* The render's accumulators (passes, film sums, sample counts, light-tracing
 * splats, ray counters, AOV sums) as n = cdl_renderer_accum_size doubles:
 * the element-wise sum of the vectors of renders (same scene and settings)
 * of disjoint sets of passes, set into one of them, makes it the render of
 * all those passes. _set checks the counts it is given. */
CDL_API size_t cdl_renderer_accum_size(const cdl_renderer *r);
CDL_API int cdl_renderer_accum_get(const cdl_renderer *r, double *out, size_t n, cdl_error *err);
CDL_API int cdl_renderer_accum_set(cdl_renderer *r, const double *in, size_t n, cdl_error *err);
/* Methods whose passes adapt to earlier ones (gkde's visibility tallies)
 * fold what they learnt at pass indices 1, 2, 4, 8, ...: pass i uses what
 * the passes before the last fold at or below i learnt. A distributed
 * driver keeps every process equal to one process: before any process
 * renders a pass >= cdl_renderer_adapt_next (and, after its last pass,
 * for each fold below the job's passes), all sum their adapt_get vectors
 * and each calls adapt_fold with the sum. *n = 0: the method does not
 * adapt (then next is UINT32_MAX). adapt_size prepares the method. */
CDL_API int cdl_renderer_adapt_size(cdl_renderer *r, size_t *n, cdl_error *err);
CDL_API uint32_t cdl_renderer_adapt_next(const cdl_renderer *r);
CDL_API int cdl_renderer_adapt_get(const cdl_renderer *r, double *out, size_t n, cdl_error *err);
CDL_API int cdl_renderer_adapt_fold(cdl_renderer *r, const double *sum, size_t n, cdl_error *err);
/* Stops the render of r under way after the current pass (its tiles stop
 * early, so that pass does not count); a cancel while r is not rendering
 * has no effect. Safe from any thread and from a signal handler. */
CDL_API void cdl_renderer_cancel(cdl_renderer *r);
/* 1 if the last render of r ended by cancel (or a progress callback). */
CDL_API int cdl_renderer_cancelled(const cdl_renderer *r);

CDL_API uint32_t cdl_renderer_passes(const cdl_renderer *r);
/* The budget cdl_renderer_render works to: *spp > 0 passes in all, or
 * (*spp = 0) *seconds of render time. */
CDL_API void cdl_renderer_budget(const cdl_renderer *r, uint32_t *spp, double *seconds);
CDL_API int cdl_renderer_width(const cdl_renderer *r);
CDL_API int cdl_renderer_height(const cdl_renderer *r);
CDL_API const char *cdl_renderer_integrator(const cdl_renderer *r); /* the method in use */

/* The film averaged so far: layer NULL (or "") is the radiance, else an AOV
 * layer asked for with "aov" ("pathlength", "strata1".."strata8",
 * "bandwidth", "records"). A new image; the caller releases it. */
CDL_API int cdl_renderer_image(const cdl_renderer *r, const char *layer, cdl_image **out, cdl_error *err);
CDL_API int cdl_renderer_layer_count(const cdl_renderer *r);
CDL_API const char *cdl_renderer_layer_name(const cdl_renderer *r, int i);

/* Writes the image by extension with its metadata (integrator, spp, seed,
 * renderTime, and command_line when not NULL). EXR outputs hold the AOV
 * layers too; a PNG output gets one PNG per layer (OUT.NAME.png). The
 * "exposure" setting applies to PNG. */
CDL_API int cdl_renderer_write(const cdl_renderer *r, const char *path, const char *command_line,
                               cdl_error *err);

/* Statistics, by name: every method reports "passes", "seconds" (render
 * time), "rays" (all rays traced), "mrays_per_s", "nonfinite" (samples
 * dropped as NaN or infinite), "threads" and "peak_rss_mib" (the process's);
 * methods add their own (pm "photon_paths", "map_mib", "t_photons"; splat
 * "t_ray", "t_solve", "memory_mib", ...). i in [0, count). */
CDL_API int cdl_renderer_stat_count(const cdl_renderer *r);
CDL_API int cdl_renderer_stat(const cdl_renderer *r, int i, const char **name, double *value);
/* The value of the statistic called name, or nan when there is none. */
CDL_API double cdl_renderer_stat_value(const cdl_renderer *r, const char *name);
/* The method's report as text (lines ending in '\n', "" if it has none). */
CDL_API const char *cdl_renderer_report(const cdl_renderer *r);

/* ---- photon plots (`candela photons`) --------------------------------- */

/* The photons (and, with "importance", the importons) pm's first pass
 * stores, seen from above on a plan of size pixels (Keller & Wald 2000,
 * Figures 1, 2 and 4). importons is left NULL without "importance".
 * summary (n bytes, may be NULL) receives one line of counts. */
CDL_API int cdl_photon_plot(cdl_scene *scene, const cdl_settings *settings, int size, cdl_image **photons,
                            cdl_image **importons, char *summary, size_t n, cdl_error *err);

#ifdef __cplusplus
}
#endif

#endif
