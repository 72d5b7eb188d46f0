#include "integrators/integrator.h"

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

static const cdl_integrator_vtbl *const all[] = {&cdl_path_integrator, &cdl_bdpt_integrator,
                                                 &cdl_ir_integrator, &cdl_rigi_integrator,
                                                 &cdl_pm_integrator, &cdl_gkde_integrator, &cdl_splat_integrator, NULL};

void cdl_options_default(cdl_options *o)
{
    memset(o, 0, sizeof *o);
    o->maxdepth = 64;
    o->rr_depth = 3;
    o->seed = 1;
    o->mis = CDL_MIS_POWER;
    o->interleave = 1;
    o->progressive = 1;
    o->alpha = 2.0f / 3.0f;
    o->pm.photons = 200000;
    o->pm.k = 20;
    o->pm.kernel = 1; /* cone */
    o->pm.gather = 8;
    o->pm.precompute = 4;
    o->pm.importons = 1u << 17;
    o->pm.eps = 0.01f;
    o->pm.caustic_ratio = 1.0f;
    o->pm.shadow_rays = 4;
    o->pm.visibility = CDL_PM_VIS_ALL;
    o->gkde.eye_paths = 1;
    o->gkde.links = 0; /* tied to the light paths (gkde.h) */
    o->gkde.footprint_cap = 2.0f;
    o->gkde.overlaps = 2.0f;
    o->gkde.max_mib = 4096;
    o->splat.photons = 200000;
    o->splat.fractions[0] = 0.3f;
    o->splat.fractions[1] = 0.6f;
    o->splat.fractions[2] = 0.1f;
    o->splat.C = 0.5f;
    o->splat.S = 0.4f;
    o->splat.R = 0.2f;
    o->splat.mode = CDL_SPLAT_DIRECT;
    o->splat.eye_samples = 1;
    o->splat.cull = 1;
    o->splat.filter_normal = 20.0f;
    o->splat.filter_depth = 0.05f;
    o->splat.filter_max = 25;
    o->splat.cache_min = 5;
    o->splat.cap = 4.0f;
    o->splat.occlusion = 1;
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
