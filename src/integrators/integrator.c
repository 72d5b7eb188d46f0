#include "integrators/integrator.h"

#include "core/common_params.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


extern const cdl_integrator_vtbl cdl_path_integrator;
extern const cdl_integrator_vtbl cdl_bdpt_integrator;
extern const cdl_integrator_vtbl cdl_ir_integrator;
extern const cdl_integrator_vtbl cdl_rigi_integrator;
extern const cdl_integrator_vtbl cdl_pm_integrator;
extern const cdl_integrator_vtbl cdl_gkde_integrator;
extern const cdl_integrator_vtbl cdl_splat_integrator;
extern const cdl_integrator_vtbl cdl_sppm_integrator;
extern const cdl_integrator_vtbl cdl_vcm_integrator;

static const cdl_integrator_vtbl *const all[] = {&cdl_path_integrator, &cdl_bdpt_integrator,
                                                 &cdl_ir_integrator, &cdl_rigi_integrator,
                                                 &cdl_pm_integrator, &cdl_gkde_integrator, &cdl_splat_integrator,
                                                 &cdl_sppm_integrator, &cdl_vcm_integrator, NULL};

#define AT(f) CDL_PARAM_AT(cdl_options, f)

static const cdl_param density_rows[] = {
    {"progressive", CDL_PARAM_BOOL, "on|off", "on",
     "consistent: every bandwidth shrinks with the passes, so the bias falls with time: pm's radii, gkde's h and "
     "splat's kernels with the pass index i as r_i^2 = r_0^2 prod (j + alpha) / (j + 1) (Knaus & Zwicker 2011), "
     "sppm's per-pixel radii by its photon counts, vcm's merge radius as r_1 i^((alpha - 1) / 2) (SmallVCM's); off: "
     "the fixed bandwidths of the reports (vcm: r_1)",
     AT(progressive)},
    {"alpha", CDL_PARAM_FLOAT, "a", "2/3",
     "radius reduction: r^2 falls about as i^(alpha - 1); smaller shrinks faster with more noise", 0, 1,
     .note = "1 keeps the bandwidths fixed, 0 lets the noise grow", .flags = CDL_PARAM_OPEN_MIN | CDL_PARAM_OPEN_MAX,
     AT(alpha)},
};
const cdl_param_table cdl_density_table = CDL_PARAM_TABLE("Density estimation (pm, gkde, splat, sppm, vcm)", density_rows);

static const cdl_param photon_rows[] = {
    {"photons", CDL_PARAM_INT, "N", "200000",
     "photons stored per pass: pm's global map (paths are traced until it holds N), splat's photon rays of all "
     "budgets, sppm's photons",
     1, 5e8, AT(photons)},
};
const cdl_param_table cdl_photon_table = CDL_PARAM_TABLE("Photons (pm, splat, sppm)", photon_rows);

static const double per_sample[] = {CDL_LIGHT_PATHS_PER_SAMPLE};
static const cdl_param light_path_rows[] = {
    {"light_paths", CDL_PARAM_INT, "K|sample", "",
     "K light paths per pass shared by all pixels, or 'sample': an independent one per pixel sample (bdpt default: "
     "sample; ir/rigi default 256 paths in 4 x 4 interleaved sets)",
     1, 1e8, .choices = "sample", .values = per_sample, AT(light_paths)},
    {"interleave", CDL_PARAM_INT, "N", "1", "N x N interleaved sets of the K light paths", 1, 64, AT(interleave)},
    {"threshold", CDL_PARAM_FLOAT, "t", "",
     "stratification threshold on G (rigi; bdpt's stratified weights; ir's clamp by default): the scene's "
     "diagonal d gives t = 1 / (0.15 d)^2; printed when used",
     1e-12, 1e12, AT(threshold)},
};
const cdl_param_table cdl_light_path_table =
    CDL_PARAM_TABLE("Shared light paths (bdpt, ir, rigi; Kollig & Keller 2004)", light_path_rows);

static const cdl_param shadow_rows[] = {
    {"shadow_mode", CDL_PARAM_CHOICE, "KIND", "bundle",
     "bundle (one Embree ray stream per point light and tile, or per footprint) or single (one by one, for "
     "comparison)",
     .choices = "bundle|single", AT(single_shadow_rays)},
};
const cdl_param_table cdl_shadow_table = CDL_PARAM_TABLE("Shadow rays to points (ir, rigi, gkde)", shadow_rows);

void cdl_options_default(cdl_options *o)
{
    memset(o, 0, sizeof *o);
    o->rr_depth = 3;
    cdl_common_params c;
    cdl_common_default(&c);
    o->maxdepth = (int)c.maxdepth;
    o->seed = (uint64_t)c.seed;
    o->sampler = (cdl_sampler_kind)c.sampler;
    for (int i = 0; all[i]; i++)
        for (const cdl_param_table *const *t = all[i]->params; t && *t; t++)
            cdl_param_defaults(*t, o);
}

int cdl_light_paths_check(const cdl_options *opt, cdl_error *err)
{
    if (opt->interleave > 1 && (!opt->light_paths || opt->light_paths == CDL_LIGHT_PATHS_PER_SAMPLE))
        return cdl_error_set(err, CDL_ERR_USAGE, "interleave", 0, "needs light_paths K (the paths to interleave)");
    if (opt->light_paths && opt->light_paths != CDL_LIGHT_PATHS_PER_SAMPLE &&
        opt->light_paths < opt->interleave * opt->interleave)
        return cdl_error_set(err, CDL_ERR_USAGE, "light_paths", 0, "%u paths cannot fill %u x %u interleaved sets",
                             opt->light_paths, opt->interleave, opt->interleave);
    return 0;
}

float cdl_progressive_r2(const cdl_options *opt, uint32_t pass)
{
    if (!opt->progressive || !pass)
        return 1.0f;
    double a = opt->alpha, i = pass;
    return (float)exp(lgamma(i + 1.0 + a) - lgamma(1.0 + a) - lgamma(i + 2.0));
}

float cdl_default_threshold(const cdl_scene *s, const cdl_options *opt)
{
    if (opt->threshold > 0.0f)
        return opt->threshold;
    float r = 0.15f * cdl_length(cdl_sub(s->bmax, s->bmin));
    return r > 0.0f ? 1.0f / (r * r) : 1.0f;
}

const cdl_integrator_vtbl *const *cdl_integrator_list(void) { return all; }

const cdl_integrator_vtbl *cdl_integrator_find(const char *name)
{
    for (int i = 0; all[i]; i++)
        if (!strcmp(all[i]->name, name))
            return all[i];
    return NULL;
}

int cdl_integrator_create(const char *name, cdl_integrator *out, cdl_error *err)
{
    const cdl_integrator_vtbl *vt = cdl_integrator_find(name);
    if (!vt)
        return cdl_error_set(err, CDL_ERR_USAGE, "-i", 0, "unknown integrator '%s'", name);
    out->vt = vt;
    out->self = calloc(1, vt->self_size);
    if (!out->self)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    return 0;
}

void cdl_integrator_destroy(cdl_integrator *it)
{
    if (it->self && it->vt->destroy)
        it->vt->destroy(it->self);
    free(it->self);
    it->self = NULL;
}

void cdl_render_tiles(void *self, cdl_film *film, uint32_t pass, cdl_tile_fn fn)
{
    enum { T = 16 };
    int tx = (film->width + T - 1) / T, ty = (film->height + T - 1) / T;
    int ntiles = tx * ty;
    uint64_t rays = 0, bad = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : rays, bad)
    for (int t = 0; t < ntiles; t++) {
        if (cdl_cancelled(film->cancel))
            continue;
        int x0 = (t % tx) * T, y0 = (t / tx) * T;
        int x1 = x0 + T < film->width ? x0 + T : film->width;
        int y1 = y0 + T < film->height ? y0 + T : film->height;
        uint64_t r = 0;
        bad += fn(self, film, x0, y0, x1, y1, pass, &r);
        rays += r;
    }
    film->rays += rays;
    film->nonfinite += bad;
}
