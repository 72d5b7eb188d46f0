/* pm: photon mapping (Jensen 1996) with the importance sampling
 * techniques of Keller & Wald 2000.
 *
 * Each pass traces fresh photons (transport/photons.c: light subpaths of
 * the shared tracer, deposited into a global and a caustic map), then one
 * sample per pixel: the camera ray follows specular surfaces (collecting
 * emission) to the first non-specular point x, where
 *   direct light    light sampling (direct power | lcon | lcon-biased),
 *   caustics        the caustic map (photons last scattered specularly),
 *   indirect light  gather N rays from x by BSDF sampling, each querying
 *                   both maps where it lands (rays that land on a specular
 *                   surface carry caustics: they are the caustic map's part);
 *                   gather 0 queries the global map at x without its
 *                   primary photons (direct visualization).
 * Passes average. By default every estimate's radius (the k nearest's,
 * within max_radius) is scaled by the pass's factor of progressive
 * photon mapping (Knaus & Zwicker 2011; cdl_progressive_r2), so the bias
 * falls with the passes as the noise does. Their probabilistic form is the
 * one that fits here: each pass is an independent estimate whose radius
 * is a function of the pass index alone, so the same schedule serves the
 * camera's point, the final-gather hits, the precomputed irradiance and
 * the caustic map alike, and passes can still be split over processes;
 * Hachisuka & Jensen's per-pixel statistics exist only for the camera's
 * points. progressive off: Jensen's fixed k-NN estimate, whose bias
 * shrinks only with photons. */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "integrators/pm.h"
#include "transport/light_select.h"
#include "transport/photons.h"
#include "transport/visible.h"

typedef struct pm_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    cdl_photon_params pp;
    cdl_photon_map global, caustic, direct;
    cdl_irr_map irr;   /* precomputed irradiance for gather rays */
    uint32_t ph_depth; /* deepest photon of both maps */
    cdl_importance imp;
    int has_imp;
    float max_r2, lcon_r2;
    cdl_vis vis_gather, vis_camera; /* photon visibility tests, or none */
    cdl_direct_cfg dcfg;
    uint32_t traced_pass; /* pass whose photons the maps hold, or UINT32_MAX */
    float shrink;         /* that pass's squared-radius factor (cdl_progressive_r2) */
    /* statistics */
    cdl_photon_stats last, sum;
    uint32_t passes;
    size_t peak_bytes;
    double t_photons, t_importons;
    uint64_t lcon_sum, lcon_points;
} pm_state;

static int trace(pm_state *st, uint32_t pass, uint64_t *rays, cdl_error *err)
{
    double t0 = cdl_time_now();
    int rc = cdl_photons_trace(st->scene, &st->walk, &st->pp, st->opt.sampler, st->opt.seed, pass,
                               &st->global, &st->caustic, &st->last, err);
    if (rc)
        return rc;
    st->shrink = cdl_progressive_r2(&st->opt, pass);
    if (st->dcfg.kind != CDL_DIRECT_POWER && st->dcfg.kind != CDL_DIRECT_NONE && !st->direct.built) {
        /* the primary photons of the first pass on their own, for the L_con
         * ball queries; kept for all passes: L_con then stays the same set at
         * a point, so each light's samples stay stratified over the passes */
        for (uint32_t i = 0; i < st->global.n && !rc; i++)
            if (cdl_photon_flags(&st->global.ph[i]) & CDL_PH_PRIMARY)
                rc = cdl_pmap_append(&st->direct, &st->global.ph[i], 1, err);
        if (!rc)
            rc = cdl_pmap_build(&st->direct, err);
        if (rc)
            return rc;
    }
    st->ph_depth = 0;
    for (int c = 0; c < 2; c++) {
        const cdl_photon_map *m = c ? &st->caustic : &st->global;
        for (uint32_t i = 0; i < m->n; i++) {
            uint32_t d = cdl_photon_depth(&m->ph[i]);
            st->ph_depth = d > st->ph_depth ? d : st->ph_depth;
        }
    }
    if (st->opt.pm.gather && st->opt.pm.precompute) {
        /* for gather rays from the first vertex: the camera ray and the
         * gather ray leave maxdepth - 1 bounces to the photons */
        cdl_pm_query q = {st->opt.pm.k, st->max_r2, (cdl_kernel)st->opt.pm.kernel, 0, NULL, NULL,
                          st->vis_gather, (uint32_t)st->opt.maxdepth - 1, NULL, 0, st->shrink};
        rc = cdl_irr_build(&st->irr, &st->global, &st->caustic, st->opt.pm.precompute, &q, err);
        if (rc)
            return rc;
    }
    st->dcfg.direct = &st->direct;
    st->traced_pass = pass;
    st->sum.paths += st->last.paths;
    st->sum.candidates += st->last.candidates;
    st->sum.rays += st->last.rays;
    *rays += st->last.rays;
    size_t bytes = cdl_pmap_bytes(&st->global) + cdl_pmap_bytes(&st->caustic) + cdl_pmap_bytes(&st->direct) +
                   cdl_irr_bytes(&st->irr);
    st->peak_bytes = bytes > st->peak_bytes ? bytes : st->peak_bytes;
    st->t_photons += cdl_time_now() - t0;
    return 0;
}

static int pm_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    pm_state *st = self;
    st->scene = scene;
    st->opt = *opt;
    opt = &st->opt;
    if (st->opt.pm.direct == CDL_PM_DIRECT_PHOTONS) {
        st->opt.pm.direct_photons = 1;
        st->opt.pm.direct = CDL_DIRECT_POWER;
    }
    st->walk.maxdepth = opt->maxdepth;
    st->walk.rr_depth = opt->rr_depth;
    st->traced_pass = UINT32_MAX;
    cdl_pmap_init(&st->global);
    cdl_pmap_init(&st->caustic);
    cdl_pmap_init(&st->direct);
    float r;
    if (cdl_pm_max_radius(scene, &opt->pm, &r, err))
        return err->code;
    st->max_r2 = r * r;
    float rl = opt->pm.lcon_radius > 0.0f ? opt->pm.lcon_radius : r;
    st->lcon_r2 = rl * rl;
    if (opt->pm.k < 1 || opt->pm.k > 4096)
        return cdl_error_set(err, CDL_ERR_USAGE, "knn", 0, "must be in [1, 4096]");
    if (!(opt->pm.caustic_ratio > 0.0f && opt->pm.caustic_ratio <= 1.0f))
        return cdl_error_set(err, CDL_ERR_USAGE, "caustic_ratio", 0, "must be in (0, 1]");
    if (!(opt->pm.eps > 0.0f && opt->pm.eps <= 1.0f))
        return cdl_error_set(err, CDL_ERR_USAGE, "importance_eps", 0, "must be in (0, 1]");
    if (opt->pm.discard && !opt->pm.importance)
        return cdl_error_set(err, CDL_ERR_USAGE, "importance_discard", 0, "needs importance");
    if (opt->pm.direct_photons && opt->pm.gather)
        return cdl_error_set(err, CDL_ERR_USAGE, "direct", 0,
                             "photons (direct light read from the photon map) needs gather 0");
    if (opt->pm.precompute == 1)
        return cdl_error_set(err, CDL_ERR_USAGE, "precompute", 0,
                             "must be 0 (off) or at least 2: the photons that carry irradiance points "
                             "cannot also estimate there");
    if (opt->pm.visibility < CDL_PM_VIS_GATHER || opt->pm.visibility > CDL_PM_VIS_OFF)
        return cdl_error_set(err, CDL_ERR_USAGE, "visibility", 0, "unknown kind %d", opt->pm.visibility);
    cdl_vis vis = {cdl_photon_vis_origin, cdl_photon_visible, scene}, none = {0};
    st->vis_gather = opt->pm.visibility != CDL_PM_VIS_OFF ? vis : none;
    st->vis_camera = opt->pm.visibility == CDL_PM_VIS_ALL ? vis : none;
    st->dcfg.kind = (cdl_direct_kind)opt->pm.direct;
    st->dcfg.shadow_rays = opt->pm.shadow_rays ? opt->pm.shadow_rays : 1;
    st->dcfg.r2 = st->lcon_r2;
    st->dcfg.direct = &st->direct;
    double t0 = cdl_time_now();
    if (cdl_pm_photon_setup(scene, opt, &st->walk, r, &st->pp, &st->imp, err))
        return err->code;
    st->has_imp = st->pp.imp != NULL;
    st->t_importons = cdl_time_now() - t0;
    /* pass 0's photons now, so that a budget that cannot be met is an error before rendering */
    uint64_t rays = 0;
    return trace(st, 0, &rays, err);
}

int cdl_pm_max_radius(const cdl_scene *s, const cdl_pm_options *o, float *r, cdl_error *err)
{
    *r = o->max_radius > 0.0f ? o->max_radius : 0.05f * cdl_length(cdl_sub(s->bmax, s->bmin));
    if (!(*r > 0.0f))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the scene has no extent to size photon queries by");
    return 0;
}

int cdl_pm_photon_setup(const cdl_scene *s, const cdl_options *opt, const cdl_walk *walk, float max_radius,
                        cdl_photon_params *pp, cdl_importance *imp, cdl_error *err)
{
    const cdl_pm_options *o = &opt->pm;
    *pp = (cdl_photon_params){opt->photons, o->caustic_ratio, o->caustic_random, NULL, o->eps, o->discard,
                              o->max_paths ? o->max_paths : cdl_photons_default_max_paths(opt->photons)};
    if (!o->importance)
        return 0;
    int rc = cdl_importance_build(imp, s, &opt->camera, walk, o->importons, 1024, max_radius, opt->sampler,
                                  opt->seed, err);
    if (!rc)
        pp->imp = imp;
    return rc;
}

typedef struct scratch {
    cdl_pm_query qg, qc;  /* at gather hits */
    cdl_pm_query qgx, qcx; /* at the camera's point */
    cdl_lcon_scratch lc;
} scratch;

/* Radiance leaving the non-specular surface point of sf towards wo, from
 * both maps (at the end of a gather ray). */
/* Both maps' radiance where a gather ray landed, from photons of at most
 * `left` bounces. */
static cdl_vec3 photon_radiance(const pm_state *st, scratch *w, const cdl_surface *sf, const cdl_bsdf *b,
                                cdl_vec3 wo, uint32_t left)
{
    /* with precomputed points, a gather ray that found none reads the photons
     * that carry none (photon_map.h: cdl_irr_map.est) */
    const cdl_photon_map *g = st->irr.n ? &st->irr.est : &st->global;
    w->qg.max_depth = left;
    w->qc.max_depth = left;
    cdl_vec3 L = cdl_pmap_radiance(g, &w->qg, sf->p, wo, b);
    if (st->caustic.n)
        L = cdl_add(L, cdl_pmap_radiance(&st->caustic, &w->qc, sf->p, wo, b));
    return L;
}

static cdl_vec3 radiance(pm_state *st, scratch *w, cdl_vec3 o, cdl_vec3 d, cdl_sampler *smp, uint64_t *rays,
                         uint32_t *nlcon)
{
    const cdl_scene *s = st->scene;
    cdl_visible v;
    if (!cdl_find_visible(s, o, d, st->opt.maxdepth, smp, rays, &v))
        return v.L;
    cdl_vec3 L = v.L, beta = v.beta, wo = v.wo;
    const cdl_surface sf = v.sf;
    const cdl_bsdf b = v.b;
    int depth = v.depth;
    if (st->opt.pm.direct_photons) {
        /* the photon map seen directly, its primary photons the direct
         * light (Jensen's visualization; Bekaert et al. 2003, Fig. 1) */
        cdl_pm_query q = w->qgx;
        q.max_depth = (uint32_t)(st->opt.maxdepth - depth);
        w->qcx.max_depth = q.max_depth;
        cdl_vec3 Lp = cdl_pmap_radiance(&st->global, &q, sf.p, wo, &b);
        if (st->caustic.n)
            Lp = cdl_add(Lp, cdl_pmap_radiance(&st->caustic, &w->qcx, sf.p, wo, &b));
        return cdl_add(L, cdl_mul(beta, Lp));
    }
    cdl_vec3 Lx = cdl_direct_light(s, &st->dcfg, &w->lc, &sf, &b, wo, smp, rays, nlcon);
    if (depth + 1 < st->opt.maxdepth) {
        /* maxdepth counts the whole path: the photons here may have met
         * as many surfaces as the camera path has bounces left */
        uint32_t left = (uint32_t)(st->opt.maxdepth - depth);
        w->qcx.max_depth = left;
        if (st->caustic.n)
            Lx = cdl_add(Lx, cdl_pmap_radiance(&st->caustic, &w->qcx, sf.p, wo, &b));
        uint32_t ng = st->opt.pm.gather;
        if (!ng) {
            cdl_pm_query q = w->qgx;
            q.skip = CDL_PH_PRIMARY; /* light sampling has the direct part */
            q.max_depth = left;
            Lx = cdl_add(Lx, cdl_pmap_radiance(&st->global, &q, sf.p, wo, &b));
        }
        cdl_vec3 Lg = cdl_v3(0.0f, 0.0f, 0.0f);
        for (uint32_t g = 0; g < ng; g++) {
            cdl_scatter sc;
            float u0 = cdl_sampler_1d(smp), u1, u2;
            cdl_sampler_2d(smp, &u1, &u2);
            if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc) || cdl_is_black(sc.weight))
                continue;
            cdl_hit hg;
            (*rays)++;
            if (!cdl_intersect(s, cdl_offset(s, sf.p, sf.ng, sc.wi), sc.wi, FLT_MAX, &hg))
                continue; /* the sky is direct light */
            cdl_surface sg;
            cdl_surface_at(s, &hg, &sg);
            cdl_bsdf bg;
            cdl_scene_bsdf(s, &sg, &bg);
            if (cdl_bsdf_is_delta(&bg))
                continue; /* specular then x: the caustic map's paths */
            cdl_vec3 wg = cdl_neg(sc.wi);
            if (bg.one_sided && cdl_dot(wg, sg.ng) <= 0.0f)
                continue; /* the back of a one-sided surface reflects nothing */
            int found = 0;
            /* the points hold photons of up to maxdepth - 1 bounces: all a
             * gather from the first vertex may use, more after a mirror
             * unless no photon went that deep */
            if (bg.type == CDL_MAT_DIFFUSE && st->irr.n && (depth == 0 || st->ph_depth <= left - 1)) {
                cdl_vec3 n = cdl_dot(sg.ng, wg) < 0.0f ? cdl_neg(sg.ng) : sg.ng;
                cdl_vec3 E = cdl_irr_lookup(&st->irr, sg.p, n, wg, st->max_r2, st->opt.progressive,
                                            st->vis_gather, &found);
                if (found)
                    Lg = cdl_add(Lg, cdl_mul(sc.weight, cdl_mul(bg.kd, cdl_scale(E, CDL_INV_PI))));
            }
            if (!found)
                Lg = cdl_add(Lg, cdl_mul(sc.weight, photon_radiance(st, w, &sg, &bg, wg, left - 1)));
        }
        if (ng)
            Lx = cdl_add(Lx, cdl_scale(Lg, 1.0f / (float)ng));
    }
    return cdl_add(L, cdl_mul(beta, Lx));
}

static uint64_t pm_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1, uint32_t pass,
                        uint64_t *rays)
{
    pm_state *st = self;
    const cdl_camera *cam = &st->opt.camera;
    scratch w;
    uint32_t k = st->opt.pm.k, cap = 4 * k;
    w.qg = (cdl_pm_query){k, st->max_r2, (cdl_kernel)st->opt.pm.kernel, 0, malloc(sizeof(uint32_t) * cap),
                          malloc(sizeof(float) * cap), st->vis_gather, 0, NULL, cap, st->shrink};
    w.qc = w.qg;
    w.qgx = w.qg;
    w.qgx.vis = st->vis_camera;
    w.qcx = w.qgx;
    /* the camera's points are coherent pixel after pixel: each query's
     * radius is the next one's first guess (per map) */
    float guess_g = 0.0f, guess_c = 0.0f;
    w.qgx.guess = &guess_g;
    w.qcx.guess = &guess_c;
    uint64_t bad = 0, lsum = 0, lpts = 0;
    if (w.qg.idx && w.qg.d2 && !cdl_lcon_scratch_init(&w.lc, st->scene->nlights)) {
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                cdl_sampler smp;
                float jx, jy;
                cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed,
                                  (uint64_t)y * (uint64_t)film->width + (uint64_t)x, pass);
                cdl_sampler_2d(&smp, &jx, &jy);
                uint32_t nl = 0;
                float fx, fy, fw;
                cdl_camera_sample(cam, x, y, jx, jy, &fx, &fy, &fw);
                cdl_vec3 L = radiance(st, &w, cam->eye, cdl_camera_ray(cam, fx, fy), &smp, rays, &nl);
                lsum += nl;
                lpts++;
                bad += (uint64_t)cdl_film_add(film, x, y, fw == 1.0f ? L : cdl_scale(L, fw));
            }
        cdl_lcon_scratch_free(&w.lc);
    }
    free(w.qg.idx);
    free(w.qg.d2);
#pragma omp atomic
    st->lcon_sum += lsum;
#pragma omp atomic
    st->lcon_points += lpts;
    return bad;
}

static int pm_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    pm_state *st = self;
    /* direct light only (maxdepth 1) reads no photon map but L_con's,
     * which the first pass built: no photons to trace */
    if (st->traced_pass != pass && (st->opt.maxdepth > 1 || st->opt.pm.direct_photons)) {
        int rc = trace(st, pass, &film->rays, err);
        if (rc)
            return rc;
    }
    st->passes++;
    cdl_render_tiles(self, film, pass, pm_tile);
    return 0;
}

static void pm_report(const void *self, cdl_stats *out)
{
    const pm_state *st = self;
    double mib = 1.0 / (1024.0 * 1024.0);
    cdl_stats_printf(out, "pm: per pass %llu photon paths traced (%llu for the global map), %u global + %u caustic "
           "photons stored of %llu surface hits; maps %.2f MiB (peak, %zu B per photon + kd-tree)\n",
           (unsigned long long)st->last.paths, (unsigned long long)st->last.paths_global, st->global.n,
           st->caustic.n, (unsigned long long)st->last.candidates, (double)st->peak_bytes * mib,
           sizeof(cdl_photon));
    cdl_stats_printf(out, "pm: photon tracing %.2f s over %u passes", st->t_photons, st->passes);
    if (st->has_imp)
        cdl_stats_printf(out, "; %u importons from %llu paths (%.2f MiB, %.2f s), f = %.4g from %u test rays", st->imp.n,
               (unsigned long long)st->imp.paths, (double)cdl_importance_bytes(&st->imp) * mib,
               st->t_importons, st->imp.f, st->imp.tests);
    if (st->dcfg.kind != CDL_DIRECT_POWER && st->dcfg.kind != CDL_DIRECT_NONE && st->lcon_points)
        cdl_stats_printf(out, "; |L_con| %.2f on average of %u lights", (double)st->lcon_sum / (double)st->lcon_points,
               st->scene->nlights);
    cdl_stats_printf(out, "\n");
    cdl_stats_add(out, "photon_paths", (double)st->last.paths);
    cdl_stats_add(out, "global_photons", (double)st->global.n);
    cdl_stats_add(out, "caustic_photons", (double)st->caustic.n);
    cdl_stats_add(out, "map_mib", (double)st->peak_bytes * mib);
    cdl_stats_add(out, "t_photons", st->t_photons);
    if (st->has_imp) {
        cdl_stats_add(out, "importons", (double)st->imp.n);
        cdl_stats_add(out, "t_importons", st->t_importons);
    }
}

static void pm_destroy(void *self)
{
    pm_state *st = self;
    cdl_pmap_free(&st->global);
    cdl_pmap_free(&st->caustic);
    cdl_pmap_free(&st->direct);
    cdl_irr_free(&st->irr);
    if (st->has_imp)
        cdl_importance_free(&st->imp);
}

#define AT(f) CDL_PARAM_AT(cdl_options, pm.f)
static const double direct_kinds[] = {CDL_DIRECT_POWER, CDL_DIRECT_LCON, CDL_DIRECT_LCON_BIASED, CDL_PM_DIRECT_PHOTONS,
                                      CDL_DIRECT_NONE};
static const cdl_param rows[] = {
    {"knn", CDL_PARAM_INT, "K", "20", "photons per radiance estimate (their radius, scaled by the pass's factor when "
     "progressive)", 1, 4096, AT(k)},
    {"max_radius", CDL_PARAM_FLOAT, "R", "", "largest estimate radius (default 5 % of the scene's diagonal)", 1e-9,
     1e9, AT(max_radius)},
    {"kernel", CDL_PARAM_CHOICE, "KIND", "cone", "box, cone or epanechnikov", .choices = "box|cone|epanechnikov",
     AT(kernel)},
    {"gather", CDL_PARAM_INT, "N", "8", "final gathering rays per pixel sample; 0 shows the global map directly", 0,
     65536, AT(gather)},
    {"precompute", CDL_PARAM_INT, "M", "4", "gather rays landing on Lambertian surfaces read the irradiance "
     "precomputed at 1 in M photons from the others (Christensen 1999; 0 = a full estimate; M >= 2)", 0, 1e6,
     AT(precompute)},
    {"visibility", CDL_PARAM_CHOICE, "V", "all", "which estimates leave out photons no free path joins to the query "
     "point (a shadow ray each): all (no light in a room that no light path enters), gather (only those at "
     "final-gather hits, incl. the precomputed irradiance: gather 0 and caustics at the camera's point may leak) or "
     "off (Jensen's: leaks through thin walls)", .choices = "gather|all|off", AT(visibility)},
    {"caustic_ratio", CDL_PARAM_FLOAT, "q", "1", "only a fraction q of the paths fills the global map, all fill the "
     "caustic map", 0, 1, .flags = CDL_PARAM_OPEN_MIN, AT(caustic_ratio)},
    {"caustic_select", CDL_PARAM_CHOICE, "S", "prefix", "prefix (the first q N paths) or random (a test against q "
     "per photon)", .choices = "prefix|random", AT(caustic_random)},
    {"importance", CDL_PARAM_BOOL, "", "off", "store photons with probability p = min(1, f I(x)) from importons "
     "traced from the camera (power L / p)", .flags = CDL_PARAM_FLAG, AT(importance)},
    {"importons", CDL_PARAM_INT, "N", "131072", "importon paths", 1, 1e8, AT(importons)},
    {"importance_eps", CDL_PARAM_FLOAT, "e", "0.01", "lower bound of p (unbiased)", 0, 1,
     .note = "a zero bound drops photons no importon saw: biased", .flags = CDL_PARAM_OPEN_MIN, AT(eps)},
    {"importance_discard", CDL_PARAM_BOOL, "", "off", "drop photons with p < e instead (biased)",
     .flags = CDL_PARAM_FLAG, AT(discard)},
    {"direct", CDL_PARAM_CHOICE, "KIND", "power", "power (lights in proportion to power), lcon (S rays to the lights "
     "of nearby primary photons, one to the rest), lcon-biased (none to the rest), photons (read from the photon "
     "map: its primary photons seen directly; needs gather 0) or none (indirect light alone, for comparisons)",
     .choices = "power|lcon|lcon-biased|photons|none", .values = direct_kinds, AT(direct)},
    {"shadow_rays", CDL_PARAM_INT, "S", "4", "direct-light shadow rays per shading point", 1, 4096, AT(shadow_rays)},
    {"lcon_radius", CDL_PARAM_FLOAT, "R", "", "radius of the L_con query (default: max_radius)", 1e-9, 1e9,
     AT(lcon_radius)},
    {"photon_paths_max", CDL_PARAM_INT, "N", "", "give up when N paths per pass have not stored the photons (default "
     "1000 per photon, at least 2^20)", 1, 2147483647.0, AT(max_paths)},
};
#undef AT
static const cdl_param_table table = CDL_PARAM_TABLE("Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)", rows);
static const cdl_param_table *const tables[] = {&cdl_density_table, &cdl_photon_table, &table, NULL};

const cdl_integrator_vtbl cdl_pm_integrator = {
    .params = tables,
    .name = "pm",
    .summary = "photon mapping with importons, automatic caustics and L_con (Keller & Wald 2000)",
    .prepare = pm_prepare,
    .render_pass = pm_render_pass,
    .destroy = pm_destroy,
    .report = pm_report,
    .self_size = sizeof(pm_state),
};
