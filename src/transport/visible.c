#include "transport/visible.h"

#include <float.h>

#include "scene/light.h"

int cdl_find_visible(const cdl_scene *s, cdl_vec3 o, cdl_vec3 d, int maxdepth, cdl_sampler *smp, uint64_t *rays,
                     cdl_visible *v)
{
    v->L = cdl_v3(0.0f, 0.0f, 0.0f);
    v->beta = cdl_v3(1.0f, 1.0f, 1.0f);
    v->dist = 0.0f;
    for (int depth = 0;; depth++) {
        cdl_hit h;
        (*rays)++;
        if (!cdl_intersect(s, o, d, FLT_MAX, &h)) {
            v->depth = depth; /* the sky met after `depth` specular bounces */
            if (s->env_light >= 0)
                v->L = cdl_add(v->L, cdl_mul(v->beta, cdl_light_env_Le(&s->lights[s->env_light], d)));
            return 0;
        }
        v->dist += h.t;
        cdl_surface_at(s, &h, &v->sf);
        cdl_scene_bsdf(s, &v->sf, &v->b);
        v->wo = cdl_neg(d);
        v->depth = depth;
        if (v->sf.light >= 0)
            v->L = cdl_add(v->L, cdl_mul(v->beta, cdl_light_Le_uv(&s->lights[v->sf.light], v->sf.ng, v->wo, v->sf.u, v->sf.v)));
        if (depth >= maxdepth)
            return 0;
        if (!cdl_bsdf_is_delta(&v->b)) /* the back of a one-sided surface reflects nothing */
            return !(v->b.one_sided && cdl_dot(v->wo, v->sf.ng) <= 0.0f);
        cdl_scatter sc;
        float u0 = cdl_sampler_1d(smp), u1, u2;
        cdl_sampler_2d(smp, &u1, &u2);
        if (!cdl_bsdf_sample(&v->b, v->wo, u0, u1, u2, 0, &sc))
            return 0;
        v->beta = cdl_mul(v->beta, sc.weight);
        if (cdl_is_black(v->beta))
            return 0;
        o = cdl_offset(s, v->sf.p, v->sf.ng, sc.wi);
        d = sc.wi;
    }
}
