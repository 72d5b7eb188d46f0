#include "transport/connect.h"

#include "transport/subpath.h"

#define MAX_PATH 1100 /* > maxdepth limit (1024) + 3 */

cdl_vec3 cdl_light_emit_factor(const cdl_light *l, cdl_vec3 n, cdl_vec3 w)
{
    switch (l->type) {
    case CDL_LIGHT_POINT:
    case CDL_LIGHT_SPOT:
    case CDL_LIGHT_PROJECTOR:
        return cdl_light_I_factor(l, w);
    case CDL_LIGHT_TRIANGLE:
    case CDL_LIGHT_SPHERE: {
        float k = cdl_is_black(cdl_light_Le(l, n, w)) ? 0.0f : 1.0f;
        return cdl_v3(k, k, k);
    }
    default: /* at infinity: the sampled radiance is in the vertex's throughput */
        return cdl_v3(1.0f, 1.0f, 1.0f);
    }
}

int cdl_visible(const cdl_scene *s, cdl_vec3 pa, cdl_vec3 na, cdl_vec3 pb, cdl_vec3 nb,
                uint32_t skip_sphere)
{
    cdl_vec3 d = cdl_sub(pb, pa);
    cdl_vec3 o = cdl_is_black(na) ? pa : cdl_offset(s, pa, na, d);
    cdl_vec3 e = cdl_is_black(nb) ? pb : cdl_offset(s, pb, nb, cdl_neg(d));
    cdl_vec3 de = cdl_sub(e, o);
    float len = cdl_length(de);
    if (!(len > 0.0f))
        return 1;
    return !cdl_occluded_skip(s, o, cdl_scale(de, 1.0f / len), len, skip_sphere);
}

/* The sphere a light vertex y_0 lies on, for cdl_visible. */
static uint32_t light_sphere(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i)
{
    if (!(vs->flags[i] & CDL_V_LIGHT))
        return UINT32_MAX;
    const cdl_light *l = &cx->scene->lights[vs->light[i]];
    return l->type == CDL_LIGHT_SPHERE ? l->prim : UINT32_MAX;
}

/* Normal used for area-density conversions and cosines: none for the
 * camera and for point and spot lights. */
cdl_vec3 cdl_vertex_normal(const cdl_vertex_store *vs, uint32_t i)
{
    if (vs->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA_LIGHT))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    return vs->ng[i];
}

static cdl_vec3 vshading(const cdl_vertex_store *vs, uint32_t i)
{
    if (vs->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA_LIGHT))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    return vs->ns[i];
}

float cdl_vertex_pdf_sa_bsdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                             const cdl_bsdf *b, cdl_vec3 from, cdl_vec3 w)
{
    float pdf_sa;
    if (vs->flags[i] & CDL_V_CAMERA)
        cdl_camera_We(cx->cam, w, &pdf_sa);
    else if (vs->flags[i] & CDL_V_LIGHT)
        pdf_sa = cdl_light_pdf_dir(&cx->scene->lights[vs->light[i]], vs->ng[i], w);
    else
        pdf_sa = cdl_bsdf_pdf(b, cdl_normalize(cdl_sub(from, vs->p[i])), w);
    return pdf_sa;
}

float cdl_vertex_pdf_sa(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i, cdl_vec3 from,
                        cdl_vec3 w)
{
    cdl_bsdf b;
    if (!(vs->flags[i] & (CDL_V_CAMERA | CDL_V_LIGHT)))
        cdl_vs_bsdf(cx->scene, vs, i, &b);
    return cdl_vertex_pdf_sa_bsdf(cx, vs, i, &b, from, w);
}

float cdl_vertex_pdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i, cdl_vec3 from,
                     cdl_vec3 to, cdl_vec3 nt)
{
    cdl_vec3 p = vs->p[i];
    cdl_vec3 w = cdl_sub(to, p);
    float len = cdl_length(w);
    if (!(len > 0.0f))
        return 0.0f;
    if (vs->flags[i] & CDL_V_INFINITE) /* a light at infinity reaches `to` from its disk */
        return cdl_light_pdf_disk(&cx->scene->lights[vs->light[i]], cdl_scale(w, 1.0f / len), nt);
    return cdl_pdf_to_area(cdl_vertex_pdf_sa(cx, vs, i, from, cdl_scale(w, 1.0f / len)), p, to, nt);
}

/* The density of vertex i (of vs, reached from `from`) choosing vertex j
 * of ws: in area measure, or in solid angle when j lies at infinity. */
static float pdf_to(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i, cdl_vec3 from,
                    const cdl_vertex_store *ws, uint32_t j)
{
    if (ws->flags[j] & CDL_V_INFINITE)
        return cdl_vertex_pdf_sa(cx, vs, i, from, cdl_normalize(cdl_sub(ws->p[j], vs->p[i])));
    return cdl_vertex_pdf(cx, vs, i, from, ws->p[j], cdl_vertex_normal(ws, j));
}

/* f at vertex i for light arriving from `from` and leaving to `to` (eye
 * vertices: radiance mode; light vertices: importance mode with Veach's
 * shading-normal correction; y_0: the emission distribution). */
cdl_vec3 cdl_vertex_f_bsdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                           const cdl_bsdf *b, cdl_vec3 from, cdl_vec3 to, int light_side)
{
    cdl_vec3 p = vs->p[i];
    cdl_vec3 wt = cdl_normalize(cdl_sub(to, p));
    if (vs->flags[i] & CDL_V_LIGHT) {
        return cdl_light_emit_factor(&cx->scene->lights[vs->light[i]], vs->ng[i], wt);
    }
    cdl_vec3 wf = cdl_normalize(cdl_sub(from, p));
    if (!light_side)
        return cdl_bsdf_eval(b, wf, wt, 0);
    cdl_vec3 f = cdl_bsdf_eval(b, wf, wt, 1);
    float num = fabsf(cdl_dot(wf, vs->ns[i])) * fabsf(cdl_dot(wt, vs->ng[i]));
    float den = fabsf(cdl_dot(wf, vs->ng[i])) * fabsf(cdl_dot(wt, vs->ns[i]));
    return cdl_scale(f, den > 0.0f ? num / den : 0.0f);
}

cdl_vec3 cdl_vertex_f(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                      cdl_vec3 from, cdl_vec3 to, int light_side)
{
    cdl_bsdf b;
    if (!(vs->flags[i] & CDL_V_LIGHT))
        cdl_vs_bsdf(cx->scene, vs, i, &b);
    return cdl_vertex_f_bsdf(cx, vs, i, &b, from, to, light_side);
}

/* Area density of next-event estimation choosing light point y (normal n)
 * of light `li` from z: only spheres (sampled by solid angle) differ from
 * the light paths' uniform area density. */
static float resample_pdf(const cdl_connect_ctx *cx, int32_t li, cdl_vec3 y, cdl_vec3 n, cdl_vec3 z)
{
    const cdl_light *l = &cx->scene->lights[li];
    if (!cx->resample_s1 || l->type != CDL_LIGHT_SPHERE)
        return 0.0f;
    cdl_vec3 d = cdl_sub(y, z);
    float dist = cdl_length(d);
    if (!(dist > 0.0f))
        return 0.0f;
    cdl_vec3 w = cdl_scale(d, 1.0f / dist);
    float sa = cdl_light_pdf_li(l, z, w, dist);
    return cx->scene->light_select.pmf[li] * sa * fabsf(cdl_dot(n, w)) / (dist * dist);
}

/* The sample counts for a path whose light is (at_inf) or is not at
 * infinity: their s = 1 strategy may be sampled differently. */
static cdl_mis_counts path_counts(const cdl_connect_ctx *cx, int at_inf)
{
    cdl_mis_counts n = cx->counts ? *cx->counts : (cdl_mis_counts){1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.0f};
    n.connect_s1 = at_inf && n.s1_infinite > 0.0f ? n.s1_infinite : 0.0f;
    return n;
}

/* MIS records of the full path: eye vertices 0..t-1, then light vertices
 * s-1..0 (indices l0 + j). */
static void fill_records(cdl_mis_vertex *v, const cdl_vertex_store *evs, uint32_t t,
                         const cdl_vertex_store *lvs, uint32_t l0, uint32_t s, int need_g)
{
    for (uint32_t k = 0; k < t; k++) {
        v[k].pdf_eye = evs->pdf_fwd[k];
        v[k].pdf_light = evs->pdf_rev[k];
        v[k].delta = (evs->flags[k] & CDL_V_DELTA) != 0;
        v[k].g_next = 0.0f;
        v[k].pdf_s1 = 0.0f;
        if (need_g && k + 1 < t)
            v[k].g_next = cdl_geometry(evs->p[k], cdl_vertex_normal(evs, k), evs->p[k + 1], cdl_vertex_normal(evs, k + 1));
    }
    for (uint32_t j = 0; j < s; j++) {
        uint32_t k = s + t - 1 - j, i = l0 + j;
        v[k].pdf_eye = lvs->pdf_rev[i];
        v[k].pdf_light = lvs->pdf_fwd[i];
        v[k].delta = (lvs->flags[i] & CDL_V_DELTA) != 0;
        v[k].g_next = 0.0f;
        v[k].pdf_s1 = 0.0f;
    }
}

cdl_vec3 cdl_connect_eye_only(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t)
{
    uint32_t i = t - 1;
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    if (!(evs->flags[i] & CDL_V_EMITTER))
        return zero;
    const cdl_light *l = &cx->scene->lights[evs->light[i]];
    int inf = (evs->flags[i] & CDL_V_INFINITE) != 0;
    cdl_vec3 d = cdl_neg(evs->wi[i]); /* at infinity: towards the sky */
    cdl_vec3 Le = inf ? cdl_light_env_Le(l, d) : cdl_light_Le_uv(l, evs->ng[i], evs->wi[i], evs->u[i], evs->v[i]);
    if (cdl_is_black(Le))
        return zero;
    cdl_vec3 c = cdl_mul(evs->beta[i], Le);
    if (t == 2 && cx->mis != CDL_MIS_STRATIFIED)
        return c;
    cdl_mis_vertex v[MAX_PATH];
    if (t > MAX_PATH)
        return zero;
    fill_records(v, evs, t, NULL, 0, 0, cx->mis == CDL_MIS_STRATIFIED);
    if (inf) { /* pbrt-v3's densities for a light at infinity */
        v[i].pdf_light = cdl_light_pdf_infinite(cx->scene, d);
        v[i - 1].pdf_light = cdl_light_pdf_disk(l, d, cdl_vertex_normal(evs, i - 1));
        v[i - 1].g_next = 0.0f; /* G to infinity */
    } else {
        v[i].pdf_light = cdl_light_pdf_origin(cx->scene, evs->light[i]);
        v[i].pdf_s1 = resample_pdf(cx, evs->light[i], evs->p[i], evs->ng[i], evs->p[i - 1]);
        v[i - 1].pdf_light = cdl_pdf_to_area(cdl_light_pdf_dir(l, evs->ng[i], evs->wi[i]), evs->p[i],
                                             evs->p[i - 1], cdl_vertex_normal(evs, i - 1));
    }
    v[i].delta = 0;
    cdl_mis_counts n = path_counts(cx, inf);
    return cdl_scale(c, cdl_mis_weight(cx->mis, v, 0, (int)t, 0, &n, cx->threshold));
}

cdl_vec3 cdl_connect(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t,
                     const cdl_vertex_store *lvs, uint32_t l0, uint32_t s, uint64_t *rays)
{
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t pt = t - 1, qs = l0 + s - 1;
    if ((evs->flags[pt] & (CDL_V_DELTA | CDL_V_INFINITE)) || (lvs->flags[qs] & CDL_V_DELTA) || s + t > MAX_PATH)
        return zero;
    cdl_vec3 pp = evs->p[pt], qp = lvs->p[qs];
    cdl_vec3 pm = evs->p[pt - 1];
    cdl_vec3 qm = s >= 2 ? lvs->p[qs - 1] : qp;
    cdl_vec3 fe = cdl_vertex_f(cx, evs, pt, pm, qp, 0);
    if (cdl_is_black(fe))
        return zero;
    cdl_vec3 fl = cdl_vertex_f(cx, lvs, qs, qm, pp, 1);
    if (cdl_is_black(fl))
        return zero;
    float G = cdl_geometry(pp, vshading(evs, pt), qp, vshading(lvs, qs));
    cdl_vec3 c = cdl_mul(cdl_mul(evs->beta[pt], fe), cdl_mul(lvs->beta[qs], fl));
    c = cdl_scale(c, G);
    if (cdl_is_black(c))
        return zero;
    cdl_mis_vertex v[MAX_PATH];
    int strat = cx->mis == CDL_MIS_STRATIFIED;
    fill_records(v, evs, t, lvs, l0, s, strat);
    cdl_vec3 np = cdl_vertex_normal(evs, pt), nq = cdl_vertex_normal(lvs, qs);
    v[pt].g_next = cdl_geometry(pp, np, qp, nq);
    /* densities through the new edge, both ways (pbrt-v3's MISWeight) */
    v[pt].pdf_light = pdf_to(cx, lvs, qs, qm, evs, pt);
    v[pt - 1].pdf_light = pdf_to(cx, evs, pt, qp, evs, pt - 1);
    v[t].pdf_eye = pdf_to(cx, evs, pt, pm, lvs, qs);
    if (lvs->flags[qs] & CDL_V_INFINITE)
        v[pt].g_next = 0.0f; /* G to infinity */
    if (s >= 2)
        v[t + 1].pdf_eye = pdf_to(cx, lvs, qs, pp, lvs, qs - 1);
    v[pt].delta = v[t].delta = 0;
    v[s + t - 1].pdf_s1 = resample_pdf(cx, lvs->light[l0], lvs->p[l0], lvs->ng[l0],
                                       s >= 2 ? lvs->p[l0 + 1] : pp);
    int delta_light = (lvs->flags[l0] & CDL_V_DELTA_LIGHT) != 0;
    cdl_mis_counts n = path_counts(cx, (lvs->flags[l0] & CDL_V_INFINITE) != 0);
    float w = cdl_mis_weight(cx->mis, v, (int)s, (int)t, delta_light, &n, cx->threshold);
    if (w <= 0.0f)
        return zero;
    (*rays)++;
    if (!cdl_visible(cx->scene, pp, np, qp, nq, light_sphere(cx, lvs, qs)))
        return zero;
    return cdl_scale(c, w);
}

cdl_vec3 cdl_connect_camera(const cdl_connect_ctx *cx, const cdl_vertex_store *lvs, uint32_t l0,
                            uint32_t s, float *x, float *y, uint64_t *rays)
{
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t qs = l0 + s - 1;
    if (s < 2 || (lvs->flags[qs] & CDL_V_DELTA) || s + 1 > MAX_PATH)
        return zero;
    const cdl_camera *cam = cx->cam;
    cdl_vec3 qp = lvs->p[qs], qm = lvs->p[qs - 1];
    cdl_vec3 d = cdl_sub(qp, cam->eye);
    float d2 = cdl_dot(d, d);
    if (!(d2 > 0.0f))
        return zero;
    cdl_vec3 w = cdl_scale(d, 1.0f / sqrtf(d2));
    if (!cdl_camera_raster(cam, w, x, y))
        return zero;
    float pdf_cam;
    float We = cdl_camera_We(cam, w, &pdf_cam);
    float cos_cam = cdl_dot(w, cam->fwd) / cdl_length(cam->fwd);
    cdl_vec3 fl = cdl_vertex_f(cx, lvs, qs, qm, cam->eye, 1);
    float cos_q = fabsf(cdl_dot(w, lvs->ns[qs]));
    cdl_vec3 c = cdl_scale(cdl_mul(lvs->beta[qs], fl), We * cos_cam / d2 * cos_q);
    if (cdl_is_black(c))
        return zero;
    cdl_mis_vertex v[MAX_PATH];
    fill_records(v, NULL, 0, lvs, l0, s, 0);
    /* shift: record 0 is the camera */
    for (uint32_t k = s; k > 0; k--)
        v[k] = v[k - 1];
    v[0].pdf_eye = 1.0f;
    v[0].pdf_light = 0.0f;
    v[0].delta = 0;
    v[0].g_next = 0.0f;
    v[0].pdf_s1 = 0.0f;
    v[s].pdf_s1 = resample_pdf(cx, lvs->light[l0], lvs->p[l0], lvs->ng[l0], lvs->p[l0 + 1]);
    cdl_vec3 nq = cdl_vertex_normal(lvs, qs);
    v[1].pdf_eye = cdl_pdf_to_area(pdf_cam, cam->eye, qp, nq);
    v[2].pdf_eye = pdf_to(cx, lvs, qs, cam->eye, lvs, qs - 1);
    v[1].delta = 0;
    int delta_light = (lvs->flags[l0] & CDL_V_DELTA_LIGHT) != 0;
    cdl_mis_counts n = path_counts(cx, (lvs->flags[l0] & CDL_V_INFINITE) != 0);
    float wgt = cdl_mis_weight(cx->mis, v, (int)s, 1, delta_light, &n, cx->threshold);
    if (wgt <= 0.0f)
        return zero;
    (*rays)++;
    if (!cdl_visible(cx->scene, cam->eye, cdl_v3(0.0f, 0.0f, 0.0f), qp, nq, UINT32_MAX))
        return zero;
    return cdl_scale(c, wgt);
}

cdl_vec3 cdl_connect_resampled(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t,
                               cdl_sampler *smp, cdl_vertex_store *tmp, int only_infinite, uint64_t *rays)
{
    /* The temporary vertex carries 1 / (its actual density) as throughput
     * but the light-path origin density for MIS, so the weights stay a
     * partition of unity. */
    const cdl_scene *s = cx->scene;
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    float us, ua, u1, u2, pmf;
    smp->dim = 2 * t;
    cdl_sampler_2d(smp, &us, &ua);
    cdl_sampler_2d(smp, &u1, &u2);
    uint32_t pt = t - 1;
    if (evs->flags[pt] & (CDL_V_DELTA | CDL_V_INFINITE))
        return zero;
    uint32_t li = cdl_alias_sample(&s->light_select, us, ua, &pmf);
    const cdl_light *l = &s->lights[li];
    cdl_light_sample ls;
    if (!cdl_light_sample_li(l, evs->p[pt], u1, u2, &ls))
        return zero;
    cdl_vec3 n = zero, Le = l->L;
    float pdf_area = ls.pdf; /* delta lights: 1 */
    int inf = cdl_light_at_infinity(l);
    if (only_infinite && !inf)
        return zero;
    if (inf) {
        /* a point 2 R away along the sampled direction: the 1 / d^2 of the
         * connection's G cancels in the throughput */
        cdl_vec3 dd = cdl_sub(ls.p, evs->p[pt]);
        float d2 = cdl_dot(dd, dd);
        pdf_area = ls.pdf / d2;
        Le = ls.Li;
    } else if (l->type == CDL_LIGHT_TRIANGLE || l->type == CDL_LIGHT_SPHERE) {
        n = l->type == CDL_LIGHT_TRIANGLE ? l->n : cdl_normalize(cdl_sub(ls.p, l->p));
        if (l->type == CDL_LIGHT_SPHERE && l->inward)
            n = cdl_neg(n);
        float c = fabsf(cdl_dot(n, ls.wi));
        pdf_area = ls.pdf * c / (ls.dist * ls.dist);
    }
    if (!(pdf_area > 0.0f))
        return zero;
    cdl_vs_clear(tmp);
    tmp->n = 1;
    tmp->p[0] = ls.p;
    tmp->ng[0] = tmp->ns[0] = n;
    tmp->wi[0] = zero;
    tmp->beta[0] = cdl_scale(Le, 1.0f / (pmf * pdf_area));
    tmp->pdf_fwd[0] = inf ? cdl_light_pdf_infinite(s, ls.wi) : cdl_light_pdf_origin(s, (int32_t)li);
    tmp->pdf_rev[0] = 0.0f;
    tmp->parent[0] = -1;
    tmp->light[0] = (int32_t)li;
    tmp->depth[0] = 0;
    tmp->flags[0] = CDL_V_LIGHT | (cdl_light_is_delta(l) ? CDL_V_DELTA_LIGHT : 0) | (inf ? CDL_V_INFINITE : 0);
    return cdl_connect(cx, evs, t, tmp, 0, 1, rays);
}

cdl_vec3 cdl_connect_all(const cdl_connect_ctx *cx_in, int maxdepth, const cdl_vertex_store *evs, uint32_t ne,
                         const cdl_vertex_store *lvs, uint32_t l0, uint32_t nl, int with_eye_only,
                         cdl_splats *splats, float splat_scale, cdl_sampler *resample, cdl_vertex_store *tmp,
                         uint64_t *rays)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_connect_ctx cx = *cx_in;
    cx.resample_s1 = resample != NULL;
    const cdl_camera *cam = cx.cam;
    for (uint32_t t = 1; t <= ne; t++) {
        for (uint32_t sidx = with_eye_only ? 0 : 1; sidx <= nl; sidx++) {
            if (sidx + t < 2 || (int)(sidx + t) - 2 > maxdepth)
                continue;
            if (t == 1) {
                /* s = 1, t = 1 would repeat the light seen directly (s = 0, t = 2) */
                if (sidx < 2 || !splats)
                    continue;
                float x, y;
                cdl_vec3 c = cdl_connect_camera(&cx, lvs, l0, sidx, &x, &y, rays);
                if (!cdl_is_black(c))
                    cdl_splats_add_filtered(splats, &cam->filter, cam->width, cam->height, x, y,
                                            cdl_scale(c, splat_scale));
                continue;
            }
            if (sidx == 0) {
                if (with_eye_only)
                    L = cdl_add(L, cdl_connect_eye_only(&cx, evs, t));
                continue;
            }
            if (sidx == 1 && resample)
                L = cdl_add(L, cdl_connect_resampled(&cx, evs, t, resample, tmp, 0, rays));
            else if (sidx == 1 && (lvs->flags[l0] & CDL_V_INFINITE))
                continue; /* no point light on the disk: resampled once per eye vertex instead */
            else
                L = cdl_add(L, cdl_connect(&cx, evs, t, lvs, l0, sidx, rays));
        }
    }
    return L;
}

float cdl_merge_weight(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t, const cdl_bsdf *b,
                       const cdl_vertex_store *lvs, uint32_t l0, uint32_t s)
{
    uint32_t pt = t - 1, qs = l0 + s - 1, n = t + s - 1;
    if (t < 2 || s < 2 || n > MAX_PATH)
        return 0.0f;
    cdl_mis_vertex v[MAX_PATH];
    /* eye records 0 .. t-1, then the light subpath's y_{s-2} .. y_0 (its
     * y_{s-1} is the merge vertex, record t-1) */
    fill_records(v, evs, t, lvs, l0, s - 1, 0);
    cdl_vec3 x = evs->p[pt], wo = evs->wi[pt], wl = lvs->wi[qs];
    v[pt].pdf_light = lvs->pdf_fwd[qs];
    v[pt].delta = 0;
    if (pt >= 2) /* z_{t-2} sampled from the merge vertex (along wo, as f sees it), light arriving along wl */
        v[pt - 1].pdf_light = cdl_pdf_to_area(cdl_bsdf_pdf(b, wl, wo), x, evs->p[pt - 1], cdl_vertex_normal(evs, pt - 1));
    /* y_{s-2} sampled from the merge vertex, the eye arriving along wo; at
     * the light subpath's own distance, as its y_{s-1} lies there */
    float pdf_sa = cdl_bsdf_pdf(b, wo, wl);
    v[t].pdf_eye = (lvs->flags[qs - 1] & CDL_V_INFINITE)
                       ? pdf_sa
                       : cdl_pdf_to_area(pdf_sa, lvs->p[qs], lvs->p[qs - 1], cdl_vertex_normal(lvs, qs - 1));
    v[n - 1].pdf_s1 = resample_pdf(cx, lvs->light[l0], lvs->p[l0], lvs->ng[l0], lvs->p[l0 + 1]);
    int delta_light = (lvs->flags[l0] & CDL_V_DELTA_LIGHT) != 0;
    cdl_mis_counts c = path_counts(cx, (lvs->flags[l0] & CDL_V_INFINITE) != 0);
    return cdl_mis_weight_merge(cx->mis, v, (int)n, (int)pt, delta_light, &c);
}

/* x^b of the heuristic, and pbrt's zero-density convention (the walk's) */
static float hp(cdl_mis_kind kind, float x) { return kind == CDL_MIS_POWER ? x * x : x; }
static float nz(float x) { return x != 0.0f ? x : 1.0f; }

void cdl_merge_partials_eye(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t ne, float *b1,
                            float *b2, float *ge)
{
    /* S(k) = X_{k-1} + H(k-2): the walk's eye-side terms of a merge at z_k
     * (relative to the connection t = k), all but its last factor
     * pl(z_{k-1}) / pe(z_{k-1}); X_i = connection t = i + merge at z_i */
    cdl_mis_kind kd = cx->mis;
    cdl_mis_counts c = path_counts(cx, 0);
    float eta = c.merge, S = 0.0f;
    for (uint32_t k = 1; k < ne; k++) {
        int dk = (evs->flags[k] & CDL_V_DELTA) != 0, dp = (evs->flags[k - 1] & CDL_V_DELTA) != 0;
        float here = hp(kd, eta * nz(evs->pdf_fwd[k]));
        float term = hp(kd, k == 1 ? c.light_trace : c.connect);
        b1[k] = dp ? 0.0f : term / here;
        b2[k] = S / hp(kd, nz(evs->pdf_fwd[k - 1])) / here;
        ge[k] = cdl_pdf_to_area(1.0f, evs->p[k], evs->p[k - 1], cdl_vertex_normal(evs, k - 1));
        float X = (!dk && !dp ? term : 0.0f) + (!dk ? here : 0.0f);
        float rho = k >= 2 ? hp(kd, nz(evs->pdf_rev[k - 1]) / nz(evs->pdf_fwd[k - 1])) : 0.0f;
        S = X + rho * S;
    }
}

void cdl_merge_partials_light(const cdl_connect_ctx *cx, const cdl_vertex_store *lvs, uint32_t l0, uint32_t nl,
                              float *a1, float *a2, float *gl)
{
    /* J(a): the walk's light-side terms beyond y_a (the connection cut
     * between y_a and y_{a-1}, merges at y_1 .. y_a, and so on down to s =
     * 0), relative to the light subpath ending at y_a */
    cdl_mis_kind kd = cx->mis;
    cdl_mis_counts c = path_counts(cx, (lvs->flags[l0] & CDL_V_INFINITE) != 0);
    float eta = c.merge;
    float pdf_s1 = nl >= 2 ? resample_pdf(cx, lvs->light[l0], lvs->p[l0], lvs->ng[l0], lvs->p[l0 + 1]) : 0.0f;
    float q = pdf_s1 > 0.0f && lvs->pdf_fwd[l0] > 0.0f ? pdf_s1 / lvs->pdf_fwd[l0] : 1.0f;
    int delta_light = (lvs->flags[l0] & CDL_V_DELTA_LIGHT) != 0;
    float J = (lvs->flags[l0] & CDL_V_DELTA) || delta_light ? 0.0f : hp(kd, c.eye);
    for (uint32_t a = 1; a < nl; a++) {
        uint32_t i = l0 + a;
        int da = (lvs->flags[i] & CDL_V_DELTA) != 0, dp = (lvs->flags[i - 1] & CDL_V_DELTA) != 0;
        float here = hp(kd, eta * nz(lvs->pdf_fwd[i]));
        float term = hp(kd, a == 1 ? (c.connect_s1 > 0.0f ? c.connect_s1 : c.connect) * q : c.connect);
        a1[a] = dp ? 0.0f : term / here;
        a2[a] = J / hp(kd, nz(lvs->pdf_fwd[i - 1])) / here;
        gl[a] = (lvs->flags[i - 1] & CDL_V_INFINITE)
                    ? 1.0f
                    : cdl_pdf_to_area(1.0f, lvs->p[i], lvs->p[i - 1], cdl_vertex_normal(lvs, i - 1));
        float sigma = hp(kd, nz(lvs->pdf_rev[i - 1]) / nz(lvs->pdf_fwd[i - 1]));
        J = (!da && !dp ? term : 0.0f) + (!da ? here : 0.0f) + sigma * J;
    }
}
