#include "transport/subpath.h"

#include <float.h>

float cdl_light_pdf_dir(const cdl_light *l, cdl_vec3 n, cdl_vec3 w)
{
    switch (l->type) {
    case CDL_LIGHT_POINT:
        return 0.25f * CDL_INV_PI;
    case CDL_LIGHT_SPOT:
    case CDL_LIGHT_PROJECTOR:
        return cdl_light_pdf_emit_dir(l, w);
    case CDL_LIGHT_TRIANGLE:
    case CDL_LIGHT_SPHERE: {
        float c = cdl_dot(n, w);
        if (l->type == CDL_LIGHT_TRIANGLE && l->twosided)
            return 0.5f * fabsf(c) * CDL_INV_PI;
        return c > 0.0f ? c * CDL_INV_PI : 0.0f;
    }
    default:
        return 0.0f;
    }
}

float cdl_light_pdf_origin(const cdl_scene *s, int32_t light)
{
    const cdl_light *l = &s->lights[light];
    float pmf = s->light_select.pmf[light];
    if (cdl_light_is_delta(l))
        return pmf;
    return l->area > 0.0f ? pmf / l->area : 0.0f;
}

float cdl_light_pdf_infinite(const cdl_scene *s, cdl_vec3 w)
{
    int32_t e = s->env_light; /* the one infinite light there may be */
    return e < 0 ? 0.0f : s->light_select.pmf[e] * cdl_light_pdf_li(&s->lights[e], cdl_v3(0, 0, 0), w, FLT_MAX);
}

float cdl_light_pdf_disk(const cdl_light *l, cdl_vec3 w, cdl_vec3 n)
{
    float pdf = 1.0f / (CDL_PI * l->radius * l->radius); /* as cdl_light_sample_le's pdf_pos */
    return cdl_is_black(n) ? pdf : pdf * fabsf(cdl_dot(n, w));
}

static uint32_t push(cdl_vertex_store *vs)
{
    uint32_t i = vs->n++;
    vs->flags[i] = 0;
    vs->light[i] = -1;
    vs->pdf_rev[i] = 0.0f;
    vs->rr[i] = 1.0f;
    vs->u[i] = vs->v[i] = 0.0f;
    vs->kdh[i] = cdl_v3(1.0f, 1.0f, 1.0f);
    vs->ts[i] = vs->nb[i] = cdl_v3(0.0f, 0.0f, 0.0f);
    vs->mat[i] = 0;
    return i;
}

/* The random walk after the start vertex `prev`: ray (o, d) carries beta
 * with solid-angle density pdf_dir; stop: it ends at the first vertex
 * whose scattering was not specular. */
static void random_walk(const cdl_scene *s, const cdl_walk *walk, cdl_sampler *smp, int adjoint,
                        uint32_t prev, cdl_vec3 o, cdl_vec3 d, cdl_vec3 beta, float pdf_dir,
                        cdl_vertex_store *vs, uint64_t *rays, cdl_escape *esc, int stop)
{
    for (int depth = 1;; depth++) {
        cdl_hit h;
        (*rays)++;
        if (!cdl_intersect(s, o, d, FLT_MAX, &h)) {
            if (esc) {
                esc->escaped = 1;
                esc->d = d;
                esc->beta = beta;
                esc->pdf_dir = pdf_dir;
            }
            if (!adjoint && walk->env_vertex && s->env_light >= 0) {
                /* the vertex at infinity where the eye path met the sky:
                 * its forward density stays in solid angle */
                uint32_t i = push(vs);
                vs->p[i] = cdl_add(o, d);
                vs->ng[i] = vs->ns[i] = cdl_neg(d);
                vs->wi[i] = cdl_neg(d);
                vs->beta[i] = beta;
                vs->pdf_fwd[i] = pdf_dir;
                vs->parent[i] = (int32_t)prev;
                vs->depth[i] = (uint16_t)depth;
                vs->light[i] = s->env_light;
                vs->flags[i] = CDL_V_EMITTER | CDL_V_INFINITE;
            }
            return;
        }
        cdl_surface sf;
        cdl_surface_at(s, &h, &sf);
        uint32_t i = push(vs);
        vs->p[i] = sf.p;
        vs->ng[i] = sf.ng;
        vs->ns[i] = cdl_dot(sf.ns, sf.ng) < 0.0f ? cdl_neg(sf.ns) : sf.ns;
        vs->wi[i] = cdl_neg(d);
        vs->beta[i] = beta;
        /* after a light at infinity: the disk's density, projected */
        vs->pdf_fwd[i] = (vs->flags[prev] & CDL_V_INFINITE) ? cdl_light_pdf_disk(&s->lights[vs->light[prev]], d, sf.ng)
                                                             : cdl_pdf_to_area(pdf_dir, vs->p[prev], sf.p, sf.ng);
        vs->u[i] = sf.u;
        vs->v[i] = sf.v;
        vs->kdh[i] = sf.kdh;
        vs->ts[i] = sf.ts;
        vs->nb[i] = sf.nb;
        vs->parent[i] = (int32_t)prev;
        vs->mat[i] = sf.mat;
        vs->depth[i] = (uint16_t)depth;
        if (sf.light >= 0) {
            vs->light[i] = sf.light;
            vs->flags[i] |= CDL_V_EMITTER;
        }
        if (depth > walk->maxdepth)
            return;
        cdl_bsdf b;
        cdl_scene_bsdf(s, &sf, &b);
        cdl_vec3 wo = vs->wi[i];
        float u0 = cdl_sampler_1d(smp), u1, u2;
        cdl_sampler_2d(smp, &u1, &u2);
        cdl_scatter sc;
        if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, adjoint, &sc))
            return;
        float pdf_rev_sa = sc.delta ? 0.0f : cdl_bsdf_pdf(&b, sc.wi, wo);
        if (sc.delta) {
            vs->flags[i] |= CDL_V_DELTA;
            sc.pdf = 0.0f;
        }
        cdl_vec3 w = sc.weight;
        if (adjoint) {
            /* shading normals break the symmetry of importance transport
             * (Veach 1997, 5.3): f_s sees |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|) */
            float num = fabsf(cdl_dot(wo, sf.ns)) * fabsf(cdl_dot(sc.wi, sf.ng));
            float den = fabsf(cdl_dot(wo, sf.ng)) * fabsf(cdl_dot(sc.wi, sf.ns));
            w = cdl_scale(w, den > 0.0f ? num / den : 0.0f);
        }
        beta = cdl_mul(beta, w);
        vs->pdf_rev[prev] = (vs->flags[prev] & CDL_V_INFINITE)
                                ? pdf_rev_sa /* solid angle, as its forward density */
                                : cdl_pdf_to_area(pdf_rev_sa, sf.p, vs->p[prev],
                                                  (vs->flags[prev] & (CDL_V_CAMERA | CDL_V_DELTA_LIGHT))
                                                      ? cdl_v3(0.0f, 0.0f, 0.0f)
                                                      : vs->ng[prev]);
        if (stop && !sc.delta)
            return;
        if (depth >= walk->rr_depth) {
            float q = cdl_minf(1.0f, cdl_max3(w));
            if (cdl_sampler_cheap(smp) >= q)
                return;
            vs->rr[i] = q;
            beta = cdl_scale(beta, 1.0f / q);
        }
        if (cdl_is_black(beta))
            return;
        o = cdl_offset(s, sf.p, sf.ng, sc.wi);
        d = sc.wi;
        pdf_dir = sc.pdf;
        prev = i;
    }
}

uint32_t cdl_trace_light_subpath(const cdl_scene *s, const cdl_walk *walk, cdl_sampler *smp,
                                 cdl_vertex_store *vs, uint64_t *rays)
{
    return cdl_trace_light_subpath_esc(s, walk, smp, vs, rays, NULL, 0);
}

uint32_t cdl_trace_light_subpath_esc(const cdl_scene *s, const cdl_walk *walk, cdl_sampler *smp,
                                     cdl_vertex_store *vs, uint64_t *rays, cdl_escape *esc, int first_diffuse)
{
    uint32_t start = vs->n;
    if (esc)
        esc->escaped = 0;
    float us, ua, u1, u2, u3, u4, pmf;
    cdl_sampler_2d(smp, &us, &ua);
    uint32_t li = cdl_alias_sample(&s->light_select, us, ua, &pmf);
    const cdl_light *l = &s->lights[li];
    cdl_sampler_2d(smp, &u1, &u2);
    cdl_sampler_2d(smp, &u3, &u4);
    cdl_light_emit e;
    /* lights at infinity emit from a disk covering the scene's bounding
     * sphere, outside it, perpendicular to the direction (cdl_light_sample_le) */
    if (!cdl_light_sample_le(l, u1, u2, u3, u4, &e) || !(e.pdf_pos > 0.0f) || !(e.pdf_dir > 0.0f))
        return 0;
    uint32_t i = push(vs);
    vs->p[i] = e.p;
    vs->ng[i] = vs->ns[i] = e.n;
    vs->wi[i] = cdl_v3(0.0f, 0.0f, 0.0f);
    /* y_0 carries the emitted radiance per unit area density; the
     * direction's distribution is applied at connection (Le_dir; for
     * point, spot and projector lights all of it: cdl_light_I_factor). */
    vs->beta[i] = cdl_scale(cdl_light_is_delta_pos(l) ? l->L : e.Le, 1.0f / (pmf * e.pdf_pos));
    vs->pdf_fwd[i] = pmf * e.pdf_pos;
    vs->parent[i] = -1;
    vs->light[i] = (int32_t)li;
    vs->depth[i] = 0;
    vs->flags[i] = CDL_V_LIGHT | (cdl_light_is_delta(l) ? CDL_V_DELTA_LIGHT : 0);
    if (cdl_light_at_infinity(l)) {
        /* pbrt-v3: y_0's density is that of its direction, y_1's that of
         * the disk point (set in random_walk) */
        vs->flags[i] |= CDL_V_INFINITE;
        vs->pdf_fwd[i] = cdl_light_pdf_infinite(s, cdl_neg(e.d));
    }
    float cos = cdl_is_black(e.n) ? 1.0f : fabsf(cdl_dot(e.n, e.d));
    cdl_vec3 beta = cdl_scale(e.Le, cos / (pmf * e.pdf_pos * e.pdf_dir));
    cdl_vec3 o = cdl_is_black(e.n) ? e.p : cdl_offset(s, e.p, e.n, e.d);
    random_walk(s, walk, smp, 1, i, o, e.d, beta, e.pdf_dir, vs, rays, esc, first_diffuse);
    return vs->n - start;
}

uint32_t cdl_trace_eye_subpath(const cdl_scene *s, const cdl_camera *cam, float px, float py,
                               const cdl_walk *walk, cdl_sampler *smp, cdl_vertex_store *vs,
                               uint64_t *rays)
{
    uint32_t start = vs->n;
    uint32_t i = push(vs);
    cdl_vec3 d = cdl_camera_ray(cam, px, py);
    float pdf_dir;
    cdl_camera_We(cam, d, &pdf_dir);
    vs->p[i] = cam->eye;
    vs->ng[i] = vs->ns[i] = cdl_normalize(cam->fwd);
    vs->wi[i] = cdl_v3(0.0f, 0.0f, 0.0f);
    vs->beta[i] = cdl_v3(1.0f, 1.0f, 1.0f);
    vs->pdf_fwd[i] = 1.0f;
    vs->parent[i] = -1;
    vs->depth[i] = 0;
    vs->flags[i] = CDL_V_CAMERA;
    random_walk(s, walk, smp, 0, i, cam->eye, d, cdl_v3(1.0f, 1.0f, 1.0f), pdf_dir, vs, rays, NULL, 0);
    return vs->n - start;
}
