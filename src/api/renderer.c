/* The public renderer: one method on one scene with its film, rendered in
 * progressive passes until a budget or a cancel. */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "api/resolve.h"
#include "film/film.h"
#include "film/image.h"

struct cdl_renderer {
    cdl_scene *scene;
    cdl_settings set; /* resolved against the scene */
    cdl_options opt;
    cdl_integrator integ;
    cdl_film film;
    int prepared, cancelled, threads;
    uint32_t passes;
    int64_t index;  /* the pass cdl_renderer_render_pass renders, or -1: the next one */
    double seconds; /* render time so far, the method's preprocessing included */
    atomic_int cancel;
    cdl_stats stats;
};

void cdl_renderer_release(cdl_renderer *r)
{
    if (!r)
        return;
    cdl_film_free(&r->film);
    cdl_integrator_destroy(&r->integ);
    free(r);
}

static int add_aovs(cdl_renderer *r, cdl_error *err)
{
    uint32_t aov = r->opt.aov;
    if ((aov & CDL_AOV_PATHLENGTH) && cdl_film_add_aov(&r->film, "pathlength", 1, err) < 0)
        return err ? err->code : CDL_ERR_USAGE;
    if ((aov & CDL_AOV_RECORDS) && cdl_film_add_aov(&r->film, "records", 3, err) < 0)
        return err ? err->code : CDL_ERR_USAGE;
    if ((aov & CDL_AOV_BANDWIDTH) && cdl_film_add_aov(&r->film, "bandwidth", 3, err) < 0)
        return err ? err->code : CDL_ERR_USAGE;
    if ((aov & CDL_AOV_MERGE) && cdl_film_add_aov(&r->film, "merge", 3, err) < 0)
        return err ? err->code : CDL_ERR_USAGE;
    if ((aov & CDL_AOV_MERGECOUNT) && cdl_film_add_aov(&r->film, "mergecount", 1, err) < 0)
        return err ? err->code : CDL_ERR_USAGE;
    for (int k = 1; (aov & CDL_AOV_STRATA) && k <= CDL_STRATA; k++) {
        char nm[32];
        snprintf(nm, sizeof nm, "strata%d", k);
        if (cdl_film_add_aov(&r->film, nm, 3, err) < 0)
            return err ? err->code : CDL_ERR_USAGE;
    }
    return 0;
}

int cdl_renderer_create(cdl_scene *scene, const cdl_settings *settings, cdl_renderer **out, cdl_error *err)
{
    if (!out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_create: no place for the renderer");
    *out = NULL;
    if (!scene)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_create: no scene");
    cdl_renderer *r = calloc(1, sizeof *r);
    cdl_settings *defaults = settings ? NULL : cdl_settings_create();
    if (!r || (!settings && !defaults)) {
        free(r);
        free(defaults);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    }
    const cdl_settings *in = settings ? settings : defaults;
    const cdl_log_sink *prev = cdl_log_push(&in->sink);
    r->scene = scene;
    r->index = -1;
    atomic_init(&r->cancel, 0);
    int rc = cdl_settings_resolve(in, scene, &r->set, &r->opt, err);
    cdl_settings_release(defaults);
    if (!rc)
        rc = cdl_integrator_create(r->set.c.integrator, &r->integ, err);
    if (!rc)
        rc = cdl_film_init(&r->film, r->set.c.res[0], r->set.c.res[1], err);
    if (!rc)
        rc = add_aovs(r, err);
    r->film.cancel = &r->cancel;
    cdl_log_pop(prev);
    if (rc) {
        cdl_renderer_release(r);
        return rc;
    }
    *out = r;
    return 0;
}

static void gather_stats(cdl_renderer *r)
{
    cdl_stats *s = &r->stats;
    memset(s, 0, sizeof *s);
    cdl_stats_add(s, "passes", r->passes);
    cdl_stats_add(s, "seconds", r->seconds);
    cdl_stats_add(s, "rays", (double)r->film.rays);
    cdl_stats_add(s, "mrays_per_s", r->seconds > 0.0 ? (double)r->film.rays / r->seconds * 1e-6 : 0.0);
    cdl_stats_add(s, "nonfinite", (double)r->film.nonfinite);
    cdl_stats_add(s, "threads", r->threads);
    struct rusage ru;
    if (!getrusage(RUSAGE_SELF, &ru))
        cdl_stats_add(s, "peak_rss_mib", (double)ru.ru_maxrss / 1024.0);
    for (int a = 0; a < r->film.naovs; a++) {
        /* one-channel layers (the eye path length): their mean and maximum */
        cdl_image img = {0};
        if (r->film.aovs[a].channels != 1 || cdl_film_resolve_aov(&r->film, a, &img, NULL))
            continue;
        size_t n = (size_t)img.width * (size_t)img.height;
        double sum = 0.0, mx = 0.0;
        for (size_t k = 0; k < n; k++) {
            sum += img.rgb[3 * k];
            mx = img.rgb[3 * k] > mx ? img.rgb[3 * k] : mx;
        }
        char nm[48];
        snprintf(nm, sizeof nm, "%.20s_mean", r->film.aovs[a].name);
        cdl_stats_add(s, nm, sum / (double)n);
        snprintf(nm, sizeof nm, "%.20s_max", r->film.aovs[a].name);
        cdl_stats_add(s, nm, mx);
        cdl_stats_printf(s, "%s: mean %.4f, max %.4f per pixel\n", r->film.aovs[a].name, sum / (double)n, mx);
        cdl_image_free(&img);
    }
    if (r->prepared && r->integ.vt->report)
        r->integ.vt->report(r->integ.self, s);
}

static int prepare(cdl_renderer *r, cdl_error *err)
{
    if (r->prepared)
        return 0;
    int rc = r->integ.vt->prepare(r->integ.self, r->scene, &r->opt, err);
    r->prepared = !rc;
    return rc;
}

/* Passes until target passes in all (target > 0) or until the render time
 * would exceed seconds, or a cancel. */
static int run(cdl_renderer *r, uint32_t target, double seconds, cdl_progress_fn fn, void *user, cdl_error *err)
{
    const cdl_log_sink *prev = cdl_log_push(&r->set.sink);
    int threads = omp_get_max_threads();
    if (r->set.c.threads > 0)
        omp_set_num_threads((int)r->set.c.threads);
    r->threads = omp_get_max_threads();
    atomic_store(&r->cancel, 0);
    r->cancelled = 0;
    double t0 = cdl_time_now() - r->seconds;
    int rc = prepare(r, err);
    uint32_t start = r->passes;
    double t_loop = cdl_time_now();
    while (!rc) {
        double now = cdl_time_now(), el = now - t0;
        if (target ? r->passes >= target
                   : (r->passes > start && el + (now - t_loop) / (r->passes - start) > seconds))
            break;
        if (cdl_cancelled(&r->cancel)) {
            r->cancelled = 1;
            break;
        }
        rc = r->integ.vt->render_pass(r->integ.self, &r->film, r->index >= 0 ? (uint32_t)r->index : r->passes, err);
        if (rc)
            break; /* the passes done so far stay in the film */
        if (cdl_cancelled(&r->cancel)) {
            r->cancelled = 1; /* the interrupted pass left some pixels with one more sample */
            break;
        }
        r->passes++;
        if (fn) {
            el = cdl_time_now() - t0;
            double frac = target ? (double)r->passes / target : el / seconds;
            cdl_progress p = {r->passes, el, frac < 1.0 ? frac : 1.0};
            if (fn(user, &p)) {
                r->cancelled = 1;
                break;
            }
        }
    }
    r->seconds = cdl_time_now() - t0;
    gather_stats(r);
    omp_set_num_threads(threads);
    cdl_log_pop(prev);
    return rc;
}

int cdl_renderer_render(cdl_renderer *r, cdl_progress_fn progress, void *user, cdl_error *err)
{
    if (!r)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_render: no renderer");
    if (r->set.c.spp > 0)
        return run(r, (uint32_t)r->set.c.spp, 0.0, progress, user, err);
    return run(r, 0, r->set.c.time, progress, user, err);
}

int cdl_renderer_render_passes(cdl_renderer *r, uint32_t n, cdl_progress_fn progress, void *user, cdl_error *err)
{
    if (!r)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_render_passes: no renderer");
    if (n == 0)
        return 0;
    if (n > UINT32_MAX - r->passes)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_render_passes: too many passes");
    return run(r, r->passes + n, 0.0, progress, user, err);
}

int cdl_renderer_render_pass(cdl_renderer *r, uint32_t index, cdl_error *err)
{
    if (!r)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_render_pass: no renderer");
    if (r->passes == UINT32_MAX)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_render_pass: too many passes");
    r->index = index;
    int rc = run(r, r->passes + 1, 0.0, NULL, NULL, err);
    r->index = -1;
    return rc;
}

size_t cdl_renderer_accum_size(const cdl_renderer *r)
{
    return r ? cdl_film_accum_size(&r->film) + 1 : 0;
}

int cdl_renderer_accum_get(const cdl_renderer *r, double *out, size_t n, cdl_error *err)
{
    if (!r || !out || n != cdl_renderer_accum_size(r))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_accum_get: no renderer or a wrong size");
    out[0] = (double)r->passes;
    cdl_film_accum_get(&r->film, out + 1);
    return 0;
}

int cdl_renderer_accum_set(cdl_renderer *r, const double *in, size_t n, cdl_error *err)
{
    if (!r || !in || n != cdl_renderer_accum_size(r))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_accum_set: no renderer or a wrong size");
    if (!(in[0] >= 0.0 && in[0] <= (double)UINT32_MAX && in[0] == floor(in[0])))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_accum_set: %g passes", in[0]);
    int rc = cdl_film_accum_set(&r->film, in + 1, err);
    if (rc)
        return rc;
    r->passes = (uint32_t)in[0];
    gather_stats(r);
    return 0;
}

int cdl_renderer_adapt_size(cdl_renderer *r, size_t *n, cdl_error *err)
{
    *n = 0;
    if (!r)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_adapt_size: no renderer");
    if (!r->integ.vt->adapt_size)
        return 0;
    const cdl_log_sink *prev = cdl_log_push(&r->set.sink);
    int threads = omp_get_max_threads();
    if (r->set.c.threads > 0)
        omp_set_num_threads((int)r->set.c.threads);
    int rc = prepare(r, err); /* the state is the method's: it must exist */
    omp_set_num_threads(threads);
    cdl_log_pop(prev);
    if (!rc)
        *n = r->integ.vt->adapt_size(r->integ.self);
    return rc;
}

uint32_t cdl_renderer_adapt_next(const cdl_renderer *r)
{
    return r && r->prepared && r->integ.vt->adapt_next ? r->integ.vt->adapt_next(r->integ.self) : UINT32_MAX;
}

int cdl_renderer_adapt_get(const cdl_renderer *r, double *out, size_t n, cdl_error *err)
{
    if (!r || !r->prepared || !r->integ.vt->adapt_get || !out || n != r->integ.vt->adapt_size(r->integ.self))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_adapt_get: no adaptive state of that size");
    r->integ.vt->adapt_get(r->integ.self, out);
    return 0;
}

int cdl_renderer_adapt_fold(cdl_renderer *r, const double *sum, size_t n, cdl_error *err)
{
    if (!r || !r->prepared || !r->integ.vt->adapt_fold || !sum || n != r->integ.vt->adapt_size(r->integ.self))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_adapt_fold: no adaptive state of that size");
    for (size_t i = 0; i < n; i++)
        if (!(sum[i] >= 0.0 && sum[i] < 1.8e19))
            return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_adapt_fold: %g is not a tally", sum[i]);
    r->integ.vt->adapt_fold(r->integ.self, sum);
    return 0;
}

void cdl_renderer_cancel(cdl_renderer *r)
{
    if (r)
        atomic_store(&r->cancel, 1);
}

int cdl_renderer_cancelled(const cdl_renderer *r)
{
    return r ? r->cancelled : 0;
}

void cdl_renderer_budget(const cdl_renderer *r, uint32_t *spp, double *seconds)
{
    *spp = r && r->set.c.spp > 0 ? (uint32_t)r->set.c.spp : 0;
    *seconds = r && r->set.c.spp <= 0 ? r->set.c.time : 0.0;
}

uint32_t cdl_renderer_passes(const cdl_renderer *r)
{
    return r ? r->passes : 0;
}

int cdl_renderer_width(const cdl_renderer *r)
{
    return r ? r->set.c.res[0] : 0;
}

int cdl_renderer_height(const cdl_renderer *r)
{
    return r ? r->set.c.res[1] : 0;
}

const char *cdl_renderer_integrator(const cdl_renderer *r)
{
    return r ? r->set.c.integrator : "";
}

int cdl_renderer_layer_count(const cdl_renderer *r)
{
    return r ? r->film.naovs : 0;
}

const char *cdl_renderer_layer_name(const cdl_renderer *r, int i)
{
    return r && i >= 0 && i < r->film.naovs ? r->film.aovs[i].name : NULL;
}

int cdl_renderer_image(const cdl_renderer *r, const char *layer, cdl_image **out, cdl_error *err)
{
    if (!out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_image: no place for the image");
    *out = NULL;
    if (!r)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_image: no renderer");
    int a = -1;
    if (layer && layer[0] && (a = cdl_film_find_aov(&r->film, layer)) < 0)
        return cdl_error_set(err, CDL_ERR_USAGE, layer, 0, "no such layer (ask for it with the aov setting)");
    cdl_image *img = calloc(1, sizeof *img);
    if (!img)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    int rc = a < 0 ? cdl_film_resolve(&r->film, img, err) : cdl_film_resolve_aov(&r->film, a, img, err);
    if (rc) {
        free(img);
        return rc;
    }
    *out = img;
    return 0;
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

/* A PNG output also gets one PNG per layer: OUT.png -> OUT.NAME.png, a
 * one-channel layer in false colours. */
static int write_layer_pngs(const char *path, const cdl_image *aov, const cdl_layer *layers, int nl,
                            const cdl_kv *meta, int nmeta, float exposure, cdl_error *err)
{
    int rc = 0;
    for (int l = 0; !rc && l < nl; l++) {
        char lp[1100];
        snprintf(lp, sizeof lp, "%.*s.%s.png", (int)(strlen(path) - 4), path, layers[l].name);
        cdl_image view = aov[l];
        if (layers[l].grey) {
            memset(&view, 0, sizeof view);
            rc = cdl_image_alloc(&view, aov[l].width, aov[l].height, err);
            if (rc)
                break;
            memcpy(view.rgb, aov[l].rgb, sizeof(float) * 3 * (size_t)view.width * (size_t)view.height);
            false_colour(&view);
        }
        rc = cdl_image_write(lp, &view, meta, nmeta, layers[l].grey ? 0.0f : exposure, err);
        if (layers[l].grey)
            cdl_image_free(&view);
    }
    return rc;
}

int cdl_renderer_write(const cdl_renderer *r, const char *path, const char *command_line, cdl_error *err)
{
    if (!r || !path)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_renderer_write: no renderer or no path");
    char s_spp[32], s_seed[32], s_time[32];
    snprintf(s_spp, sizeof s_spp, "%u", r->passes);
    snprintf(s_seed, sizeof s_seed, "%ld", r->set.c.seed);
    snprintf(s_time, sizeof s_time, "%.3f", r->seconds);
    cdl_kv meta[] = {{"integrator", r->set.c.integrator}, {"spp", s_spp}, {"seed", s_seed},
                     {"renderTime", s_time}, {"commandLine", command_line}};
    int nmeta = command_line ? 5 : 4;
    cdl_image img = {0}, aov[CDL_MAX_AOVS];
    cdl_layer layers[CDL_MAX_AOVS];
    int nl = 0;
    int rc = cdl_film_resolve(&r->film, &img, err);
    for (int i = 0; !rc && i < r->film.naovs; i++) {
        memset(&aov[i], 0, sizeof aov[i]);
        rc = cdl_film_resolve_aov(&r->film, i, &aov[i], err);
        layers[i] = (cdl_layer){r->film.aovs[i].name, &aov[i], r->film.aovs[i].channels == 1};
        nl = i + 1;
    }
    float exposure = (float)r->set.c.exposure;
    if (!rc)
        rc = nl && cdl_image_has_ext(path, ".exr") ? cdl_image_write_layers(path, &img, layers, nl, meta, nmeta, err)
                                                   : cdl_image_write(path, &img, meta, nmeta, exposure, err);
    if (!rc && nl && cdl_image_has_ext(path, ".png"))
        rc = write_layer_pngs(path, aov, layers, nl, meta, nmeta, exposure, err);
    for (int i = 0; i < nl; i++)
        cdl_image_free(&aov[i]);
    cdl_image_free(&img);
    return rc;
}

int cdl_renderer_stat_count(const cdl_renderer *r)
{
    return r ? r->stats.n : 0;
}

int cdl_renderer_stat(const cdl_renderer *r, int i, const char **name, double *value)
{
    if (!r || i < 0 || i >= r->stats.n)
        return CDL_ERR_USAGE;
    if (name)
        *name = r->stats.v[i].name;
    if (value)
        *value = r->stats.v[i].value;
    return 0;
}

double cdl_renderer_stat_value(const cdl_renderer *r, const char *name)
{
    for (int i = 0; r && name && i < r->stats.n; i++)
        if (!strcmp(r->stats.v[i].name, name))
            return r->stats.v[i].value;
    return NAN;
}

const char *cdl_renderer_report(const cdl_renderer *r)
{
    return r ? r->stats.text : "";
}
