#include "transport/light_select.h"

#include <float.h>
#include <stdlib.h>

int cdl_lcon_scratch_init(cdl_lcon_scratch *sc, uint32_t nlights)
{
    sc->mark = calloc(nlights ? nlights : 1, 1);
    sc->ids = malloc(sizeof(uint32_t) * (nlights ? nlights : 1));
    if (sc->mark && sc->ids)
        return 0;
    cdl_lcon_scratch_free(sc);
    return -1;
}

void cdl_lcon_scratch_free(cdl_lcon_scratch *sc)
{
    free(sc->mark);
    free(sc->ids);
    sc->mark = NULL;
    sc->ids = NULL;
}

typedef struct lcon_ctx {
    const cdl_photon_map *m;
    cdl_lcon_scratch *sc;
    uint32_t n;
} lcon_ctx;

static void visit(void *ctx, uint32_t point, float d2)
{
    (void)d2;
    lcon_ctx *c = ctx;
    uint32_t l = cdl_photon_light(&c->m->ph[point]);
    if (l != CDL_PH_NO_LIGHT && !c->sc->mark[l]) {
        c->sc->mark[l] = 1;
        c->sc->ids[c->n++] = l;
    }
}

uint32_t cdl_lcon_query(const cdl_scene *s, const cdl_photon_map *direct, cdl_vec3 x, float r2,
                        cdl_lcon_scratch *sc)
{
    lcon_ctx c = {direct, sc, 0};
    for (uint32_t l = 0; l < s->nlights; l++)
        if (cdl_light_at_infinity(&s->lights[l]) ||
            l >= CDL_PH_NO_LIGHT) {
            sc->mark[l] = 1;
            sc->ids[c.n++] = l;
        }
    if (direct->n && direct->built)
        cdl_kd_ball(&direct->kd, x, r2, visit, &c);
    for (uint32_t i = 0; i < c.n; i++)
        sc->mark[sc->ids[i]] = 0;
    /* insertion sort: L_con is small, and the rest is indexed through it */
    for (uint32_t i = 1; i < c.n; i++) {
        uint32_t v = sc->ids[i], j = i;
        for (; j > 0 && sc->ids[j - 1] > v; j--)
            sc->ids[j] = sc->ids[j - 1];
        sc->ids[j] = v;
    }
    return c.n;
}

cdl_vec3 cdl_sample_light(const cdl_scene *s, uint32_t li, const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo,
                          cdl_sampler *smp, uint64_t *rays)
{
    const cdl_light *l = &s->lights[li];
    float u1, u2;
    cdl_sampler_2d(smp, &u1, &u2);
    cdl_light_sample ls;
    if (!cdl_light_sample_li(l, sf->p, u1, u2, &ls) || !(ls.pdf > 0.0f))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_vec3 f = cdl_bsdf_eval(b, wo, ls.wi, 0);
    if (cdl_is_black(f))
        return f;
    (*rays)++;
    if (!cdl_light_sample_visible(s, l, sf->p, sf->ng, &ls))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    float cos = fabsf(cdl_dot(ls.wi, b->frame.n));
    return cdl_scale(cdl_mul(f, ls.Li), cos / ls.pdf);
}

cdl_vec3 cdl_direct_light_infinite(const cdl_scene *s, const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo,
                                   cdl_sampler *smp, uint64_t *rays)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = 0; i < s->nlights; i++)
        if (cdl_light_at_infinity(&s->lights[i]))
            L = cdl_add(L, cdl_sample_light(s, i, sf, b, wo, smp, rays));
    return L;
}

cdl_vec3 cdl_direct_light(const cdl_scene *s, const cdl_direct_cfg *cfg, cdl_lcon_scratch *sc,
                          const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo, cdl_sampler *smp,
                          uint64_t *rays, uint32_t *nlcon)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t S = cfg->shadow_rays ? cfg->shadow_rays : 1;
    *nlcon = 0;
    if (!s->nlights || cfg->kind == CDL_DIRECT_NONE)
        return L;
    if (cfg->kind == CDL_DIRECT_POWER) {
        for (uint32_t i = 0; i < S; i++) {
            float us, ua, pmf;
            cdl_sampler_2d(smp, &us, &ua);
            uint32_t li = cdl_alias_sample(&s->light_select, us, ua, &pmf);
            if (pmf > 0.0f)
                L = cdl_add(L, cdl_scale(cdl_sample_light(s, li, sf, b, wo, smp, rays), 1.0f / pmf));
        }
        return cdl_scale(L, 1.0f / (float)S);
    }
    /* Fixed sampler dimensions per (light, ray), so that a light's samples
     * at a pixel form one low-discrepancy sequence over the passes, and
     * later dimensions start at the same place for every pixel. */
    uint32_t base = smp->dim, stride = S + 1;
    uint32_t n = cdl_lcon_query(s, cfg->direct, sf->p, cfg->r2, sc);
    *nlcon = n;
    const float *pw = s->light_select.pmf;
    float W = 0.0f;
    for (uint32_t j = 0; j < n; j++)
        W += pw[sc->ids[j]];
    if (n && W > 0.0f) {
        if (S >= n) {
            /* every light of L_con gets n_j >= 1 rays, about S in proportion to power */
            for (uint32_t j = 0; j < n; j++) {
                uint32_t nj = (uint32_t)((float)S * pw[sc->ids[j]] / W + 0.5f);
                nj = nj ? nj : 1;
                cdl_vec3 Lj = cdl_v3(0.0f, 0.0f, 0.0f);
                for (uint32_t r = 0; r < nj; r++) {
                    smp->dim = base + 2 + sc->ids[j] * stride + (r < stride ? r : stride - 1);
                    Lj = cdl_add(Lj, cdl_sample_light(s, sc->ids[j], sf, b, wo, smp, rays));
                }
                L = cdl_add(L, cdl_scale(Lj, 1.0f / (float)nj));
            }
        } else {
            /* fewer rays than lights: S lights drawn in proportion to power */
            for (uint32_t r = 0; r < S; r++) {
                smp->dim = base + 2 + 2 * r;
                float u = cdl_sampler_1d(smp) * W, acc = 0.0f;
                uint32_t j = 0;
                for (; j + 1 < n; j++) {
                    acc += pw[sc->ids[j]];
                    if (u < acc)
                        break;
                }
                float pmf = pw[sc->ids[j]] / W;
                if (pmf > 0.0f)
                    L = cdl_add(L, cdl_scale(cdl_sample_light(s, sc->ids[j], sf, b, wo, smp, rays),
                                             1.0f / (pmf * (float)S)));
            }
        }
    }
    uint32_t rest = s->nlights - n;
    if (cfg->kind == CDL_DIRECT_LCON && rest) {
        /* one ray to a uniformly chosen light outside L_con, scaled by |rest| */
        smp->dim = base;
        uint32_t r = (uint32_t)(cdl_sampler_1d(smp) * (float)rest);
        r = r < rest ? r : rest - 1;
        for (uint32_t j = 0; j < n && sc->ids[j] <= r; j++)
            r++; /* the r-th index not in the sorted L_con */
        L = cdl_add(L, cdl_scale(cdl_sample_light(s, r, sf, b, wo, smp, rays), (float)rest));
    }
    uint32_t used = 2 + s->nlights * stride, drawn = 2 + 2 * S;
    smp->dim = base + (used > drawn ? used : drawn);
    return L;
}
