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

/* Direct light at a surface point by light sampling, MIS-weighted
 * against the BSDF having found the same point. */
static cdl_vec3 next_event(const cdl_scene *s, const cdl_surface *sf, const cdl_bsdf *b,
                           cdl_vec3 wo, const cdl_vertex_numbers *u, uint64_t *rays)
{
    const cdl_alias *sel = &s->light_select;
    uint32_t k = cdl_alias_slot(sel, u->u[0]);
    if (!cdl_alias_certain(sel, k))
        k = cdl_alias_take(sel, k, cdl_vertex_number_late(u, 1));
    float pmf = sel->pmf[k];
    const cdl_light *l = &s->lights[k];
    cdl_light_sample ls;
    if (!cdl_light_sample_li(l, sf->p, u->u[2], u->u[3], &ls))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    float pdf_b;
    cdl_vec3 f = cdl_bsdf_eval_pdf(b, wo, ls.wi, 0, &pdf_b);
    if (cdl_is_black(f))
        return f;
    (*rays)++;
    if (!cdl_light_sample_visible(s, l, sf->p, sf->ng, &ls))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    float pdf_l = ls.pdf * pmf;
    float cos = fabsf(cdl_dot(ls.wi, b->frame.n));
    float w = ls.delta ? 1.0f : cdl_power_heuristic(pdf_l, pdf_b);
    return cdl_scale(cdl_mul(f, ls.Li), cos * w / pdf_l);
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

static cdl_vec3 radiance(const path_state *ps, cdl_vec3 o, cdl_vec3 d, cdl_sampler *smp,
                         uint64_t *rays)
{
    const cdl_scene *s = ps->scene;
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f), beta = cdl_v3(1.0f, 1.0f, 1.0f);
    int specular = 1;
    float pdf_prev = 0.0f;
    for (int depth = 0;; depth++) {
        cdl_hit h;
        (*rays)++;
        if (!cdl_intersect(s, o, d, FLT_MAX, &h)) {
            if (s->env_light >= 0)
                L = cdl_add(L, cdl_mul(beta, emitted(s, s->env_light, o, d, FLT_MAX, NULL,
                                                     specular, pdf_prev)));
            break;
        }
        cdl_surface sf;
        cdl_surface_at(s, &h, &sf);
        cdl_vec3 wo = cdl_neg(d);
        if (sf.light >= 0)
            L = cdl_add(L, cdl_mul(beta, emitted(s, sf.light, o, d, h.t, &sf, specular, pdf_prev)));
        if (depth >= ps->opt.maxdepth)
            break;
        cdl_bsdf b;
        cdl_scene_bsdf(s, &sf, &b);
        float u4, u5, u6;
        if (!cdl_bsdf_is_delta(&b)) {
            cdl_vertex_numbers u = cdl_vertex_numbers_draw(smp);
            L = cdl_add(L, cdl_mul(beta, next_event(s, &sf, &b, wo, &u, rays)));
            u4 = cdl_vertex_number_late(&u, 4);
            u5 = u.u[5];
            u6 = u.u[6];
        } else {
            u4 = cdl_sampler_1d(smp);
            cdl_sampler_2d(smp, &u5, &u6);
        }
        cdl_scatter bs;
        if (!cdl_bsdf_sample_inline(&b, wo, u4, u5, u6, 0, &bs))
            break;
        beta = cdl_mul(beta, bs.weight);
        specular = bs.delta;
        pdf_prev = bs.pdf;
        o = cdl_offset(s, sf.p, sf.ng, bs.wi);
        d = bs.wi;
        if (depth + 1 >= ps->opt.rr_depth) {
            float q = cdl_maxf(0.05f, 1.0f - cdl_max3(beta));
            if (cdl_sampler_cheap(smp) < q)
                break;
            beta = cdl_scale(beta, 1.0f / (1.0f - q));
        }
        if (cdl_is_black(beta))
            break;
    }
    return L;
}

static uint64_t path_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1,
                          uint32_t pass, uint64_t *rays)
{
    const path_state *ps = self;
    const cdl_camera *cam = &ps->opt.camera;
    uint64_t bad = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            cdl_sampler smp;
            float jx, jy;
            cdl_sampler_start(&smp, ps->opt.sampler, ps->opt.seed, (uint64_t)y * film->width + x, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            float fx, fy, fw;
            cdl_vec3 o, d;
            cdl_camera_sample(cam, x, y, jx, jy, &fx, &fy, &fw);
            cdl_camera_gen(cam, fx, fy, &o, &d);
            cdl_vec3 L = radiance(ps, o, d, &smp, rays);
            bad += (uint64_t)cdl_film_add(film, x, y, fw == 1.0f ? L : cdl_scale(L, fw));
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
