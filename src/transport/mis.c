#include "transport/mis.h"

#include <math.h>

static float remap0(float x) { return x != 0.0f ? x : 1.0f; }

/* x^beta for the two heuristics: powf is needlessly slow here */
static float hpow(float x, int power) { return power ? x * x : x; }

static float count(const cdl_mis_counts *n, int s, int t)
{
    if (s == 0)
        return n->eye;
    if (t == 1)
        return n->light_trace;
    return s == 1 && n->connect_s1 > 0.0f ? n->connect_s1 : n->connect;
}

/* §3.2: the strategy whose connecting edge is the first edge, counted
 * from z_1, with G below the threshold. Edges at delta vertices cannot be
 * connected and are skipped; a path ending on a delta light must be
 * connected at its last edge; a path without such an edge is left to the
 * eye path alone (s = 0). */
static float stratified(const cdl_mis_vertex *v, int s, int t, int delta_light, float thr)
{
    int L = s + t - 1;
    int designated = -1; /* edge (z_k, z_k+1) */
    int last = s == 0 ? L - 1 : t - 1; /* edges past the connection cannot matter */
    for (int k = 1; k <= last; k++) {
        if (v[k].delta || v[k + 1].delta)
            continue;
        if (v[k].g_next < thr || (k + 1 == L && delta_light)) {
            designated = k;
            break;
        }
    }
    if (s == 0)
        return designated < 0 ? 1.0f : 0.0f;
    if (t == 1)
        return 0.0f;
    return designated == t - 1 ? 1.0f : 0.0f;
}

float cdl_mis_weight(cdl_mis_kind kind, const cdl_mis_vertex *v, int s, int t, int delta_light,
                     const cdl_mis_counts *n, float threshold)
{
    if (kind == CDL_MIS_STRATIFIED)
        return stratified(v, s, t, delta_light, threshold);
    if (kind == CDL_MIS_LIGHT_TRACING)
        return (t == 1 || s + t == 2) ? 1.0f : 0.0f;
    if (s + t == 2)
        return 1.0f;
    int pw = kind == CDL_MIS_POWER;
    /* s = 1 may sample the light point differently from the light paths:
     * its density enters that one strategy only */
    int L = s + t - 1;
    float q = v[L].pdf_s1 > 0.0f && v[L].pdf_light > 0.0f ? v[L].pdf_s1 / v[L].pdf_light : 1.0f;
    float here = count(n, s, t) * (s == 1 ? q : 1.0f), sum = 0.0f, r = 1.0f, eta = n->merge;
#define CORR(sp, tp) hpow(count(n, sp, tp) * ((sp) == 1 ? q : 1.0f) / here, pw)
    /* moving the connection towards the camera: fewer eye vertices */
    for (int i = t - 1; i > 0; i--) {
        r *= hpow(remap0(v[i].pdf_light) / remap0(v[i].pdf_eye), pw);
        if (!v[i].delta && !v[i - 1].delta)
            sum += r * CORR(s + t - i, i);
        if (eta > 0.0f && i < L && !v[i].delta) /* merging at z_i: (t = i) x pe(z_i) eta */
            sum += r * hpow(eta * remap0(v[i].pdf_eye) / here, pw);
    }
    /* towards the light: fewer light vertices */
    r = 1.0f;
    for (int i = t; i < s + t; i++) {
        r *= hpow(remap0(v[i].pdf_eye) / remap0(v[i].pdf_light), pw);
        int delta_prev = i + 1 < s + t ? v[i + 1].delta : delta_light;
        if (!v[i].delta && !delta_prev)
            sum += r * CORR(s + t - i - 1, i + 1);
        if (eta > 0.0f && i < L && !v[i].delta) /* merging at z_i: (t = i + 1) x pl(z_i) eta */
            sum += r * hpow(eta * remap0(v[i].pdf_light) / here, pw);
    }
#undef CORR
    return 1.0f / (1.0f + sum);
}

float cdl_mis_weight_merge(cdl_mis_kind kind, const cdl_mis_vertex *v, int n, int k, int delta_light,
                           const cdl_mis_counts *c)
{
    int pw = kind == CDL_MIS_POWER, L = n - 1;
    float eta = c->merge;
    if (!(eta > 0.0f) || k < 1 || k >= L)
        return 0.0f;
    float q = v[L].pdf_s1 > 0.0f && v[L].pdf_light > 0.0f ? v[L].pdf_s1 / v[L].pdf_light : 1.0f;
    /* every term relative to the connection (t = k): eye subpath z_0 ..
     * z_{k-1}, light subpath z_k .. z_L; this merge is that times pe(z_k) eta */
    float here = hpow(eta * remap0(v[k].pdf_eye), pw), sum = here, r = 1.0f;
#define TERM(sp, tp) hpow(count(c, sp, tp) * ((sp) == 1 ? q : 1.0f), pw)
    if (!v[k].delta && !v[k - 1].delta)
        sum += TERM(n - k, k);
    for (int i = k - 1; i > 0; i--) { /* fewer eye vertices: r = (t = i) / (t = k) */
        r *= hpow(remap0(v[i].pdf_light) / remap0(v[i].pdf_eye), pw);
        if (!v[i].delta && !v[i - 1].delta)
            sum += r * TERM(n - i, i);
        if (!v[i].delta)
            sum += r * hpow(eta * remap0(v[i].pdf_eye), pw);
    }
    r = 1.0f;
    for (int i = k; i < n; i++) { /* fewer light vertices: r = (t = i + 1) / (t = k) */
        r *= hpow(remap0(v[i].pdf_eye) / remap0(v[i].pdf_light), pw);
        int delta_prev = i + 1 < n ? v[i + 1].delta : delta_light;
        if (!v[i].delta && !delta_prev)
            sum += r * TERM(L - i, i + 1);
        if (i > k && i < L && !v[i].delta)
            sum += r * hpow(eta * remap0(v[i].pdf_light), pw);
    }
#undef TERM
    return here / sum;
}
