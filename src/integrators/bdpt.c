/* bdpt: bidirectional path tracing (Veach 1997; Lafortune & Willems 1993)
 * with every connection strategy, light tracing onto the film included.
 *
 * Options:
 *   mis balance|power|stratified  weighting; stratified is Kollig &
 *       Keller's heuristic (a connection x_i - y_j counts where
 *       G(x_i, y_j) < t and every earlier eye edge had G >= t)
 *   threshold t    for stratified (default from the scene size)
 *   light_paths K  K light paths per pass shared by all pixels (0: one
 *       independent light path per pixel sample)
 *   interleave N   N x N interleaved sets of the K paths
 *   maxdepth N     bounces of the full path
 * Without K, s = 1 resamples a light point per eye vertex (as pbrt-v3).
 * With K > 0 a pixel sample connects its eye path to every path of its
 * set; MIS weights count each strategy's samples (eye 1, connections
 * |set|, light tracing K / pixels). */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "integrators/integrator.h"
#include "transport/connect.h"
#include "transport/light_pool.h"

typedef struct bdpt_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    float threshold;
    cdl_light_pool pool;
    cdl_splats *tile_splats; /* one list per tile (independent mode) or per light path batch */
    int ntiles;
    int at_infinity; /* the scene has distant or infinite lights */
} bdpt_state;

static int bdpt_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    bdpt_state *st = self;
    st->scene = scene;
    st->opt = *opt;
    st->walk.maxdepth = opt->maxdepth;
    st->walk.rr_depth = opt->rr_depth;
    st->threshold = cdl_default_threshold(scene, opt);
    if (cdl_light_paths_check(opt, err))
        return err->code;
    if (st->opt.light_paths == CDL_LIGHT_PATHS_PER_SAMPLE)
        st->opt.light_paths = 0; /* bdpt's default */
    st->walk.env_vertex = 1;
    for (uint32_t i = 0; i < scene->nlights; i++)
        st->at_infinity |= cdl_light_at_infinity(&scene->lights[i]);
    if (st->opt.light_paths && cdl_light_pool_init(&st->pool, st->opt.light_paths, opt->interleave,
                                                   opt->maxdepth, err))
        return err->code;
    int tx = (opt->camera.width + 15) / 16, ty = (opt->camera.height + 15) / 16;
    st->ntiles = tx * ty;
    int nlists = st->ntiles > 1024 ? st->ntiles : 1024;
    st->tile_splats = calloc((size_t)nlists, sizeof(cdl_splats));
    return st->tile_splats ? 0 : cdl_error_set(err, CDL_ERR_SYSTEM, "bdpt", 0, "out of memory");
}

/* All strategies of one eye subpath against one light subpath (the light
 * path's vertices are light[0 .. nl), indices into lvs). */
static cdl_vec3 combine(const bdpt_state *st, const cdl_vertex_store *evs, uint32_t ne,
                        const cdl_vertex_store *lvs, uint32_t l0, uint32_t nl,
                        const cdl_mis_counts *cnt, int with_eye_only, cdl_splats *splats,
                        float splat_scale, cdl_sampler *resample, cdl_vertex_store *tmp,
                        uint64_t *rays)
{
    cdl_connect_ctx cx = {st->scene, &st->opt.camera, st->opt.mis, st->threshold, cnt, 0};
    return cdl_connect_all(&cx, st->opt.maxdepth, evs, ne, lvs, l0, nl, with_eye_only, splats, splat_scale,
                           resample, tmp, rays);
}

static uint64_t bdpt_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1,
                          uint32_t pass, uint64_t *rays)
{
    bdpt_state *st = self;
    const cdl_camera *cam = &st->opt.camera;
    uint32_t room = (uint32_t)st->opt.maxdepth + 3;
    cdl_vertex_store evs, lvs, tvs;
    cdl_vs_init(&evs);
    cdl_vs_init(&lvs);
    cdl_vs_init(&tvs);
    cdl_error err;
    if (cdl_vs_reserve(&evs, room, &err) || cdl_vs_reserve(&lvs, room, &err) ||
        cdl_vs_reserve(&tvs, 1, &err))
        return 0;
    int tile = (y0 / 16) * ((film->width + 15) / 16) + x0 / 16;
    cdl_splats *splats = &st->tile_splats[tile];
    uint64_t bad = 0;
    uint64_t npix = (uint64_t)film->width * (uint64_t)film->height;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            uint64_t pix = (uint64_t)y * (uint64_t)film->width + (uint64_t)x;
            cdl_sampler smp;
            float jx, jy;
            cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed, pix, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            cdl_vs_clear(&evs);
            float fx, fy, fw;
            cdl_camera_sample(cam, x, y, jx, jy, &fx, &fy, &fw);
            uint32_t ne = cdl_trace_eye_subpath(st->scene, cam, fx, fy, &st->walk, &smp, &evs, rays);
            cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
            if (!st->opt.light_paths) {
                cdl_sampler lsmp;
                cdl_sampler_start(&lsmp, st->opt.sampler, st->opt.seed, pix + npix, pass);
                cdl_vs_clear(&lvs);
                uint32_t nl = cdl_trace_light_subpath(st->scene, &st->walk, &lsmp, &lvs, rays);
                cdl_mis_counts cnt = {1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.0f};
                cdl_sampler rsmp;
                cdl_sampler_start(&rsmp, st->opt.sampler, st->opt.seed, pix + 2 * npix, pass);
                L = combine(st, &evs, ne, &lvs, 0, nl, &cnt, 1, splats, 1.0f, &rsmp, &tvs, rays);
            } else {
                const cdl_light_pool *lp = &st->pool;
                uint32_t set = cdl_light_pool_set(lp, x, y), m = cdl_light_pool_set_size(lp, set);
                cdl_mis_counts cnt = {1.0f, (float)lp->k / (float)npix, (float)m, 1.0f, 0.0f, 0.0f};
                /* pure eye paths once, connections to each path of the set */
                L = combine(st, &evs, ne, &lvs, 0, 0, &cnt, 1, NULL, 0.0f, NULL, NULL, rays);
                if (st->at_infinity) { /* their s = 1: light sampling, once */
                    cdl_sampler rsmp;
                    cdl_sampler_start(&rsmp, st->opt.sampler, st->opt.seed, pix + 2 * npix, pass);
                    cdl_connect_ctx cx = {st->scene, cam, st->opt.mis, st->threshold, &cnt, 0};
                    for (uint32_t t = 2; t <= ne && (int)t - 1 <= st->opt.maxdepth; t++)
                        L = cdl_add(L, cdl_connect_resampled(&cx, &evs, t, &rsmp, &tvs, 1, rays));
                }
                cdl_vec3 Lc = cdl_v3(0.0f, 0.0f, 0.0f);
                for (uint32_t k = set; k < lp->k; k += lp->sets)
                    Lc = cdl_add(Lc, combine(st, &evs, ne, &lp->vs, k * lp->stride, lp->len[k], &cnt, 0,
                                             NULL, 0.0f, NULL, NULL, rays));
                if (m)
                    L = cdl_add(L, cdl_scale(Lc, 1.0f / (float)m));
            }
            bad += (uint64_t)cdl_film_add(film, x, y, fw == 1.0f ? L : cdl_scale(L, fw));
        }
    cdl_vs_free(&evs);
    cdl_vs_free(&lvs);
    cdl_vs_free(&tvs);
    return bad;
}

/* Reused light paths: each of the K paths is traced onto the film once
 * per pass (t = 1), scaled to one light path per pixel. */
static void light_trace_pool(bdpt_state *st, cdl_film *film)
{
    const cdl_light_pool *lp = &st->pool;
    uint64_t npix = (uint64_t)film->width * (uint64_t)film->height, rays = 0;
    cdl_mis_counts cnt = {1.0f, (float)lp->k / (float)npix, 1.0f, 1.0f, 0.0f, 0.0f};
    float scale = (float)npix / (float)lp->k;
    int nbatch = 1024;
    cdl_vertex_store none;
    cdl_vs_init(&none);
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : rays)
    for (int b = 0; b < nbatch; b++) {
        for (uint32_t k = (uint32_t)b; k < lp->k; k += (uint32_t)nbatch) {
            uint32_t set = k % lp->sets;
            cdl_mis_counts c = cnt;
            c.connect = (float)cdl_light_pool_set_size(lp, set);
            uint64_t r = 0;
            combine(st, &none, 1, &lp->vs, k * lp->stride, lp->len[k], &c, 0, &st->tile_splats[b], scale,
                    NULL, NULL, &r);
            rays += r;
        }
    }
    film->rays += rays;
}

static int bdpt_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    (void)err;
    bdpt_state *st = self;
    if (st->opt.light_paths) {
        cdl_light_pool_trace(&st->pool, st->scene, &st->walk, st->opt.sampler, st->opt.seed, pass,
                             &film->rays);
    }
    cdl_render_tiles(self, film, pass, bdpt_tile);
    if (st->opt.light_paths && !cdl_cancelled(film->cancel))
        light_trace_pool(st, film);
    int nlists = st->ntiles > 1024 ? st->ntiles : 1024;
    if (cdl_cancelled(film->cancel)) {
        for (int i = 0; i < nlists; i++)
            st->tile_splats[i].n = 0; /* an interrupted pass's splats are incomplete */
        return 0;
    }
    for (int i = 0; i < nlists; i++)
        film->nonfinite += cdl_film_merge_splats(film, &st->tile_splats[i]);
    film->splat_passes++;
    return 0;
}

static void bdpt_destroy(void *self)
{
    bdpt_state *st = self;
    if (st->tile_splats) {
        int nlists = st->ntiles > 1024 ? st->ntiles : 1024;
        for (int i = 0; i < nlists; i++)
            cdl_splats_free(&st->tile_splats[i]);
        free(st->tile_splats);
    }
    if (st->opt.light_paths)
        cdl_light_pool_free(&st->pool);
}

static const cdl_param rows[] = {
    {"mis", CDL_PARAM_CHOICE, "KIND", "power", "weights: balance, power, stratified (Kollig & Keller's heuristic on G "
     "with threshold), or light (light tracing alone: every path through t = 1)",
     .choices = "balance|power|stratified|light", CDL_PARAM_AT(cdl_options, mis)},
};
static const cdl_param_table table = CDL_PARAM_TABLE("Bidirectional path tracing (bdpt; Veach 1997)", rows);
static const cdl_param_table *const tables[] = {&cdl_light_path_table, &table, NULL};

const cdl_integrator_vtbl cdl_bdpt_integrator = {
    .params = tables,
    .name = "bdpt",
    .summary = "bidirectional path tracing, all strategies incl. light tracing; mis, light_paths, interleave",
    .prepare = bdpt_prepare,
    .render_pass = bdpt_render_pass,
    .destroy = bdpt_destroy,
    .self_size = sizeof(bdpt_state),
};
