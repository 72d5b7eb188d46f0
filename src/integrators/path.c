/* path: unidirectional path tracing, the reference of candela.
 *
 * Next-event estimation at every non-delta vertex (one light chosen in
 * proportion to its power through the alias table, one point on it),
 * combined with BSDF sampling by multiple importance sampling with the
 * power heuristic (Veach 1997, ch. 9). Russian roulette on the throughput
 * after opt.rr_depth bounces, survival at least 5 %.
 *
 * Options: maxdepth N  bounces (1 = direct light only), default 64.
 */
#include <float.h>

#include "core/sampler.h"
#include "core/sampler_block.h"
#include "core/sampling.h"
#include "integrators/integrator.h"

typedef struct path_state {
    const cdl_scene *scene;
    cdl_options opt;
} path_state;

static int path_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    (void)err;
    path_state *ps = self;
    ps->scene = scene;
    ps->opt = *opt;
    return 0;
}

/* A path between two rays: where its next ray starts and what it carries. */
typedef struct path_ray {
    cdl_vec3 o, d, beta, L;
    float pdf_prev;
    int specular, depth;
} path_ray;

/* A vertex between its shading and its scattering; the next-event
 * estimate waits there for its shadow ray (shadow = 1). */
typedef struct path_vertex {
    cdl_surface sf;
    cdl_bsdf b;
    cdl_vec3 wo, C; /* C: beta times the light's contribution if visible */
    cdl_vec3 so, sd;
    float stmax, u4, u5, u6;
    uint32_t skip;
    int shadow;
} path_vertex;

/* Direct light at a surface point by light sampling, MIS-weighted
 * against the BSDF having found the same point: added to L, or (defer)
 * left in v->C with the shadow ray that must pass for it to count. */
__attribute__((always_inline)) static inline void next_event(const cdl_scene *s, path_vertex *v, cdl_vec3 beta,
                                                             cdl_vec3 *L, const cdl_vertex_numbers *u,
                                                             int defer, uint64_t *rays)
{
    const cdl_alias *sel = &s->light_select;
    const cdl_surface *sf = &v->sf;
    uint32_t k = cdl_alias_slot(sel, u->u[0]);
    if (!cdl_alias_certain(sel, k))
        k = cdl_alias_take(sel, k, cdl_vertex_number_late(u, 1));
    float pmf = sel->pmf[k];
    const cdl_light *l = &s->lights[k];
    cdl_light_sample ls;
    if (!cdl_light_sample_li(l, sf->p, u->u[2], u->u[3], &ls))
        return;
    float pdf_b;
    cdl_vec3 f = cdl_bsdf_eval_pdf(&v->b, v->wo, ls.wi, 0, &pdf_b);
    if (cdl_is_black(f))
        return;
    (*rays)++;
    if (!defer && !cdl_light_sample_visible(s, l, sf->p, sf->ng, &ls))
        return;
    float pdf_l = ls.pdf * pmf;
    float cos = fabsf(cdl_dot(ls.wi, v->b.frame.n));
    float w = ls.delta ? 1.0f : cdl_power_heuristic(pdf_l, pdf_b);
    cdl_vec3 C = cdl_mul(beta, cdl_scale(cdl_mul(f, ls.Li), cos * w / pdf_l));
    if (!defer) {
        *L = cdl_add(*L, C);
        return;
    }
    v->C = C;
    v->so = cdl_offset(s, sf->p, sf->ng, ls.wi);
    v->sd = ls.wi;
    v->stmax = cdl_shadow_tmax(s, sf->p, ls.dist);
    v->skip = l->type == CDL_LIGHT_SPHERE ? l->prim : UINT32_MAX;
    v->shadow = 1;
}

/* Emission found by following the path (an area light hit, or the
 * infinite light on escape), MIS-weighted against light sampling unless
 * the last bounce was specular. */
static cdl_vec3 emitted(const cdl_scene *s, int32_t light, cdl_vec3 o, cdl_vec3 d, float t,
                        const cdl_surface *sf, int specular, float pdf_prev)
{
    const cdl_light *l = &s->lights[light];
    cdl_vec3 Le = l->type == CDL_LIGHT_INFINITE ? cdl_light_env_Le(l, d)
                                                : cdl_light_Le_uv(l, sf->ng, cdl_neg(d), sf->u, sf->v);
    if (specular || cdl_is_black(Le))
        return Le;
    float pdf_l = s->light_select.pmf[light] * cdl_light_pdf_li(l, o, d, t);
    return cdl_scale(Le, cdl_power_heuristic(pdf_prev, pdf_l));
}

/* The vertex at ray r's hit h (found = 0: it escaped): its emission and
 * its next-event estimate (defer: see next_event). ahead: the numbers
 * its block drew ahead for lane (cdl_sampler_block_start) or NULL. Returns
 * 0 where the path ends. */
__attribute__((always_inline)) static inline int shade(const path_state *ps, path_ray *r, const cdl_hit *h,
                                                       int found, cdl_sampler *smp, const cdl_numbers_ahead *ahead,
                                                       int lane, path_vertex *v, int defer, uint64_t *rays)
{
    const cdl_scene *s = ps->scene;
    v->shadow = 0;
    if (!found) {
        if (s->env_light >= 0)
            r->L = cdl_add(r->L, cdl_mul(r->beta, emitted(s, s->env_light, r->o, r->d, FLT_MAX, NULL,
                                                         r->specular, r->pdf_prev)));
        return 0;
    }
    cdl_surface_at(s, h, &v->sf);
    v->wo = cdl_neg(r->d);
    if (v->sf.light >= 0)
        r->L = cdl_add(r->L, cdl_mul(r->beta, emitted(s, v->sf.light, r->o, r->d, h->t, &v->sf, r->specular,
                                                     r->pdf_prev)));
    if (r->depth >= ps->opt.maxdepth)
        return 0;
    cdl_scene_bsdf(s, &v->sf, &v->b);
    if (!cdl_bsdf_is_delta(&v->b)) {
        cdl_vertex_numbers u;
        if (!ahead || !cdl_numbers_ahead_take(ahead, lane, smp, &u))
            u = cdl_vertex_numbers_draw(smp);
        next_event(s, v, r->beta, &r->L, &u, defer, rays);
        v->u4 = cdl_vertex_number_late(&u, 4);
        v->u5 = u.u[5];
        v->u6 = u.u[6];
    } else {
        v->u4 = cdl_sampler_1d(smp);
        cdl_sampler_2d(smp, &v->u5, &v->u6);
    }
    return 1;
}

/* The next ray from vertex v, with Russian roulette after opt.rr_depth
 * bounces. Returns 0 where the path ends. */
__attribute__((always_inline)) static inline int scatter(const path_state *ps, path_ray *r, const path_vertex *v,
                                                         cdl_sampler *smp)
{
    cdl_scatter bs;
    if (!cdl_bsdf_sample_inline(&v->b, v->wo, v->u4, v->u5, v->u6, 0, &bs))
        return 0;
    r->beta = cdl_mul(r->beta, bs.weight);
    r->specular = bs.delta;
    r->pdf_prev = bs.pdf;
    r->o = cdl_offset(ps->scene, v->sf.p, v->sf.ng, bs.wi);
    r->d = bs.wi;
    if (r->depth + 1 >= ps->opt.rr_depth) {
        float q = cdl_maxf(0.05f, 1.0f - cdl_max3(r->beta));
        if (cdl_sampler_cheap(smp) < q)
            return 0;
        r->beta = cdl_scale(r->beta, 1.0f / (1.0f - q));
    }
    r->depth++;
    return !cdl_is_black(r->beta);
}

/* Vertices whose numbers a block draws ahead in vector lanes. */
enum { PATH_AHEAD = 3 };

/* The rest of path r (lane of a block that drew numbers ahead), one ray
 * at a time. */
static void trace(const path_state *ps, path_ray *r, cdl_sampler *smp, const cdl_numbers_ahead *ahead, int lane,
                  uint64_t *rays)
{
    const cdl_scene *s = ps->scene;
    for (;;) {
        cdl_hit h;
        path_vertex v;
        (*rays)++;
        int found = cdl_intersect(s, r->o, r->d, FLT_MAX, &h);
        if (!shade(ps, r, &h, found, smp, ahead, lane, &v, 0, rays))
            return;
        if (!scatter(ps, r, &v, smp))
            return;
    }
}

/* The tile in blocks of 4x4 pixels. Their camera rays are coherent, and
 * so are the shadow rays of their first vertices (they share the light):
 * both go to Embree as packets. */
static uint64_t path_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1,
                          uint32_t pass, uint64_t *rays)
{
    enum { B = 4 };
    const path_state *ps = self;
    const cdl_camera *cam = &ps->opt.camera;
    uint64_t bad = 0;
    for (int by = y0; by < y1; by += B)
        for (int bx = x0; bx < x1; bx += B) {
            cdl_sampler smp[B * B];
            path_ray r[B * B];
            path_vertex v[B * B];
            cdl_vec3 o[B * B], d[B * B], so[B * B], sd[B * B];
            cdl_hit h[B * B];
            float w[B * B], stmax[B * B];
            uint32_t skip[B * B];
            int px[B * B], py[B * B], lane[B * B], n = 0, m = 0;
            uint8_t found[B * B], live[B * B], blocked[B * B];
            uint64_t stream[B * B];
            cdl_numbers_ahead ahead;
            float jx[B * B], jy[B * B];
            for (int y = by; y < by + B && y < y1; y++)
                for (int x = bx; x < bx + B && x < x1; x++, n++) {
                    stream[n] = (uint64_t)y * film->width + x;
                    px[n] = x;
                    py[n] = y;
                }
            cdl_sampler_block_start(smp, n, ps->opt.sampler, ps->opt.seed, stream, pass, jx, jy, &ahead, PATH_AHEAD);
            for (int k = 0; k < n; k++) {
                float fx, fy;
                cdl_camera_sample(cam, px[k], py[k], jx[k], jy[k], &fx, &fy, &w[k]);
                cdl_camera_gen(cam, fx, fy, &o[k], &d[k]);
                r[k] = (path_ray){o[k], d[k], cdl_v3(1.0f, 1.0f, 1.0f), cdl_v3(0.0f, 0.0f, 0.0f), 0.0f, 1, 0};
            }
            *rays += (uint64_t)n;
            cdl_intersect_packet(ps->scene, n, o, d, h, found);
            for (int k = 0; k < n; k++) {
                live[k] = (uint8_t)shade(ps, &r[k], &h[k], found[k], &smp[k], &ahead, k, &v[k], 1, rays);
                if (live[k] && v[k].shadow) {
                    so[m] = v[k].so;
                    sd[m] = v[k].sd;
                    stmax[m] = v[k].stmax;
                    skip[m] = v[k].skip;
                    lane[m++] = k;
                }
            }
            cdl_occluded_packet(ps->scene, m, so, sd, stmax, skip, blocked);
            for (int j = 0; j < m; j++)
                if (!blocked[j])
                    r[lane[j]].L = cdl_add(r[lane[j]].L, v[lane[j]].C);
            for (int k = 0; k < n; k++) {
                if (live[k] && scatter(ps, &r[k], &v[k], &smp[k]))
                    trace(ps, &r[k], &smp[k], &ahead, k, rays);
                cdl_vec3 L = r[k].L;
                bad += (uint64_t)cdl_film_add(film, px[k], py[k], w[k] == 1.0f ? L : cdl_scale(L, w[k]));
            }
        }
    return bad;
}

static int path_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    (void)err;
    cdl_render_tiles(self, film, pass, path_tile);
    return 0;
}

static void path_destroy(void *self) { (void)self; }

const cdl_integrator_vtbl cdl_path_integrator = {
    .name = "path",
    .summary = "path tracing with next-event estimation and MIS (the reference)",
    .prepare = path_prepare,
    .render_pass = path_render_pass,
    .destroy = path_destroy,
    .self_size = sizeof(path_state),
};
