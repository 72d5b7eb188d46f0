/* rigi and ir: robust instant global illumination (Kollig & Keller 2004,
 * §2) and classic instant radiosity (Keller 1997) on the same point lights.
 *
 * Point lights are the vertices of K light paths per pass (the shared
 * light pool; y_0 on the emitters included), split into N x N interleaved
 * sets (light_paths K, interleave N; default 256 in 4 x 4 sets, 16 point-light
 * paths per pixel sample, about 1 s per pass at 512 x 512 on 2 cores), or
 * one independent light path per pixel sample (light_paths sample: the
 * "pure Monte Carlo" left column of the report's Figure 6).
 *
 * rigi: at each eye vertex x_i, a shadow ray goes only to point lights
 * y_j with G(x_i, y_j) < t (eq. 2-3); one BSDF-sampled ray is traced, clipped
 * at r <= sqrt(cos / t) (§4.1, "cheaper rays"), and the eye path continues
 * only if G(x_i, x_{i+1}) >= t; emitters hit by a continued path add L_e.
 * At specular vertices the path always continues (no connection is
 * possible there). This is bdpt with the stratification heuristic, so it
 * is unbiased. strata distance thresholds 1 / d^2 instead of G (Fig. 2c).
 * Shadow rays towards one point light are traced together, as a bundle
 * from all eye vertices of a 16 x 16 tile (Embree ray stream).
 *
 * ir: the first diffuse eye vertex connects to every point light of its
 * set with G clamped at clamp (Fig. 2a): biased, darker in corners.
 *
 * Lights at infinity (distant, infinite): their light paths start on the
 * disk covering the scene, which is no point light; their vertices from
 * the first hit on are. Their direct light comes by light sampling at every
 * eye vertex instead (G to a light at infinity is 0 < t: the light-sampling
 * stratum of rigi, whole), and eye rays that leave the scene see them only
 * from the camera or after specular bounces, as emitters. */
#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "integrators/integrator.h"
#include "transport/connect.h"
#include "transport/light_pool.h"
#include "transport/light_select.h"

typedef struct rigi_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    float t;      /* threshold (rigi) or clamp (ir) */
    int clamped;  /* ir */
    int clip;     /* §4.1 clipping is only safe without specular surfaces */
    int per_sample; /* an independent light path per pixel sample, no pool */
    int at_infinity; /* the scene has distant or infinite lights */
    cdl_light_pool pool;
} rigi_state;


static int prepare(void *self, const cdl_scene *scene, const cdl_options *opt, int clamped,
                   cdl_error *err)
{
    rigi_state *st = self;
    st->scene = scene;
    st->opt = *opt;
    st->clamped = clamped;
    st->walk.maxdepth = opt->maxdepth;
    st->walk.rr_depth = opt->rr_depth;
    /* A path must pass specular vertices whatever G is; a clipped ray could
     * stop short of a distant mirror, so scenes with one trace full rays. */
    st->clip = 1;
    for (uint32_t i = 0; i < scene->nmats; i++)
        if (cdl_mat_is_delta(scene->mats[i].type))
            st->clip = 0;
    if (clamped)
        st->t = opt->clamp > 0.0f ? opt->clamp : cdl_default_threshold(scene, opt);
    else
        st->t = cdl_default_threshold(scene, opt);
    st->at_infinity = 0;
    for (uint32_t i = 0; i < scene->nlights; i++)
        st->at_infinity |= cdl_light_at_infinity(&scene->lights[i]);
    if (cdl_light_paths_check(opt, err))
        return err->code;
    st->per_sample = opt->light_paths == CDL_LIGHT_PATHS_PER_SAMPLE;
    if (st->per_sample)
        return 0;
    uint32_t k = opt->light_paths ? opt->light_paths : 256;
    uint32_t n = opt->light_paths ? opt->interleave : 4;
    if (cdl_light_pool_init(&st->pool, k, n, opt->maxdepth, err))
        return err->code;
    return 0;
}

static int rigi_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    return prepare(self, scene, opt, 0, err);
}

static int ir_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    return prepare(self, scene, opt, 1, err);
}

/* The stratification function: G, or 1 / d^2 for strata distance. */
static float strata_g(const rigi_state *st, cdl_vec3 pa, cdl_vec3 na, cdl_vec3 pb, cdl_vec3 nb)
{
    if (!st->opt.strata_distance)
        return cdl_geometry(pa, na, pb, nb);
    cdl_vec3 d = cdl_sub(pb, pa);
    float d2 = cdl_dot(d, d);
    return d2 > 0.0f ? 1.0f / d2 : FLT_MAX;
}

/* One candidate shadow ray of a tile: eye vertex -> point light. */
typedef struct candidate {
    uint32_t pixel;
    uint32_t depth; /* eye path length at the connecting vertex, for aov strata */
    cdl_vec3 c; /* contribution if unoccluded */
    cdl_vec3 o, d;
    float tmax;
} candidate;

typedef struct tile_work {
    cdl_vec3 strata[256][CDL_STRATA]; /* per pixel, per eye path length */
    float plen[256];                  /* eye vertices per pixel */
    cdl_vertex_store eye;  /* eye vertices of the tile's pixels */
    uint32_t *eye_pixel;   /* pixel of each eye vertex */
    candidate *cand;
    uint32_t ncand, cap_cand;
    cdl_vec3 *bo, *bd;
    float *bt;
    uint8_t *blocked;
    uint32_t cap_bundle;
} tile_work;

static int grow_cand(tile_work *w)
{
    uint32_t cap = w->cap_cand ? 2 * w->cap_cand : 4096;
    candidate *c = realloc(w->cand, sizeof(candidate) * cap);
    if (!c)
        return -1;
    w->cand = c;
    w->cap_cand = cap;
    return 0;
}

/* The eye path of one pixel sample; appends its non-delta vertices to
 * w->eye and returns the emission it collects (Le at x_1, and at later
 * vertices reached by continued paths). */
static cdl_vec3 eye_path(const rigi_state *st, cdl_sampler *smp, cdl_vec3 o, cdl_vec3 d,
                         uint32_t pixel, tile_work *w, uint64_t *rays)
{
    const cdl_scene *s = st->scene;
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f), beta = cdl_v3(1.0f, 1.0f, 1.0f);
    float tmax = FLT_MAX;
    int stratum = 0;
    int prev_delta = 1; /* the camera edge is never thresholded */
    cdl_vec3 prev_p = o, prev_n = cdl_v3(0.0f, 0.0f, 0.0f);
    for (int depth = 0;; depth++) {
        cdl_hit h;
        (*rays)++;
        if (!cdl_intersect(s, o, d, tmax, &h)) {
            /* beyond the clip radius: G < t, the point lights cover it; a
             * ray that leaves the scene from the camera or a specular
             * bounce sees the lights at infinity (no connection there) */
            if (prev_delta && tmax == FLT_MAX && s->env_light >= 0) {
                cdl_vec3 e = cdl_mul(beta, cdl_light_env_Le(&s->lights[s->env_light], d));
                L = cdl_add(L, e);
                stratum = depth < CDL_STRATA ? depth : CDL_STRATA - 1;
                w->strata[pixel][stratum] = cdl_add(w->strata[pixel][stratum], e);
            }
            return L;
        }
        cdl_surface sf;
        cdl_surface_at(s, &h, &sf);
        cdl_bsdf b;
        cdl_scene_bsdf(s, &sf, &b);
        int delta = cdl_bsdf_is_delta(&b);
        /* §2b: continue only if G(x_i, x_i+1) >= t; specular ends exempt */
        if (!prev_delta && !delta && !st->clamped &&
            strata_g(st, prev_p, prev_n, sf.p, sf.ng) < st->t)
            return L;
        cdl_vec3 wo = cdl_neg(d);
        stratum = depth < CDL_STRATA ? depth : CDL_STRATA - 1;
        w->plen[pixel] = (float)(depth + 1);
        if (sf.light >= 0 && (depth == 0 || !st->clamped || prev_delta)) {
            cdl_vec3 e = cdl_mul(beta, cdl_light_Le_uv(&s->lights[sf.light], sf.ng, wo, sf.u, sf.v));
            L = cdl_add(L, e);
            w->strata[pixel][stratum] = cdl_add(w->strata[pixel][stratum], e);
        }
        if (!delta) {
            uint32_t i = w->eye.n;
            if (cdl_vs_reserve(&w->eye, i + 1, NULL))
                return L;
            w->eye.n++;
            w->eye.p[i] = sf.p;
            w->eye.ng[i] = sf.ng;
            w->eye.ns[i] = cdl_dot(sf.ns, sf.ng) < 0.0f ? cdl_neg(sf.ns) : sf.ns;
            w->eye.wi[i] = wo;
            w->eye.beta[i] = beta;
            w->eye.u[i] = sf.u;
            w->eye.v[i] = sf.v;
            w->eye.kdh[i] = sf.kdh;
            w->eye.ts[i] = sf.ts;
            w->eye.nb[i] = sf.nb;
            w->eye.mat[i] = sf.mat;
            w->eye.light[i] = sf.light;
            w->eye.flags[i] = 0;
            w->eye.depth[i] = (uint16_t)depth; /* < maxdepth + 1 <= 1025 */
            w->eye_pixel = realloc(w->eye_pixel, sizeof(uint32_t) * w->eye.cap);
            if (!w->eye_pixel)
                return L;
            w->eye_pixel[i] = pixel;
            if (st->at_infinity && depth < st->opt.maxdepth) {
                cdl_vec3 e = cdl_mul(beta, cdl_direct_light_infinite(s, &sf, &b, wo, smp, rays));
                L = cdl_add(L, e);
                w->strata[pixel][stratum] = cdl_add(w->strata[pixel][stratum], e);
            }
            if (st->clamped)
                return L; /* ir: the point lights carry all further bounces */
        }
        if (depth >= st->opt.maxdepth)
            return L;
        cdl_scatter sc;
        float u0 = cdl_sampler_1d(smp), u1, u2;
        cdl_sampler_2d(smp, &u1, &u2);
        if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc))
            return L;
        beta = cdl_mul(beta, sc.weight);
        if (depth + 1 >= st->opt.rr_depth) {
            float q = cdl_maxf(0.05f, 1.0f - cdl_max3(beta));
            if (cdl_sampler_cheap(smp) < q)
                return L;
            beta = cdl_scale(beta, 1.0f / (1.0f - q));
        }
        /* §4.1: beyond sqrt(cos / t) the next vertex has G < t anyway */
        tmax = FLT_MAX;
        if (!delta && !st->clamped && st->clip) {
            float c = fabsf(cdl_dot(sc.wi, sf.ng));
            tmax = st->opt.strata_distance ? sqrtf(1.0f / st->t) : sqrtf(c / st->t);
        }
        prev_delta = delta;
        prev_p = sf.p;
        prev_n = sf.ng;
        o = cdl_offset(s, sf.p, sf.ng, sc.wi);
        d = sc.wi;
    }
}

/* All point lights of one interleaved set against the tile's eye vertices
 * of that set: candidates with G < t (ir: every one, G clamped), then one
 * shadow-ray bundle per point light. */
static void connect_set(const rigi_state *st, const cdl_light_pool *lp, tile_work *w, uint32_t set,
                        const uint32_t *verts, uint32_t nverts, const int *pix_of, cdl_vec3 *acc,
                        uint64_t *rays)
{
    const cdl_vertex_store *lv = &lp->vs;
    uint32_t m = cdl_light_pool_set_size(lp, set);
    if (!m || !nverts)
        return;
    float inv_m = 1.0f / (float)m;
    cdl_connect_ctx cx = {st->scene, &st->opt.camera, CDL_MIS_STRATIFIED, st->t, NULL, 0};
    for (uint32_t k = set; k < lp->k; k += lp->sets) {
        uint32_t base = k * lp->stride;
        for (uint32_t j = 0; j < lp->len[k]; j++) {
            uint32_t y = base + j;
            if (lv->flags[y] & CDL_V_DELTA)
                continue; /* specular light vertices are not point lights */
            if (j == 0 && cdl_light_at_infinity(&st->scene->lights[lv->light[y]]))
                continue; /* light sampling covers lights at infinity */
            int delta_pos = (lv->flags[y] & CDL_V_DELTA_LIGHT) != 0;
            cdl_vec3 yp = lv->p[y], yn = cdl_vertex_normal(lv, y);
            cdl_vec3 yfrom = j > 0 ? lv->p[y - 1] : yp;
            uint32_t skip = UINT32_MAX;
            if (j == 0 && st->scene->lights[lv->light[y]].type == CDL_LIGHT_SPHERE)
                skip = st->scene->lights[lv->light[y]].prim;
            w->ncand = 0;
            /* maxdepth counts the whole path: x_1 .. x_i then y_j .. y_1 */
            int room = st->opt.maxdepth - (int)lv->depth[y] - 1;
            for (uint32_t a = 0; a < nverts; a++) {
                uint32_t e = verts[a];
                if ((int)w->eye.depth[e] > room)
                    continue;
                cdl_vec3 ep = w->eye.p[e];
                if (!st->clamped && !delta_pos && strata_g(st, ep, w->eye.ng[e], yp, yn) >= st->t)
                    continue; /* §2a: this stratum belongs to the continued eye path */
                cdl_vec3 fe = cdl_vertex_f(&cx, &w->eye, e, cdl_madd(ep, w->eye.wi[e], 1.0f), yp, 0);
                if (cdl_is_black(fe))
                    continue;
                cdl_vec3 fl = cdl_vertex_f(&cx, lv, y, yfrom, ep, 1);
                if (cdl_is_black(fl))
                    continue;
                /* G with shading cosines, as bdpt's connections; ir clamps
                 * that term itself (Fig. 2a), so smooth shading adds no bias */
                float Gs = cdl_geometry(ep, w->eye.ns[e], yp, delta_pos ? yn : lv->ns[y]);
                if (st->clamped && Gs > st->t)
                    Gs = st->t;
                cdl_vec3 c = cdl_scale(cdl_mul(cdl_mul(w->eye.beta[e], fe), cdl_mul(lv->beta[y], fl)),
                                       Gs * inv_m);
                if (cdl_is_black(c) || !cdl_is_finite3(c))
                    continue;
                if (w->ncand == w->cap_cand && grow_cand(w))
                    return;
                candidate *cd = &w->cand[w->ncand++];
                cd->pixel = (uint32_t)pix_of[e];
                cd->depth = w->eye.depth[e] < CDL_STRATA ? w->eye.depth[e] : CDL_STRATA - 1;
                cd->c = c;
                cdl_vec3 dd = cdl_sub(yp, ep);
                cd->o = cdl_offset(st->scene, ep, w->eye.ng[e], dd);
                cdl_vec3 end = cdl_is_black(yn) ? yp : cdl_offset(st->scene, yp, yn, cdl_neg(dd));
                cdl_vec3 de = cdl_sub(end, cd->o);
                cd->tmax = cdl_length(de);
                cd->d = cd->tmax > 0.0f ? cdl_scale(de, 1.0f / cd->tmax) : cdl_v3(0.0f, 0.0f, 1.0f);
            }
            if (!w->ncand)
                continue;
            if (w->ncand > w->cap_bundle) {
                w->cap_bundle = w->cap_cand;
                w->bo = realloc(w->bo, sizeof(cdl_vec3) * w->cap_bundle);
                w->bd = realloc(w->bd, sizeof(cdl_vec3) * w->cap_bundle);
                w->bt = realloc(w->bt, sizeof(float) * w->cap_bundle);
                w->blocked = realloc(w->blocked, w->cap_bundle);
                if (!w->bo || !w->bd || !w->bt || !w->blocked)
                    return;
            }
            for (uint32_t a = 0; a < w->ncand; a++) {
                w->bo[a] = w->cand[a].o;
                w->bd[a] = w->cand[a].d;
                w->bt[a] = w->cand[a].tmax;
            }
            *rays += w->ncand;
            if (st->opt.single_shadow_rays) {
                for (uint32_t a = 0; a < w->ncand; a++)
                    w->blocked[a] = (uint8_t)cdl_occluded_skip(st->scene, w->bo[a], w->bd[a], w->bt[a], skip);
            } else {
                cdl_occluded_bundle(st->scene, w->ncand, w->bo, w->bd, w->bt, skip, w->blocked);
            }
            for (uint32_t a = 0; a < w->ncand; a++)
                if (!w->blocked[a]) {
                    const candidate *cd = &w->cand[a];
                    acc[cd->pixel] = cdl_add(acc[cd->pixel], cd->c);
                    w->strata[cd->pixel][cd->depth] = cdl_add(w->strata[cd->pixel][cd->depth], cd->c);
                }
        }
    }
}

static uint64_t rigi_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1,
                          uint32_t pass, uint64_t *rays)
{
    rigi_state *st = self;
    const cdl_camera *cam = &st->opt.camera;
    int tw = x1 - x0, th = y1 - y0, np = tw * th;
    /* on the heap: the per-pixel strata make it too large for a stack */
    tile_work *w = calloc(1, sizeof(tile_work));
    if (!w)
        return 0;
    cdl_vs_init(&w->eye);
    cdl_vec3 acc[256];
    int pix_sets[256];
    /* light_paths sample: the tile's own pool, pixel p's path in set p */
    cdl_light_pool local;
    const cdl_light_pool *lp = &st->pool;
    if (st->per_sample) {
        if (cdl_light_pool_init(&local, (uint32_t)np, 1, st->opt.maxdepth, NULL)) {
            cdl_light_pool_free(&local);
            free(w);
            return 0;
        }
        local.sets = (uint32_t)np;
        lp = &local;
    }
    /* eye paths of every pixel first, so that shadow rays can be bundled */
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            int p = (y - y0) * tw + (x - x0);
            cdl_sampler smp;
            float jx, jy;
            cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed,
                              (uint64_t)y * (uint64_t)film->width + (uint64_t)x, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            acc[p] = eye_path(st, &smp, cam->eye, cdl_camera_ray(cam, (float)x + jx, (float)y + jy),
                              (uint32_t)p, w, rays);
            if (!st->per_sample) {
                pix_sets[p] = (int)cdl_light_pool_set(&st->pool, x, y);
            } else {
                /* seeded as bdpt's independent light paths */
                uint64_t pix = (uint64_t)y * (uint64_t)film->width + (uint64_t)x;
                uint64_t npix = (uint64_t)film->width * (uint64_t)film->height;
                cdl_sampler lsmp;
                cdl_sampler_start(&lsmp, st->opt.sampler, st->opt.seed, pix + npix, pass);
                cdl_vertex_store view = local.vs;
                view.n = (uint32_t)p * local.stride;
                local.len[p] = cdl_trace_light_subpath(st->scene, &st->walk, &lsmp, &view, rays);
                pix_sets[p] = p;
            }
        }
    /* group the eye vertices by interleaved set */
    uint32_t nv = w->eye.n;
    uint32_t *order = malloc(sizeof(uint32_t) * (nv ? nv : 1));
    int *pix_of = malloc(sizeof(int) * (nv ? nv : 1));
    if (order && pix_of) {
        for (uint32_t e = 0; e < nv; e++)
            pix_of[e] = (int)w->eye_pixel[e];
        for (uint32_t set = 0; set < lp->sets; set++) {
            uint32_t n = 0;
            for (uint32_t e = 0; e < nv; e++)
                if ((uint32_t)pix_sets[pix_of[e]] == set)
                    order[n++] = e;
            connect_set(st, lp, w, set, order, n, pix_of, acc, rays);
        }
    }
    uint64_t bad = 0;
    int a_len = cdl_film_find_aov(film, "pathlength"), a_str = cdl_film_find_aov(film, "strata1");
    for (int p = 0; p < np; p++) {
        int x = x0 + p % tw, y = y0 + p / tw;
        size_t pi = (size_t)y * (size_t)film->width + (size_t)x;
        bad += (uint64_t)cdl_film_add(film, x, y, acc[p]);
        if (a_len >= 0)
            film->aovs[a_len].sum[pi] += w->plen[p];
        for (int k = 0; a_str >= 0 && k < CDL_STRATA; k++) {
            double *d = film->aovs[a_str + k].sum + 3 * pi;
            d[0] += w->strata[p][k].x;
            d[1] += w->strata[p][k].y;
            d[2] += w->strata[p][k].z;
        }
    }
    free(order);
    free(pix_of);
    if (st->per_sample)
        cdl_light_pool_free(&local);
    cdl_vs_free(&w->eye);
    free(w->eye_pixel);
    free(w->cand);
    free(w->bo);
    free(w->bd);
    free(w->bt);
    free(w->blocked);
free(w);
    return bad;
}

static int rigi_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    (void)err;
    rigi_state *st = self;
    if (!st->per_sample)
        cdl_light_pool_trace(&st->pool, st->scene, &st->walk, st->opt.sampler, st->opt.seed, pass, &film->rays);
    cdl_render_tiles(self, film, pass, rigi_tile);
    return 0;
}

static void rigi_destroy(void *self)
{
    rigi_state *st = self;
    cdl_light_pool_free(&st->pool);
}

static const double aov_bits[] = {CDL_AOV_PATHLENGTH, CDL_AOV_STRATA};
static const cdl_param rigi_rows[] = {
    {"strata", CDL_PARAM_CHOICE, "KIND", "geometry", "geometry (threshold G) or distance (threshold 1 / d^2, Fig. 2c)",
     .choices = "geometry|distance", CDL_PARAM_AT(cdl_options, strata_distance)},
    {"aov", CDL_PARAM_CHOICE, "NAME", "", "extra EXR layers, repeatable: pathlength (average eye path length, Fig. 4) "
     "or strata (the contribution of each eye path length as layers strata1..strata8, Fig. 5)",
     .choices = "pathlength|strata", .values = aov_bits, .flags = CDL_PARAM_BITS, CDL_PARAM_AT(cdl_options, aov)},
};
static const cdl_param ir_rows[] = {
    {"clamp", CDL_PARAM_FLOAT, "c", "", "clamp G at c (default: the threshold, 1 / (0.15 d)^2 for the scene's "
     "diagonal d)", 1e-12, 1e12, CDL_PARAM_AT(cdl_options, clamp)},
};
static const cdl_param_table rigi_table = CDL_PARAM_TABLE("Robust instant GI (rigi; Kollig & Keller 2004)", rigi_rows);
static const cdl_param_table ir_table = CDL_PARAM_TABLE("Instant radiosity (ir; Keller 1997)", ir_rows);
static const cdl_param_table *const rigi_tables[] = {&cdl_light_path_table, &cdl_shadow_table, &rigi_table, NULL};
static const cdl_param_table *const ir_tables[] = {&cdl_light_path_table, &cdl_shadow_table, &ir_table, NULL};

const cdl_integrator_vtbl cdl_rigi_integrator = {
    .params = rigi_tables,
    .name = "rigi",
    .summary = "robust instant GI (Kollig & Keller 2004): point lights below G < t, eye path beyond",
    .prepare = rigi_prepare,
    .render_pass = rigi_render_pass,
    .destroy = rigi_destroy,
    .self_size = sizeof(rigi_state),
};

const cdl_integrator_vtbl cdl_ir_integrator = {
    .params = ir_tables,
    .name = "ir",
    .summary = "instant radiosity (Keller 1997), G clamped at clamp (biased)",
    .prepare = ir_prepare,
    .render_pass = rigi_render_pass,
    .destroy = rigi_destroy,
    .self_size = sizeof(rigi_state),
};
