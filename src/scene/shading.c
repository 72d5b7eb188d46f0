#include "scene/shading.h"

#include <math.h>

cdl_vec3 cdl_bump_normal(cdl_vec3 dpdu, cdl_vec3 dpdv, const float grad[2], cdl_vec3 s, cdl_vec3 t, cdl_vec3 n,
                         cdl_vec3 ng)
{
    /* the displaced surface p + h n, ignoring dn/du (Mitsuba's bumpmap;
     * pbrt adds h dn/du, a relative change of h times the curvature that
     * candela drops) */
    cdl_vec3 du = cdl_madd(dpdu, n, grad[0] - cdl_dot(n, dpdu));
    cdl_vec3 dv = cdl_madd(dpdv, n, grad[1] - cdl_dot(n, dpdv));
    cdl_vec3 c = cdl_cross(du, dv);
    if (cdl_dot(ng, c) < 0.0f)
        c = cdl_neg(c);
    return cdl_v3(cdl_dot(c, s), cdl_dot(c, t), cdl_dot(c, n));
}

void cdl_surface_shade(const cdl_scene *s, cdl_surface *sf, cdl_vec3 wo)
{
    sf->nb = sf->ns;
    sf->ts = cdl_v3(0.0f, 0.0f, 0.0f);
    const cdl_material *m = &s->mats[sf->mat];
    if (!cdl_mat_uses_tangent(&m->maps, m->alpha_x, m->alpha_y))
        return;
    /* the unperturbed frame: n on the geometric side (as cdl_bsdf_init
     * puts it), s = dp/du made perpendicular (Mitsuba's sh_frame) */
    cdl_vec3 n = cdl_dot(sf->ns, sf->ng) < 0.0f ? cdl_neg(sf->ns) : sf->ns;
    cdl_vec3 t0 = cdl_madd(sf->dpdu, n, -cdl_dot(n, sf->dpdu));
    float len = cdl_length(t0);
    cdl_vec3 ts = len > 0.0f && isfinite(len) ? cdl_scale(t0, 1.0f / len) : cdl_frame_from(n).t;
    cdl_vec3 tb = cdl_cross(n, ts);
    sf->nb = n;
    sf->ns = n;
    sf->ts = ts;
    cdl_vec3 np;
    if (!m->maps.on) {
        return;
    } else if (m->maps.bump_tex >= 0) {
        float g[2];
        cdl_texture_grad1(s->texs, m->maps.bump_tex, sf->u, sf->v, g);
        g[0] *= m->maps.bump_scale;
        g[1] *= m->maps.bump_scale;
        /* the partials the height displaces (cdl_bump_frame) */
        cdl_vec3 bu = sf->dpdu, bv = sf->dpdv;
        if (m->maps.bump_frame == CDL_BUMP_PBRT3_VN || m->maps.bump_frame == CDL_BUMP_PBRT4_VN) {
            float l = m->maps.bump_frame == CDL_BUMP_PBRT3_VN ? -1.0f : len > 0.0f && isfinite(len) ? len : 0.0f;
            bu = cdl_scale(ts, l);
            bv = cdl_scale(tb, l);
        }
        np = cdl_bump_normal(bu, bv, g, ts, tb, n, sf->ng);
    } else if (m->maps.normal_tex >= 0) {
        cdl_vec3 c = cdl_texture_eval(s->texs, m->maps.normal_tex, sf->u, sf->v);
        np = cdl_v3(2.0f * c.x - 1.0f, 2.0f * c.y - 1.0f, 2.0f * c.z - 1.0f);
    } else {
        return;
    }
    /* Mitsuba's flip_invalid_normals: keep the viewer on the side of the
     * perturbed normal that it is on of the unperturbed one */
    cdl_vec3 wl = cdl_v3(cdl_dot(wo, ts), cdl_dot(wo, tb), cdl_dot(wo, n));
    if (cdl_is_finite3(wl) && wl.z * cdl_dot(wl, np) <= 0.0f)
        np = cdl_v3(-np.x, -np.y, np.z);
    float l2 = cdl_dot(np, np);
    np = l2 > 0.0f && isfinite(1.0f / l2) ? cdl_scale(np, 1.0f / sqrtf(l2)) : cdl_v3(0.0f, 0.0f, 1.0f);
    /* the perturbed tangent: (1, 0, 0) made perpendicular to np */
    cdl_vec3 sl = cdl_madd(cdl_v3(1.0f, 0.0f, 0.0f), np, -np.x);
    float sl2 = cdl_dot(sl, sl);
    sl = sl2 > 0.0f && isfinite(1.0f / sl2) ? cdl_scale(sl, 1.0f / sqrtf(sl2)) : cdl_v3(0.0f, 1.0f, 0.0f);
    cdl_frame base = {ts, tb, n};
    sf->ns = cdl_normalize(cdl_to_world(&base, np));
    sf->ts = cdl_normalize(cdl_to_world(&base, sl));
}

void cdl_scene_bsdf_maps(const cdl_scene *s, const cdl_material *m, const cdl_surface *sf, cdl_bsdf *b)
{
    b->nb = b->frame.n;
    b->perturbed = 0;
    for (int k = 0; k < 2 && m->maps.on; k++)
        if (m->maps.alpha_tex[k] >= 0) {
            float a = cdl_texture_eval1(s->texs, m->maps.alpha_tex[k], sf->u, sf->v);
            if (m->maps.alpha_remap != CDL_ROUGH_ALPHA && isfinite(a))
                a = cdl_roughness_to_alpha(a, m->maps.alpha_remap);
            a = isfinite(a) ? cdl_maxf(a, 1e-4f) : 1e-4f;
            if (k == 0)
                b->ax = a;
            else
                b->ay = a;
        }
    if (cdl_is_black(sf->ts))
        return;
    /* the frame follows the tangent; n as cdl_bsdf_init oriented it */
    cdl_vec3 n = b->frame.n;
    cdl_vec3 t = cdl_madd(sf->ts, n, -cdl_dot(n, sf->ts));
    float len = cdl_length(t);
    if (!(len > 0.0f) || !isfinite(len))
        return;
    b->frame.t = cdl_scale(t, 1.0f / len);
    b->frame.b = cdl_cross(n, b->frame.t);
    b->nb = cdl_dot(sf->nb, sf->ng) < 0.0f ? cdl_neg(sf->nb) : sf->nb;
    b->perturbed = cdl_dot(b->nb, n) < 1.0f - 1e-7f;
}
