/* Mitsuba 3's principled / principledthin BSDFs, term by term as Mitsuba
 * defines them (src/bsdfs/principled.cpp, principledthin.cpp,
 * principledhelpers.h, include/mitsuba/render/microfacet.h, fresnel.h).
 * Where Mitsuba's model departs from Burley's notes it is followed, not
 * fixed: separable Smith masking, the clearcoat lobe without its
 * 1 / (4 cos cos), the sheen without 1 / pi, the thin transmission as a
 * mirrored reflection lobe masked by the microfacet side test.
 *
 * The local functions use Mitsuba's names: wi is the direction the path
 * came from (candela's wo), wo the scattered direction (candela's wi);
 * they return Mitsuba's "value", f |cos(wo)|. */
#include "scene/bsdf_principled.h"

#include <math.h>

#include "core/sampling.h"
#include "scene/bsdf.h"
#include "scene/microfacet.h"
#include "scene/texture.h"

static float sqr(float x) { return x * x; }
static float lerp(float a, float b, float t) { return a * (1.0f - t) + b * t; }
static float clampf(float x, float lo, float hi) { return x > lo ? (x < hi ? x : hi) : lo; }
static float sign_of(float x) { return signbit(x) ? -1.0f : 1.0f; } /* drjit's mulsign */
/* Mitsuba's RGB luminance (sRGB primaries, Y row) */
static float mts_lum(cdl_vec3 c) { return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z; }

cdl_principled cdl_principled_default(int thin)
{
    cdl_principled m;
    m.thin = thin;
    for (int i = 0; i < CDL_PR_NPARAMS; i++) {
        m.value[i] = 0.0f;
        m.tex[i] = -1;
    }
    m.value[CDL_PR_ROUGHNESS] = 0.5f;
    /* principled: specular 0.5 gives eta = 2 / (1 - sqrt(0.04)) - 1 */
    m.value[CDL_PR_ETA] = thin ? 1.5f : 2.0f / (1.0f - sqrtf(0.08f * 0.5f)) - 1.0f;
    for (int i = 0; i < CDL_PR_NRATES; i++)
        m.rate[i] = 1.0f;
    return m;
}

void cdl_principled_at_init(cdl_principled_at *p, const cdl_principled *m, const cdl_texture *texs, float u,
                            float v)
{
    p->thin = m->thin;
    for (int i = 0; i < CDL_PR_NPARAMS; i++) {
        float x = m->value[i];
        if (texs && m->tex[i] >= 0)
            x *= cdl_texture_eval1(texs, m->tex[i], u, v); /* Mitsuba's eval_1 */
        if (i == CDL_PR_ETA)
            p->p[i] = isfinite(x) && x > 1e-3f ? x : 1e-3f;
        else
            p->p[i] = isfinite(x) ? clampf(x, 0.0f, i == CDL_PR_DIFF_TRANS ? 2.0f : 1.0f) : 0.0f;
    }
    for (int i = 0; i < CDL_PR_NRATES; i++)
        p->rate[i] = m->rate[i];
}

void cdl_principled_tangent(cdl_bsdf *b, cdl_vec3 dpdu)
{
    cdl_vec3 n = b->frame.n;
    cdl_vec3 t = cdl_sub(dpdu, cdl_scale(n, cdl_dot(n, dpdu)));
    float len = cdl_length(t), full = cdl_length(dpdu);
    if (!(len > 1e-6f * full) || !isfinite(len))
        return; /* no uv, or dp/du along the normal: keep the frame */
    b->frame.t = cdl_scale(t, 1.0f / len);
    b->frame.b = cdl_cross(n, b->frame.t);
}

/* ---- Mitsuba's building blocks ------------------------------------------ */

/* Dielectric Fresnel (fresnel.h): cos_i < 0 is inside; *cos_t is signed
 * opposite to cos_i, *eta_ti the index ratio refraction scales by. */
static float fresnel(float cos_i, float eta, float *cos_t, float *eta_ti)
{
    int outside = !signbit(cos_i);
    float eta_it = outside ? eta : 1.0f / eta, e_ti = outside ? 1.0f / eta : eta;
    float ct2 = 1.0f - (1.0f - cos_i * cos_i) * e_ti * e_ti;
    float ci = fabsf(cos_i), ct = ct2 > 0.0f ? sqrtf(ct2) : 0.0f;
    if (cos_t)
        *cos_t = outside ? -ct : ct;
    if (eta_ti)
        *eta_ti = e_ti;
    if (eta == 1.0f)
        return 0.0f;
    if (ci == 0.0f)
        return 1.0f;
    float as = (ci - eta_it * ct) / (ci + eta_it * ct), ap = (eta_it * ci - ct) / (eta_it * ci + ct);
    return 0.5f * (as * as + ap * ap);
}

static float schlick_weight(float c)
{
    float m = clampf(1.0f - c, 0.0f, 1.0f);
    return sqr(sqr(m)) * m;
}

/* The Schlick weight of calc_schlick: of the transmitted angle when
 * leaving the denser side. calc_schlick(R0) = R0 + (1 - R0) w. */
static float schlick_w_eta(float cos_i, float eta)
{
    int outside = cos_i >= 0.0f;
    float eta_it = outside ? eta : 1.0f / eta, eta_ti = 1.0f / eta_it;
    float ct2 = 1.0f - (1.0f - cos_i * cos_i) * eta_ti * eta_ti;
    return eta_it > 1.0f ? schlick_weight(fabsf(cos_i)) : schlick_weight(ct2 > 0.0f ? sqrtf(ct2) : 0.0f);
}

static float schlick_r0(float eta) { return sqr((eta - 1.0f) / (eta + 1.0f)); }

/* Disney's roughness and anisotropy to GGX alphas (calc_dist_params). */
static void dist_params(float anisotropic, float roughness, float *ax, float *ay)
{
    float r2 = roughness * roughness, aspect = sqrtf(1.0f - 0.9f * anisotropic);
    *ax = cdl_maxf(0.001f, r2 / aspect);
    *ay = cdl_maxf(0.001f, r2 * aspect);
}

static float ggx_D(cdl_vec3 m, float ax, float ay)
{
    float r = 1.0f / (CDL_PI * ax * ay * sqr(sqr(m.x / ax) + sqr(m.y / ay) + sqr(m.z)));
    return r * m.z > 1e-20f ? r : 0.0f;
}

/* Smith's G1 for GGX, zero for a back-facing microfacet. */
static float ggx_G1(cdl_vec3 v, cdl_vec3 m, float ax, float ay)
{
    float xy = sqr(ax * v.x) + sqr(ay * v.y);
    float r = 2.0f / (1.0f + sqrtf(1.0f + xy / sqr(v.z)));
    if (xy == 0.0f)
        r = 1.0f;
    if (cdl_dot(v, m) * v.z <= 0.0f)
        r = 0.0f;
    return r;
}

/* Density of visible-normal sampling of m seen from wi (wi.z > 0). */
static float vndf_pdf(cdl_vec3 wi, cdl_vec3 m, float ax, float ay)
{
    return ggx_D(m, ax, ay) * ggx_G1(wi, m, ax, ay) * fabsf(cdl_dot(wi, m)) / wi.z;
}

/* GTR1 (Berry) distribution of the clearcoat, alpha in [0.001, 0.1]. */
static float gtr1_D(cdl_vec3 m, float a)
{
    float a2 = a * a;
    float r = (a2 - 1.0f) / (CDL_PI * logf(a2) * (1.0f + (a2 - 1.0f) * m.z * m.z));
    return r * m.z > 1e-20f ? r : 0.0f;
}

static cdl_vec3 gtr1_sample(float a, float u1, float u2)
{
    float a2 = a * a, phi = 2.0f * CDL_PI * u1;
    float c2 = (1.0f - powf(a2, 1.0f - u2)) / (1.0f - a2);
    float s = sqrtf(cdl_maxf(0.0f, 1.0f - c2)), c = sqrtf(cdl_maxf(0.0f, c2));
    return cdl_v3(cosf(phi) * s, sinf(phi) * s, c);
}

/* The clearcoat's fixed separable masking, alpha 0.25 (smith_ggx1). */
static float cc_G1(cdl_vec3 v, cdl_vec3 m)
{
    float c2 = v.z * v.z;
    float r = 2.0f / (1.0f + sqrtf(1.0f + 0.0625f * (1.0f - c2) / c2));
    if (v.z == 1.0f)
        r = 1.0f;
    if (cdl_dot(v, m) * v.z <= 0.0f)
        r = 0.0f;
    return r;
}

static float cc_alpha(float gloss) { return lerp(0.1f, 0.001f, gloss); }

/* principled_fresnel: metallic and tinted Schlick terms blended with the
 * true dielectric one on the front side; the bare dielectric inside. */
static cdl_vec3 principled_fresnel(float F, const float *p, cdl_vec3 base, float cos_i, int front, float bsdf)
{
    if (!front)
        return cdl_v3(bsdf * F, bsdf * F, bsdf * F);
    float met = p[CDL_PR_METALLIC], tint = p[CDL_PR_SPEC_TINT], eta = p[CDL_PR_ETA];
    float eta_it = cos_i >= 0.0f ? eta : 1.0f / eta;
    float w = schlick_w_eta(cos_i, eta), r0 = schlick_r0(eta_it), lum = mts_lum(base);
    float b[3] = {base.x, base.y, base.z}, out[3];
    for (int k = 0; k < 3; k++) {
        float ct = lum > 0.0f ? b[k] / lum : 1.0f, f0 = ct * r0;
        float fs = met * (b[k] + (1.0f - b[k]) * w) + (1.0f - met) * tint * (f0 + (1.0f - f0) * w);
        out[k] = (1.0f - met) * (1.0f - tint) * F + fs;
    }
    return cdl_v3(out[0], out[1], out[2]);
}

/* Burley's diffuse with retro-reflection, blended with the fake
 * subsurface term by flatness; cos_d = wo . wh. */
static float disney_diffuse(float roughness, float flatness, float abs_ci, float abs_co, float cos_d)
{
    float Fo = schlick_weight(abs_co), Fi = schlick_weight(abs_ci);
    float f_diff = (1.0f - 0.5f * Fi) * (1.0f - 0.5f * Fo);
    float Rr = 2.0f * roughness * cos_d * cos_d;
    float f_retro = Rr * (Fo + Fi + Fo * Fi * (Rr - 1.0f));
    float Fss90 = 0.5f * Rr;
    float Fss = lerp(1.0f, Fss90, Fo) * lerp(1.0f, Fss90, Fi);
    float f_ss = 1.25f * (Fss * (1.0f / (abs_co + abs_ci) - 0.5f) + 0.5f);
    return lerp(f_diff + f_retro, f_ss, flatness);
}

/* Sheen colour: white tinted towards the base colour's hue. */
static cdl_vec3 sheen_color(cdl_vec3 base, float tint)
{
    float lum = mts_lum(base);
    cdl_vec3 c = lum > 0.0f ? cdl_scale(base, 1.0f / lum) : cdl_v3(1.0f, 1.0f, 1.0f);
    return cdl_v3(lerp(1.0f, c.x, tint), lerp(1.0f, c.y, tint), lerp(1.0f, c.z, tint));
}

/* ---- principled --------------------------------------------------------- */

/* Lobe selection probabilities (sample and pdf share them); F is the
 * dielectric Fresnel term of the main lobe's microfacet. */
static void principled_probs(const cdl_principled_at *p, int front, float F, float pr[4])
{
    float met = p->p[CDL_PR_METALLIC], st = p->p[CDL_PR_SPEC_TRANS];
    float brdf = (1.0f - met) * (1.0f - st), bsdf = (1.0f - met) * st;
    float spec = p->rate[1];
    /* 0 diffuse, 1 clearcoat (a quarter of the main lobe's energy), 2 spec transmission, 3 spec reflection */
    pr[0] = front ? brdf * p->rate[0] : 0.0f;
    pr[1] = front ? 0.25f * p->p[CDL_PR_CLEARCOAT] * p->rate[2] : 0.0f;
    pr[2] = front ? spec * bsdf * (1.0f - F) : 1.0f - F;
    pr[3] = front ? spec * (1.0f - bsdf * (1.0f - F)) : F;
    float tot = pr[0] + pr[1] + pr[2] + pr[3];
    for (int k = 0; k < 4; k++)
        pr[k] = tot > 0.0f ? pr[k] / tot : 0.0f;
}

static cdl_vec3 principled_value(const cdl_principled_at *p, cdl_vec3 base, cdl_vec3 wi, cdl_vec3 wo, int adjoint,
                                 float *pdf)
{
    const float *q = p->p;
    cdl_vec3 v = cdl_v3(0.0f, 0.0f, 0.0f);
    *pdf = 0.0f;
    float cos_i = wi.z, cos_o = wo.z;
    int reflect = cos_i * cos_o > 0.0f, refract = cos_i * cos_o < 0.0f;
    if (cos_i == 0.0f || (!reflect && !refract))
        return v;
    float met = q[CDL_PR_METALLIC], st = q[CDL_PR_SPEC_TRANS], eta = q[CDL_PR_ETA];
    float brdf = (1.0f - met) * (1.0f - st), bsdf = (1.0f - met) * st;
    int front = cos_i > 0.0f;
    float eta_path = front ? eta : 1.0f / eta;
    /* generalized half vector, on the outer side */
    cdl_vec3 wh = cdl_add(wi, cdl_scale(wo, reflect ? 1.0f : eta_path));
    float len = cdl_length(wh);
    if (!(len > 0.0f))
        return v;
    wh = cdl_scale(wh, sign_of(wh.z) / len);
    float ax, ay;
    dist_params(q[CDL_PR_ANISOTROPIC], q[CDL_PR_ROUGHNESS], &ax, &ay);
    float dih = cdl_dot(wi, wh), doh = cdl_dot(wo, wh), sgn = sign_of(cos_i);
    float F = fresnel(dih, eta, NULL, NULL);
    int compat_r = dih * sgn > 0.0f && doh * sgn > 0.0f; /* mac_mic_compatibility */
    int compat_t = dih * sgn > 0.0f && doh * sgn < 0.0f;
    float D = ggx_D(wh, ax, ay), G = ggx_G1(wi, wh, ax, ay) * ggx_G1(wo, wh, ax, ay);

    if (reflect && compat_r && F > 0.0f) /* main specular reflection */
        v = cdl_scale(principled_fresnel(F, q, base, dih, front, bsdf), D * G / (4.0f * fabsf(cos_i)));
    if (bsdf > 0.0f && refract && compat_t && F < 1.0f) {
        /* radiance is compressed by 1 / eta_path^2 (not importance) */
        float scale = adjoint ? 1.0f : 1.0f / (eta_path * eta_path);
        float t = fabsf(scale * (1.0f - F) * D * G * eta_path * eta_path * dih * doh /
                        (cos_i * sqr(dih + eta_path * doh)));
        v = cdl_madd(v, cdl_v3(sqrtf(base.x), sqrtf(base.y), sqrtf(base.z)), bsdf * t);
    }
    if (q[CDL_PR_CLEARCOAT] > 0.0f && reflect && compat_r && front) {
        float Fcc = 0.04f + 0.96f * schlick_w_eta(dih, eta);
        float Dcc = gtr1_D(wh, cc_alpha(q[CDL_PR_CC_GLOSS]));
        float c = q[CDL_PR_CLEARCOAT] * 0.25f * Fcc * Dcc * cc_G1(wi, wh) * cc_G1(wo, wh) * fabsf(cos_o);
        v = cdl_add(v, cdl_v3(c, c, c));
    }
    if (brdf > 0.0f && reflect && front) {
        float d = disney_diffuse(q[CDL_PR_ROUGHNESS], q[CDL_PR_FLATNESS], fabsf(cos_i), fabsf(cos_o), doh);
        v = cdl_madd(v, base, brdf * fabsf(cos_o) * CDL_INV_PI * d);
        if (q[CDL_PR_SHEEN] > 0.0f && 1.0f - met > 0.0f) {
            float s = q[CDL_PR_SHEEN] * (1.0f - met) * schlick_weight(fabsf(doh)) * fabsf(cos_o);
            v = cdl_madd(v, sheen_color(base, q[CDL_PR_SHEEN_TINT]), s);
        }
    }

    float pr[4];
    principled_probs(p, front, F, pr);
    float dwh = reflect ? fabsf(1.0f / (4.0f * doh))
                        : fabsf(eta_path * eta_path * doh / sqr(dih + eta_path * doh));
    float pm = vndf_pdf(cdl_scale(wi, sgn), wh, ax, ay) * dwh, pd = 0.0f;
    if (reflect && compat_r)
        pd += pr[3] * pm + pr[1] * wh.z * gtr1_D(wh, cc_alpha(q[CDL_PR_CC_GLOSS])) * dwh;
    if (reflect)
        pd += pr[0] * cos_o * CDL_INV_PI;
    if (refract && compat_t)
        pd += pr[2] * pm;
    *pdf = pd;
    return v;
}

static int principled_sample(const cdl_principled_at *p, cdl_vec3 wi, float u0, float u1, float u2, cdl_vec3 *wo)
{
    const float *q = p->p;
    float cos_i = wi.z;
    if (cos_i == 0.0f)
        return 0;
    float bsdf = (1.0f - q[CDL_PR_METALLIC]) * q[CDL_PR_SPEC_TRANS];
    int front = cos_i > 0.0f;
    if (!front && !(bsdf > 0.0f))
        return 0; /* inside an opaque material */
    float ax, ay, sgn = sign_of(cos_i);
    dist_params(q[CDL_PR_ANISOTROPIC], q[CDL_PR_ROUGHNESS], &ax, &ay);
    cdl_vec3 m = cdl_ggx_sample_vndf(cdl_scale(wi, sgn), ax, ay, u1, u2);
    float cos_t, eta_ti, dim = cdl_dot(wi, m);
    float F = fresnel(dim, q[CDL_PR_ETA], &cos_t, &eta_ti);
    float pr[4];
    principled_probs(p, front, F, pr);
    cdl_vec3 o;
    if (u0 < pr[0]) {
        o = cdl_sample_cosine_hemisphere(u1, u2);
        return (*wo = o, cos_i * o.z > 0.0f);
    }
    if (u0 < pr[0] + pr[1]) {
        m = gtr1_sample(cc_alpha(q[CDL_PR_CC_GLOSS]), u1, u2);
        dim = cdl_dot(wi, m);
        o = cdl_reflect(wi, m);
        return (*wo = o, dim * sgn > 0.0f && cdl_dot(o, m) * sgn > 0.0f && cos_i * o.z > 0.0f);
    }
    if (u0 < pr[0] + pr[1] + pr[2]) {
        o = cdl_sub(cdl_scale(m, dim * eta_ti + cos_t), cdl_scale(wi, eta_ti)); /* refract */
        return (*wo = o, dim * sgn > 0.0f && cdl_dot(o, m) * sgn < 0.0f && cos_i * o.z < 0.0f);
    }
    o = cdl_reflect(wi, m);
    return (*wo = o, dim * sgn > 0.0f && cdl_dot(o, m) * sgn > 0.0f && cos_i * o.z > 0.0f);
}

/* ---- principledthin ----------------------------------------------------- */

/* Thin lobes are symmetric: wi is turned to the front side first. The
 * specular transmission is a reflection lobe of roughness scaled by
 * (0.65 eta - 0.35) (Burley 2015, fig. 15), mirrored through the sheet. */
static void thin_probs(const cdl_principled_at *p, float pr[4])
{
    float st = p->p[CDL_PR_SPEC_TRANS], dt = 0.5f * p->p[CDL_PR_DIFF_TRANS];
    /* 0 spec reflection, 1 spec transmission, 2 diffuse reflection, 3 diffuse transmission */
    pr[0] = st * p->rate[1] * 0.5f;
    pr[1] = st * p->rate[2] * 0.5f;
    pr[2] = p->rate[0] * (1.0f - st) * (1.0f - dt);
    pr[3] = p->rate[3] * (1.0f - st) * dt;
    float tot = pr[0] + pr[1] + pr[2] + pr[3];
    for (int k = 0; k < 4; k++)
        pr[k] = tot > 0.0f ? pr[k] / tot : 0.0f;
}

static void thin_trans_alphas(const float *q, float *ax, float *ay)
{
    dist_params(q[CDL_PR_ANISOTROPIC], (0.65f * q[CDL_PR_ETA] - 0.35f) * q[CDL_PR_ROUGHNESS], ax, ay);
}

static cdl_vec3 thin_value(const cdl_principled_at *p, cdl_vec3 base, cdl_vec3 wi, cdl_vec3 wo, float *pdf)
{
    const float *q = p->p;
    cdl_vec3 v = cdl_v3(0.0f, 0.0f, 0.0f);
    *pdf = 0.0f;
    if (wi.z == 0.0f)
        return v;
    float sgn = sign_of(wi.z);
    wi = cdl_scale(wi, sgn);
    cdl_vec3 wt = cdl_scale(wo, sgn); /* Mitsuba's wo_t */
    float ci = wi.z, co = wt.z, st = q[CDL_PR_SPEC_TRANS], dt = 0.5f * q[CDL_PR_DIFF_TRANS];
    int reflect = co > 0.0f, refract = co < 0.0f;
    if (!reflect && !refract)
        return v;
    cdl_vec3 wr = cdl_v3(wt.x, wt.y, fabsf(wt.z));
    cdl_vec3 wh = cdl_add(wi, wr);
    float len = cdl_length(wh);
    if (!(len > 0.0f))
        return v;
    wh = cdl_scale(wh, 1.0f / len);
    float dih = cdl_dot(wi, wh), dth = cdl_dot(wt, wh);
    int compat_r = reflect && dih > 0.0f && dth > 0.0f, compat_t = refract && dih > 0.0f && dth < 0.0f;
    float ax, ay, tx, ty;
    dist_params(q[CDL_PR_ANISOTROPIC], q[CDL_PR_ROUGHNESS], &ax, &ay);
    thin_trans_alphas(q, &tx, &ty);

    if (st > 0.0f && (compat_r || compat_t)) {
        float F = fresnel(dih, q[CDL_PR_ETA], NULL, NULL);
        if (compat_r) {
            /* thin_fresnel: the dielectric term blended with a tinted Schlick one */
            float tint = q[CDL_PR_SPEC_TINT], lum = mts_lum(base), w = schlick_w_eta(dih, q[CDL_PR_ETA]);
            float r0 = schlick_r0(q[CDL_PR_ETA]), b[3] = {base.x, base.y, base.z}, Ft[3];
            for (int k = 0; k < 3; k++) {
                float f0 = (lum > 0.0f ? b[k] / lum : 1.0f) * r0;
                Ft[k] = lerp(F, f0 + (1.0f - f0) * w, tint);
            }
            float s = st * ggx_D(wh, ax, ay) * ggx_G1(wi, wh, ax, ay) * ggx_G1(wt, wh, ax, ay) / (4.0f * ci);
            v = cdl_scale(cdl_v3(Ft[0], Ft[1], Ft[2]), s);
        } else {
            float s = st * (1.0f - F) * ggx_D(wh, tx, ty) * ggx_G1(wi, wh, tx, ty) * ggx_G1(wt, wh, tx, ty) /
                      (4.0f * ci);
            v = cdl_scale(base, s);
        }
    }
    if (reflect && st < 1.0f && dt < 1.0f) {
        float d = disney_diffuse(q[CDL_PR_ROUGHNESS], q[CDL_PR_FLATNESS], ci, co, dth);
        v = cdl_madd(v, base, (1.0f - st) * co * CDL_INV_PI * (1.0f - dt) * d);
        if (q[CDL_PR_SHEEN] > 0.0f) {
            float s = q[CDL_PR_SHEEN] * (1.0f - st) * schlick_weight(fabsf(dth)) * (1.0f - dt) * co;
            v = cdl_madd(v, sheen_color(base, q[CDL_PR_SHEEN_TINT]), s);
        }
    }
    if (refract && st < 1.0f && dt > 0.0f)
        v = cdl_madd(v, base, (1.0f - st) * dt * CDL_INV_PI * -co);

    float pr[4], pd = 0.0f, dwh = fabsf(1.0f / (4.0f * cdl_dot(wr, wh)));
    thin_probs(p, pr);
    if (compat_r)
        pd += pr[0] * vndf_pdf(wi, wh, ax, ay) * dwh;
    if (compat_t)
        pd += pr[1] * vndf_pdf(wi, wh, tx, ty) * dwh;
    pd += reflect ? pr[2] * co * CDL_INV_PI : pr[3] * -co * CDL_INV_PI;
    *pdf = pd;
    return v;
}

static int thin_sample(const cdl_principled_at *p, cdl_vec3 wi, float u0, float u1, float u2, cdl_vec3 *wo)
{
    if (wi.z == 0.0f)
        return 0;
    float sgn = sign_of(wi.z), pr[4], ax, ay;
    wi = cdl_scale(wi, sgn);
    thin_probs(p, pr);
    cdl_vec3 o;
    int ok;
    if (u0 < pr[0] + pr[1]) {
        int trans = u0 >= pr[0];
        if (trans)
            thin_trans_alphas(p->p, &ax, &ay);
        else
            dist_params(p->p[CDL_PR_ANISOTROPIC], p->p[CDL_PR_ROUGHNESS], &ax, &ay);
        cdl_vec3 m = cdl_ggx_sample_vndf(wi, ax, ay, u1, u2);
        o = cdl_reflect(wi, m);
        if (trans)
            o.z = -o.z;
        float dom = cdl_dot(o, m);
        ok = cdl_dot(wi, m) > 0.0f && (trans ? dom < 0.0f && o.z < 0.0f : dom > 0.0f && o.z > 0.0f);
    } else {
        o = cdl_sample_cosine_hemisphere(u1, u2);
        if (u0 >= pr[0] + pr[1] + pr[2])
            o = cdl_neg(o);
        ok = 1;
    }
    *wo = cdl_scale(o, sgn);
    return ok;
}

/* ---- entry points -------------------------------------------------------- */

cdl_vec3 cdl_principled_local(const cdl_principled_at *p, cdl_vec3 base, cdl_vec3 wi, cdl_vec3 wo, int adjoint,
                              float *pdf)
{
    return p->thin ? thin_value(p, base, wi, wo, pdf) : principled_value(p, base, wi, wo, adjoint, pdf);
}

int cdl_principled_sample_local(const cdl_principled_at *p, cdl_vec3 wi, float u0, float u1, float u2,
                                cdl_vec3 *wo)
{
    return p->thin ? thin_sample(p, wi, u0, u1, u2, wo) : principled_sample(p, wi, u0, u1, u2, wo);
}

/* Local directions; 0 when the geometric normal and the shading frame
 * disagree on reflection vs transmission (as for rough glass). */
static int to_local(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, cdl_vec3 *lo, cdl_vec3 *li)
{
    *lo = cdl_to_local(&b->frame, wo);
    *li = cdl_to_local(&b->frame, wi);
    return cdl_dot(wo, b->ng) * cdl_dot(wi, b->ng) * (lo->z * li->z) >= 0.0f;
}

cdl_vec3 cdl_principled_eval(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int adjoint)
{
    cdl_vec3 lo, li;
    float pdf;
    if (!to_local(b, wo, wi, &lo, &li) || li.z == 0.0f)
        return cdl_v3(0.0f, 0.0f, 0.0f);
    return cdl_scale(cdl_principled_local(&b->pr, b->kd, lo, li, adjoint, &pdf), 1.0f / fabsf(li.z));
}

float cdl_principled_pdf(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    cdl_vec3 lo, li;
    float pdf = 0.0f;
    if (to_local(b, wo, wi, &lo, &li))
        cdl_principled_local(&b->pr, b->kd, lo, li, 0, &pdf);
    return pdf;
}

int cdl_principled_sample(const cdl_bsdf *b, cdl_vec3 wo, float u0, float u1, float u2, int adjoint,
                          cdl_scatter *s)
{
    cdl_vec3 lo = cdl_to_local(&b->frame, wo), li;
    if (!cdl_principled_sample_local(&b->pr, lo, u0, u1, u2, &li))
        return 0;
    float pdf;
    cdl_vec3 v = cdl_principled_local(&b->pr, b->kd, lo, li, adjoint, &pdf);
    if (!(pdf > 0.0f) || !cdl_is_finite3(v))
        return 0;
    cdl_vec3 wi = cdl_normalize(cdl_to_world(&b->frame, li));
    if (cdl_dot(wo, b->ng) * cdl_dot(wi, b->ng) * (lo.z * li.z) < 0.0f)
        return 0; /* the geometric sides disagree with the shading frame */
    s->wi = wi;
    s->delta = 0;
    s->pdf = pdf;
    s->weight = cdl_scale(v, 1.0f / pdf);
    return 1;
}
