#include "scene/light.h"

#include <float.h>

#include "core/sampling.h"
#include "scene/envmap.h"
#include "scene/texture.h"

/* The light's texture at candela's (u, v), with the texture's own mapping,
 * wrap and filter (tex points into the scene's array at tex_id). */
static cdl_vec3 tex_eval(const cdl_light *l, float u, float v)
{
    return cdl_texture_eval(l->tex - l->tex_id, l->tex_id, u, v);
}

/* A uniform point on a triangle light, and its radiance there. */
static cdl_vec3 triangle_point(const cdl_light *l, float u1, float u2, cdl_vec3 *L)
{
    float b1, b2;
    cdl_sample_triangle(u1, u2, &b1, &b2);
    *L = l->L;
    if (l->tex) {
        float u = l->uv[0] + b1 * (l->uv[2] - l->uv[0]) + b2 * (l->uv[4] - l->uv[0]);
        float v = l->uv[1] + b1 * (l->uv[3] - l->uv[1]) + b2 * (l->uv[5] - l->uv[1]);
        *L = cdl_mul(*L, tex_eval(l, u, v));
    }
    return cdl_light_triangle_at(l, b1, b2);
}

/* A texture projected by a spot or projector at Mitsuba's uv, whose v = 0
 * is the image's top row (candela's uv has v = 0 at the bottom). */
static cdl_vec3 projected(const cdl_light *l, float u, float v)
{
    return tex_eval(l, u, 1.0f - v);
}

/* A cosine-distributed emission direction about e->n (area lights);
 * face_prob is the probability the face e->n was chosen with. */
static int emit_cosine(cdl_light_emit *e, float u3, float u4, float face_prob)
{
    cdl_frame f = cdl_frame_from(e->n);
    cdl_vec3 local = cdl_sample_cosine_hemisphere(u3, u4);
    if (local.z <= 0.0f)
        return 0;
    e->d = cdl_to_world(&f, local);
    e->pdf_dir = local.z * CDL_INV_PI * face_prob;
    return 1;
}

/* pbrt-v3's spot falloff: smooth fourth power between the two cones;
 * Mitsuba's: linear in the angle. */
static float spot_falloff(const cdl_light *l, float cos_t)
{
    if (l->spot_linear) {
        if (!(cos_t > l->cos_total))
            return 0.0f;
        if (cos_t >= l->cos_falloff || !(l->cutoff > l->beam))
            return 1.0f;
        float a = acosf(cdl_minf(cos_t, 1.0f));
        return fminf(fmaxf((l->cutoff - a) / (l->cutoff - l->beam), 0.0f), 1.0f);
    }
    if (cos_t < l->cos_total)
        return 0.0f;
    if (cos_t >= l->cos_falloff)
        return 1.0f;
    float d = (cos_t - l->cos_total) / (l->cos_falloff - l->cos_total);
    return (d * d) * (d * d);
}

cdl_vec3 cdl_light_I_factor(const cdl_light *l, cdl_vec3 w)
{
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    float c = cdl_dot(w, l->n);
    if (l->type == CDL_LIGHT_SPOT) {
        float f = spot_falloff(l, c);
        if (!(f > 0.0f))
            return zero;
        if (!l->tex)
            return cdl_v3(f, f, f);
        /* Mitsuba's spot uv: u grows along +x (the light's left) */
        float u = 0.5f + 0.5f * cdl_dot(w, l->ax) / (c * l->tan_x);
        float v = 0.5f + 0.5f * cdl_dot(w, l->ay) / (c * l->tan_y);
        return cdl_scale(projected(l, u, v), f);
    }
    if (l->type == CDL_LIGHT_PROJECTOR) {
        if (!(c > 0.0f))
            return zero;
        /* a perspective camera's uv (u grows to the image's right, v down):
         * the irradiance at distance 1, as intensity over cos^3 */
        float u = 0.5f - 0.5f * cdl_dot(w, l->ax) / (c * l->tan_x);
        float v = 0.5f - 0.5f * cdl_dot(w, l->ay) / (c * l->tan_y);
        if (!(u >= 0.0f && u <= 1.0f && v >= 0.0f && v <= 1.0f))
            return zero;
        float k = 1.0f / (c * c * c);
        return l->tex ? cdl_scale(projected(l, u, v), k) : cdl_v3(k, k, k);
    }
    return cdl_v3(1.0f, 1.0f, 1.0f);
}

float cdl_light_pdf_emit_dir(const cdl_light *l, cdl_vec3 w)
{
    float c = cdl_dot(w, l->n);
    if (l->type == CDL_LIGHT_SPOT)
        return c >= l->cos_total ? 1.0f / (2.0f * CDL_PI * (1.0f - l->cos_total)) : 0.0f;
    if (l->type == CDL_LIGHT_PROJECTOR) {
        if (!(c > 0.0f) || fabsf(cdl_dot(w, l->ax)) > c * l->tan_x || fabsf(cdl_dot(w, l->ay)) > c * l->tan_y)
            return 0.0f;
        return 1.0f / (4.0f * l->tan_x * l->tan_y * c * c * c);
    }
    return 0.0f;
}

/* 1 - cos(theta_max) of the cone a sphere subtends, sin^2 theta_max given:
 * s / (1 + sqrt(1 - s)) keeps full precision where 1 - sqrt(1 - s) would not. */
static float one_minus_cos_max(float sin2)
{
    return sin2 / (1.0f + sqrtf(cdl_maxf(0.0f, 1.0f - sin2)));
}

static int sample_sphere(const cdl_light *l, cdl_vec3 ref, float u1, float u2, cdl_light_sample *s)
{
    cdl_vec3 dc = cdl_sub(l->p, ref);
    float d2 = cdl_dot(dc, dc), r2 = l->radius * l->radius;
    if (d2 <= r2 * 1.0001f) {
        /* inside (or on) the sphere: uniform on the surface */
        cdl_vec3 n = cdl_sample_uniform_sphere(u1, u2);
        s->p = cdl_madd(l->p, n, l->radius);
        cdl_vec3 d = cdl_sub(s->p, ref);
        float dd = cdl_dot(d, d);
        if (!(dd > 0.0f))
            return 0;
        s->dist = sqrtf(dd);
        s->wi = cdl_scale(d, 1.0f / s->dist);
        float c = fabsf(cdl_dot(n, s->wi));
        if (!(c > 0.0f))
            return 0;
        s->pdf = dd / (c * l->area);
        s->Li = cdl_light_Le(l, n, cdl_neg(s->wi));
        s->delta = 0;
        return !cdl_is_black(s->Li);
    }
    /* outside: uniform in the cone the sphere subtends (pbrt-v3 Sphere::Sample) */
    float dist_c = sqrtf(d2);
    cdl_vec3 wc = cdl_scale(dc, 1.0f / dist_c);
    float sin2_max = r2 / d2;
    float omc = one_minus_cos_max(sin2_max);
    /* cos_t = 1 - u1 omc; sin^2 from omc directly, as 1 - cos^2 cancels
     * catastrophically for small, distant spheres */
    float x = u1 * omc;
    float cos_t = 1.0f - x;
    float sin_t2 = x * (2.0f - x);
    float phi = 2.0f * CDL_PI * u2;
    float ds = dist_c * cos_t - sqrtf(cdl_maxf(0.0f, r2 - d2 * sin_t2));
    float cos_a = (d2 + r2 - ds * ds) / (2.0f * dist_c * l->radius);
    float sin_a = sqrtf(cdl_maxf(0.0f, 1.0f - cos_a * cos_a));
    cdl_frame f = cdl_frame_from(cdl_neg(wc));
    cdl_vec3 n = cdl_to_world(&f, cdl_v3(sin_a * cosf(phi), sin_a * sinf(phi), cos_a));
    s->p = cdl_madd(l->p, n, l->radius);
    cdl_vec3 d = cdl_sub(s->p, ref);
    s->dist = cdl_length(d);
    if (!(s->dist > 0.0f))
        return 0;
    s->wi = cdl_scale(d, 1.0f / s->dist);
    s->pdf = 1.0f / (2.0f * CDL_PI * omc);
    s->Li = cdl_light_Le(l, n, cdl_neg(s->wi));
    s->delta = 0;
    return !cdl_is_black(s->Li) && isfinite(s->pdf);
}

int cdl_light_sample_li_any(const cdl_light *l, cdl_vec3 ref, float u1, float u2, cdl_light_sample *s)
{
    switch (l->type) {
    case CDL_LIGHT_POINT:
    case CDL_LIGHT_SPOT:
    case CDL_LIGHT_PROJECTOR: {
        cdl_vec3 d = cdl_sub(l->p, ref);
        float d2 = cdl_dot(d, d);
        if (!(d2 > 0.0f))
            return 0;
        s->dist = sqrtf(d2);
        s->wi = cdl_scale(d, 1.0f / s->dist);
        s->p = l->p;
        s->Li = cdl_scale(cdl_mul(l->L, cdl_light_I_factor(l, cdl_neg(s->wi))), 1.0f / d2);
        s->pdf = 1.0f;
        s->delta = 1;
        return !cdl_is_black(s->Li);
    }
    case CDL_LIGHT_DISTANT:
        s->wi = cdl_neg(l->n);
        s->dist = FLT_MAX;
        s->p = cdl_madd(ref, s->wi, 2.0f * l->radius);
        s->Li = l->L;
        s->pdf = 1.0f;
        s->delta = 1;
        return 1;
    case CDL_LIGHT_INFINITE:
        if (l->map) {
            s->Li = cdl_envmap_sample(l->map, u1, u2, &s->wi, &s->pdf);
            if (!(s->pdf > 0.0f))
                return 0;
        } else {
            s->wi = cdl_sample_uniform_sphere(u1, u2);
            s->Li = l->L;
            s->pdf = 0.25f * CDL_INV_PI;
        }
        s->dist = FLT_MAX;
        s->p = cdl_madd(ref, s->wi, 2.0f * l->radius);
        s->delta = 0;
        return 1;
    case CDL_LIGHT_SPHERE:
        return sample_sphere(l, ref, u1, u2, s);
    case CDL_LIGHT_TRIANGLE:
        break;
    }
    cdl_vec3 Le, p = triangle_point(l, u1, u2, &Le);
    return cdl_light_triangle_li(l, ref, p, Le, s);
}

float cdl_light_pdf_li(const cdl_light *l, cdl_vec3 ref, cdl_vec3 wi, float dist)
{
    switch (l->type) {
    case CDL_LIGHT_TRIANGLE: {
        float cos_l = -cdl_dot(wi, l->n);
        if (l->twosided)
            cos_l = fabsf(cos_l);
        return cos_l > 0.0f ? dist * dist / (cos_l * l->area) : 0.0f;
    }
    case CDL_LIGHT_SPHERE: {
        cdl_vec3 dc = cdl_sub(l->p, ref);
        float d2 = cdl_dot(dc, dc), r2 = l->radius * l->radius;
        if (d2 <= r2 * 1.0001f) {
            cdl_vec3 n = cdl_normalize(cdl_sub(cdl_madd(ref, wi, dist), l->p));
            float c = fabsf(cdl_dot(n, wi));
            return c > 0.0f ? dist * dist / (c * l->area) : 0.0f;
        }
        return 1.0f / (2.0f * CDL_PI * one_minus_cos_max(r2 / d2));
    }
    case CDL_LIGHT_INFINITE:
        return l->map ? cdl_envmap_pdf(l->map, wi) : 0.25f * CDL_INV_PI;
    default:
        return 0.0f;
    }
}

cdl_vec3 cdl_light_Le(const cdl_light *l, cdl_vec3 ng, cdl_vec3 wo)
{
    float c = cdl_dot(ng, wo);
    int front = l->type == CDL_LIGHT_SPHERE ? (l->inward ? c < 0.0f : c > 0.0f)
                                            : (l->twosided ? c != 0.0f : c > 0.0f);
    return front ? l->L : cdl_v3(0.0f, 0.0f, 0.0f);
}

cdl_vec3 cdl_light_Le_uv(const cdl_light *l, cdl_vec3 ng, cdl_vec3 wo, float u, float v)
{
    cdl_vec3 L = cdl_light_Le(l, ng, wo);
    return l->tex && !cdl_is_black(L) ? cdl_mul(L, tex_eval(l, u, v)) : L;
}

int cdl_light_sample_le(const cdl_light *l, float u1, float u2, float u3, float u4,
                        cdl_light_emit *e)
{
    switch (l->type) {
    case CDL_LIGHT_POINT:
    case CDL_LIGHT_SPOT:
    case CDL_LIGHT_PROJECTOR:
        e->p = l->p;
        e->n = cdl_v3(0.0f, 0.0f, 0.0f);
        e->pdf_pos = 1.0f;
        if (l->type == CDL_LIGHT_POINT) {
            e->d = cdl_sample_uniform_sphere(u3, u4);
            e->pdf_dir = 0.25f * CDL_INV_PI;
            e->Le = l->L;
        } else if (l->type == CDL_LIGHT_SPOT) {
            /* uniform in the outer cone */
            float cos_t = 1.0f - u3 * (1.0f - l->cos_total);
            float sin_t = sqrtf(cdl_maxf(0.0f, 1.0f - cos_t * cos_t));
            float phi = 2.0f * CDL_PI * u4;
            cdl_frame f = cdl_frame_from(l->n);
            e->d = cdl_to_world(&f, cdl_v3(sin_t * cosf(phi), sin_t * sinf(phi), cos_t));
            e->pdf_dir = 1.0f / (2.0f * CDL_PI * (1.0f - l->cos_total));
            e->Le = l->tex || l->spot_linear ? cdl_mul(l->L, cdl_light_I_factor(l, e->d))
                                             : cdl_scale(l->L, spot_falloff(l, cos_t));
        } else {
            /* uniform on the image at distance 1 */
            cdl_vec3 q = cdl_add(cdl_scale(l->ax, (2.0f * u3 - 1.0f) * l->tan_x),
                                 cdl_scale(l->ay, (2.0f * u4 - 1.0f) * l->tan_y));
            e->d = cdl_normalize(cdl_add(l->n, q));
            e->pdf_dir = cdl_light_pdf_emit_dir(l, e->d);
            e->Le = cdl_mul(l->L, cdl_light_I_factor(l, e->d));
            return e->pdf_dir > 0.0f;
        }
        return 1;
    case CDL_LIGHT_DISTANT:
    case CDL_LIGHT_INFINITE: {
        /* a ray entering the scene's bounding sphere: a disk perpendicular
         * to the direction, pushed out to the sphere */
        float pdf_dir = 1.0f;
        e->Le = l->L;
        if (l->type == CDL_LIGHT_DISTANT) {
            e->d = l->n;
        } else if (l->map) { /* travelling away from where the light comes from */
            cdl_vec3 w;
            e->Le = cdl_envmap_sample(l->map, u3, u4, &w, &pdf_dir);
            if (!(pdf_dir > 0.0f))
                return 0;
            e->d = cdl_neg(w);
        } else {
            e->d = cdl_sample_uniform_sphere(u3, u4);
            pdf_dir = 0.25f * CDL_INV_PI;
        }
        cdl_frame f = cdl_frame_from(e->d);
        cdl_vec3 disk = cdl_sample_cosine_hemisphere(u1, u2); /* x, y uniform on the unit disk */
        e->p = cdl_add(l->p, cdl_scale(cdl_add(cdl_scale(f.t, disk.x), cdl_scale(f.b, disk.y)), l->radius));
        e->p = cdl_madd(e->p, e->d, -l->radius);
        e->n = e->d;
        e->pdf_pos = 1.0f / (CDL_PI * l->radius * l->radius);
        e->pdf_dir = pdf_dir;
        return 1;
    }
    case CDL_LIGHT_SPHERE: {
        cdl_vec3 n = cdl_sample_uniform_sphere(u1, u2);
        e->p = cdl_madd(l->p, n, l->radius);
        e->n = l->inward ? cdl_neg(n) : n;
        e->Le = l->L;
        e->pdf_pos = 1.0f / l->area;
        return emit_cosine(e, u3, u4, 1.0f);
    }
    case CDL_LIGHT_TRIANGLE:
        break;
    }
    e->p = triangle_point(l, u1, u2, &e->Le);
    e->n = l->n;
    float pick = u3;
    if (l->twosided) {
        /* choose a face with probability 1/2, reusing u3 */
        pick = u3 < 0.5f ? 2.0f * u3 : 2.0f * u3 - 1.0f;
        e->n = cdl_scale(l->n, u3 < 0.5f ? 1.0f : -1.0f);
    }
    e->pdf_pos = 1.0f / l->area;
    return emit_cosine(e, pick, u4, l->twosided ? 0.5f : 1.0f);
}

cdl_vec3 cdl_light_power(const cdl_light *l)
{
    switch (l->type) {
    case CDL_LIGHT_POINT:
        return cdl_scale(l->L, 4.0f * CDL_PI);
    case CDL_LIGHT_SPOT: {
        float omega = 2.0f * CDL_PI * (1.0f - 0.5f * (l->cos_falloff + l->cos_total));
        if (l->spot_linear) { /* 2 pi int falloff sin: midpoints */
            omega = 0.0f;
            for (int i = 0; i < 64; i++) {
                float t = (i + 0.5f) / 64.0f * l->cutoff;
                omega += spot_falloff(l, cosf(t)) * sinf(t);
            }
            omega *= 2.0f * CDL_PI * l->cutoff / 64.0f;
        }
        return cdl_scale(l->tex ? cdl_mul(l->L, l->tex_mean) : l->L, omega);
    }
    case CDL_LIGHT_PROJECTOR: /* int E / cos^3 dw = int E over the image at distance 1 */
        return cdl_scale(l->tex ? cdl_mul(l->L, l->tex_mean) : l->L, 4.0f * l->tan_x * l->tan_y);
    case CDL_LIGHT_DISTANT:
        return cdl_scale(l->L, CDL_PI * l->radius * l->radius);
    case CDL_LIGHT_INFINITE: /* the flux through the disk facing each direction */
        return cdl_scale(l->map ? l->map->flux : cdl_scale(l->L, 4.0f * CDL_PI),
                         CDL_PI * l->radius * l->radius);
    case CDL_LIGHT_SPHERE:
        return cdl_scale(l->L, CDL_PI * l->area);
    case CDL_LIGHT_TRIANGLE:
        break;
    }
    return cdl_scale(l->tex ? cdl_mul(l->L, l->tex_mean) : l->L, CDL_PI * l->area * (l->twosided ? 2.0f : 1.0f));
}

cdl_vec3 cdl_light_env_Le(const cdl_light *l, cdl_vec3 w)
{
    return l->map ? cdl_envmap_eval(l->map, w) : l->L;
}
