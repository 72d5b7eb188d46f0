/* sppm: stochastic progressive photon mapping (Hachisuka & Jensen 2009,
 * as pbrt-v3 implements it).
 *
 * Each pass traces fresh photons (transport/photons.c, the shared light
 * subpaths; every non-specular hit stores one) and one camera sample per
 * pixel. The camera ray follows specular surfaces (collecting emission)
 * to its visible point x, where direct light is sampled from the lights
 * and the photons within the pixel's radius R give the rest: their count
 * M and Phi = sum f(wo, wi_p) flux_p. Each pixel keeps Hachisuka and
 * Jensen's statistics across passes (the visible point moves, the
 * statistics stay):
 *
 *   N' = N + alpha M,   R'^2 = R^2 N' / (N + M),   tau' = (tau + beta Phi) R'^2 / R^2
 *
 * so R shrinks where photons arrive and the bias falls with the passes.
 * After n passes the pixel is the mean of its direct samples plus
 * tau / (n pi R^2) (photon flux is normalized per pass). The film averages
 * what each pass adds, so a pass adds its direct sample plus the change of
 * n times the photon estimate, tau / (pi R^2) now minus before.
 *
 * The statistics belong to one sequence of passes: under MPI every
 * process runs its own sequence over the passes it renders (each
 * consistent; the image is their mean), with photons seeded by the global
 * pass index. A pass cancelled part way leaves the pixels it did not
 * reach as they were. The initial radius is a few pixel footprints at the
 * pixel's first visible point unless given in scene units. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "integrators/integrator.h"
#include "integrators/pm.h"
#include "transport/light_select.h"
#include "transport/photons.h"
#include "transport/visible.h"

typedef struct sppm_pixel {
    float r2;      /* squared radius, 0 until the first visible point */
    float n;       /* N: the accumulated photon count */
    cdl_vec3 tau;  /* accumulated flux, over the current disc */
    cdl_vec3 shown; /* tau / (pi r2) as the film holds it */
} sppm_pixel;

typedef struct sppm_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    cdl_photon_params pp;
    cdl_photon_map global, caustic;
    cdl_direct_cfg dcfg;
    cdl_vis vis;
    sppm_pixel *px;
    float alpha;
    float px_angle; /* a pixel's angle (footprint per unit distance) */
    cdl_photon_stats last;
    uint32_t passes;
    double t_photons;
    size_t peak_bytes;
    uint64_t found, points; /* photons found and visible points over all passes (statistics) */
} sppm_state;

static int sppm_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    sppm_state *st = self;
    st->scene = scene;
    st->opt = *opt;
    st->walk.maxdepth = opt->maxdepth;
    st->walk.rr_depth = opt->rr_depth;
    cdl_pmap_init(&st->global);
    cdl_pmap_init(&st->caustic);
    if (!(opt->sppm.radius_px > 0.0f))
        return cdl_error_set(err, CDL_ERR_USAGE, "radius_px", 0, "must be > 0");
    st->alpha = opt->progressive ? opt->alpha : 1.0f;
    const cdl_camera *cam = &opt->camera;
    st->px_angle = 2.0f * cam->tan_half * cdl_length(cam->up) / (float)(cam->height > 0 ? cam->height : 1);
    size_t n = (size_t)cam->width * (size_t)cam->height;
    if (!(st->px = calloc(n ? n : 1, sizeof *st->px)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, "sppm", 0, "out of memory for %zu pixels", n);
    st->dcfg.kind = CDL_DIRECT_POWER;
    st->dcfg.shadow_rays = 1;
    cdl_vis vis = {cdl_photon_vis_origin, cdl_photon_visible, scene}, none = {0};
    st->vis = opt->sppm.visibility ? vis : none;
    /* every photon in one of the two maps, no importance: pm's defaults */
    cdl_options po = *opt;
    po.pm.caustic_ratio = 1.0f;
    po.pm.importance = 0;
    return cdl_pm_photon_setup(scene, &po, &st->walk, 0.0f, &st->pp, NULL, err);
}

/* One pixel's pass: what the film gets. */
static cdl_vec3 pixel_pass(sppm_state *st, sppm_pixel *px, cdl_pm_query *q, cdl_vec3 o, cdl_vec3 d,
                           cdl_sampler *smp, uint64_t *rays)
{
    const cdl_scene *s = st->scene;
    cdl_visible v;
    cdl_vec3 L, phi = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t M = 0;
    if (!cdl_find_visible(s, o, d, st->opt.maxdepth, smp, rays, &v)) {
        L = v.L;
    } else {
        uint32_t nl;
        L = cdl_add(v.L, cdl_mul(v.beta, cdl_direct_light(s, &st->dcfg, NULL, &v.sf, &v.b, v.wo, smp, rays, &nl)));
        if (v.depth + 1 < st->opt.maxdepth) {
            if (px->r2 == 0.0f) {
                float r = st->opt.sppm.radius > 0.0f ? st->opt.sppm.radius
                                                      : st->opt.sppm.radius_px * st->px_angle * v.dist;
                px->r2 = r > 0.0f && isfinite(r) ? r * r : 1e-12f;
            }
            /* maxdepth counts the whole path: photons of at most the
             * bounces the camera path has left (their own surface is x) */
            q->max_depth = (uint32_t)(st->opt.maxdepth - v.depth);
            cdl_vec3 f;
            M = cdl_pmap_flux(&st->global, q, px->r2, v.sf.p, v.wo, &v.b, &phi);
            M += cdl_pmap_flux(&st->caustic, q, px->r2, v.sf.p, v.wo, &v.b, &f);
            phi = cdl_mul(v.beta, cdl_add(phi, f));
        }
    }
    if (M) {
        float n2 = px->n + st->alpha * (float)M, shrink = n2 / (px->n + (float)M);
        px->tau = cdl_scale(cdl_add(px->tau, phi), shrink);
        px->r2 *= shrink;
        px->n = n2;
    }
    cdl_vec3 shown = px->r2 > 0.0f ? cdl_scale(px->tau, 1.0f / (CDL_PI * px->r2)) : px->tau;
    L = cdl_add(L, cdl_sub(shown, px->shown));
    px->shown = shown;
#pragma omp atomic
    st->found += M;
    return L;
}

static uint64_t sppm_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1, uint32_t pass, uint64_t *rays)
{
    sppm_state *st = self;
    const cdl_camera *cam = &st->opt.camera;
    /* primary photons are the direct light, which is sampled */
    cdl_pm_query q = {0};
    q.skip = CDL_PH_PRIMARY;
    q.vis = st->vis;
    uint64_t bad = 0, pts = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            uint64_t i = (uint64_t)y * (uint64_t)film->width + (uint64_t)x;
            cdl_sampler smp;
            float jx, jy, fx, fy, fw;
            cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed, i, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            cdl_camera_sample(cam, x, y, jx, jy, &fx, &fy, &fw);
            cdl_vec3 L = pixel_pass(st, &st->px[i], &q, cam->eye, cdl_camera_ray(cam, fx, fy), &smp, rays);
            bad += (uint64_t)cdl_film_add(film, x, y, L);
            pts++;
        }
#pragma omp atomic
    st->points += pts;
    return bad;
}

static int sppm_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    sppm_state *st = self;
    if (st->opt.maxdepth > 1) {
        double t0 = cdl_time_now();
        int rc = cdl_photons_trace(st->scene, &st->walk, &st->pp, st->opt.sampler, st->opt.seed, pass, &st->global,
                                   &st->caustic, &st->last, err);
        if (rc)
            return rc;
        film->rays += st->last.rays;
        size_t bytes = cdl_pmap_bytes(&st->global) + cdl_pmap_bytes(&st->caustic);
        st->peak_bytes = bytes > st->peak_bytes ? bytes : st->peak_bytes;
        st->t_photons += cdl_time_now() - t0;
    }
    st->passes++;
    cdl_render_tiles(self, film, pass, sppm_tile);
    return 0;
}

static void sppm_report(const void *self, cdl_stats *out)
{
    const sppm_state *st = self;
    double mib = 1.0 / (1024.0 * 1024.0);
    size_t n = (size_t)st->opt.camera.width * (size_t)st->opt.camera.height;
    size_t state = n * sizeof(sppm_pixel);
    cdl_stats_printf(out, "sppm: per pass %llu photon paths, %u + %u photons stored; maps %.2f MiB (peak), pixel "
                          "statistics %.2f MiB; %.1f photons found per visible point and pass\n",
                     (unsigned long long)st->last.paths, st->global.n, st->caustic.n, (double)st->peak_bytes * mib,
                     (double)state * mib, st->points ? (double)st->found / (double)st->points : 0.0);
    cdl_stats_printf(out, "sppm: photon tracing %.2f s over %u passes\n", st->t_photons, st->passes);
    cdl_stats_add(out, "photon_paths", (double)st->last.paths);
    cdl_stats_add(out, "map_mib", (double)(st->peak_bytes + state) * mib);
    cdl_stats_add(out, "t_photons", st->t_photons);
    cdl_stats_add(out, "photons_per_point", st->points ? (double)st->found / (double)st->points : 0.0);
}

static void sppm_destroy(void *self)
{
    sppm_state *st = self;
    cdl_pmap_free(&st->global);
    cdl_pmap_free(&st->caustic);
    free(st->px);
}

#define AT(f) CDL_PARAM_AT(cdl_options, sppm.f)
static const cdl_param rows[] = {
    {"radius", CDL_PARAM_FLOAT, "R", "", "initial radius of every pixel's photon disc in scene units (default: "
     "radius_px pixel footprints at the pixel's first visible point)", 1e-9, 1e9, AT(radius)},
    {"radius_px", CDL_PARAM_FLOAT, "P", "1", "the default initial radius in pixel footprints", 1e-3, 1e4,
     AT(radius_px)},
    {"photon_visibility", CDL_PARAM_BOOL, "on|off", "on", "leave out photons no free path joins to the visible "
     "point (a shadow ray each; without, light leaks near a wall's foot until the radius shrinks past it)",
     AT(visibility)},
};
#undef AT
static const cdl_param_table table =
    CDL_PARAM_TABLE("Stochastic progressive photon mapping (sppm; Hachisuka & Jensen 2009)", rows);
static const cdl_param_table *const tables[] = {&cdl_density_table, &cdl_photon_table, &table, NULL};

const cdl_integrator_vtbl cdl_sppm_integrator = {
    .params = tables,
    .name = "sppm",
    .summary = "stochastic progressive photon mapping: per-pixel radii shrinking with alpha (Hachisuka & Jensen 2009)",
    .prepare = sppm_prepare,
    .render_pass = sppm_render_pass,
    .destroy = sppm_destroy,
    .report = sppm_report,
    .self_size = sizeof(sppm_state),
};
