#include "spatial/photon_map.h"

#include "core/rng.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Octahedral map of the unit sphere to [-1, 1]^2: uniform precision,
 * 15 bits per coordinate are better than 0.01 degrees. */
void cdl_pmap_init(cdl_photon_map *m) { memset(m, 0, sizeof *m); }

void cdl_pmap_free(cdl_photon_map *m)
{
    cdl_kd_free(&m->kd);
    free(m->ph);
    memset(m, 0, sizeof *m);
}

void cdl_pmap_clear(cdl_photon_map *m)
{
    cdl_kd_free(&m->kd);
    m->n = 0;
    m->built = 0;
}

int cdl_pmap_append(cdl_photon_map *m, const cdl_photon *ph, uint32_t n, cdl_error *err)
{
    if (!n)
        return 0;
    if ((uint64_t)m->n + n > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_INPUT, "photon map", 0, "more than 2^31 photons");
    if (m->n + n > m->cap) {
        uint32_t cap = m->cap ? m->cap : 1024;
        while (cap < m->n + n)
            cap = cap > UINT32_MAX / 4 ? m->n + n : cap * 2;
        cdl_photon *p = realloc(m->ph, sizeof(cdl_photon) * cap);
        if (!p)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "photon map", 0, "out of memory for %u photons", cap);
        m->ph = p;
        m->cap = cap;
    }
    if (n)
        memcpy(m->ph + m->n, ph, sizeof(cdl_photon) * n);
    m->n += n;
    m->built = 0;
    return 0;
}

void cdl_pmap_scale(cdl_photon_map *m, float s)
{
    for (uint32_t i = 0; i < m->n; i++)
        for (int c = 0; c < 3; c++)
            m->ph[i].power[c] *= s;
}

int cdl_pmap_build(cdl_photon_map *m, cdl_error *err)
{
    cdl_kd_free(&m->kd);
    int rc = cdl_kd_build(&m->kd, m->n ? m->ph[0].p : NULL, sizeof(cdl_photon) / sizeof(float), m->n, err);
    if (rc)
        return rc;
    /* photons in tree order: a query touches neighbouring memory */
    cdl_photon *sorted = malloc(sizeof(cdl_photon) * (m->cap ? m->cap : 1));
    if (!sorted)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photon map", 0, "out of memory");
    for (uint32_t i = 0; i < m->n; i++)
        sorted[i] = m->ph[m->kd.idx[i]];
    free(m->ph);
    m->ph = sorted;
    m->kd.pts = m->n ? m->ph[0].p : NULL;
    cdl_kd_make_identity(&m->kd);
    m->built = 1;
    return 0;
}

size_t cdl_pmap_bytes(const cdl_photon_map *m) { return (size_t)m->n * sizeof(cdl_photon) + cdl_kd_bytes(&m->kd); }

/* Kernel weight at squared distance d2 in a disc of squared radius r2,
 * and the kernel's integral over that disc (pi r^2, pi r^2 / 3, pi r^2 / 2). */
static float kernel_w(cdl_kernel k, float d2, float r2)
{
    if (k == CDL_KERNEL_CONE)
        return 1.0f - sqrtf(d2 / r2);
    if (k == CDL_KERNEL_EPANECHNIKOV)
        return 1.0f - d2 / r2;
    /* the photon that sets the radius lies on the rim and is not counted:
     * k - 1 photons over pi r_k^2 is unbiased on a uniform density, k over
     * it reads k / (k - 1) too high */
    return d2 < r2 ? 1.0f : 0.0f;
}

static float kernel_area(cdl_kernel k, float r2)
{
    float a = CDL_PI * r2;
    return k == CDL_KERNEL_CONE ? a / 3.0f : k == CDL_KERNEL_EPANECHNIKOV ? a * 0.5f : a;
}

/* The k nearest within the maximum radius (with a guess, perhaps more)
 * and the radius of the estimate: the k-th distance, or the maximum with
 * fewer than k. The kernels weight the points beyond it 0. */
static uint32_t gather(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, float *r2)
{
    if (!m->n || !m->built || !q->k)
        return 0;
    uint32_t n;
    if (q->guess && q->cap > q->k) {
        /* perhaps more than k points: the kernel of r2 leaves the others out */
        float kth;
        n = cdl_kd_knn_guess(&m->kd, x, q->k, q->max_r2, q->guess, q->cap, q->idx, q->d2, &kth);
        *r2 = kth >= 0.0f ? kth : q->max_r2;
    } else {
        n = cdl_kd_knn_heap(&m->kd, x, q->k, q->max_r2, q->idx, q->d2);
        *r2 = n == q->k ? q->d2[0] : q->max_r2;
    }
    if (q->shrink > 0.0f && q->shrink < 1.0f)
        *r2 *= q->shrink;
    return *r2 > 0.0f ? n : 0;
}

static int left_out(const cdl_pm_query *q, const cdl_photon *ph)
{
    return (cdl_photon_flags(ph) & q->skip) || (q->max_depth && cdl_photon_depth(ph) > q->max_depth);
}

/* A query's lifted origin, made on the first photon that needs it. */
typedef struct vis_origin {
    cdl_vec3 x, nx, wx, o;
    float lift;
    int ready;
} vis_origin;

static int visible(const cdl_pm_query *q, vis_origin *vo, const cdl_photon *ph)
{
    if (!q->vis.fn)
        return 1;
    if (!vo->ready) {
        vo->o = q->vis.origin(q->vis.ctx, vo->x, vo->nx, vo->wx, vo->lift);
        vo->ready = 1;
    }
    return q->vis.fn(q->vis.ctx, vo->o, cdl_v3(ph->p[0], ph->p[1], ph->p[2]), cdl_photon_wi(ph));
}

cdl_vec3 cdl_pmap_radiance(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, cdl_vec3 wo,
                           const cdl_bsdf *b)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_vec3 nx = cdl_dot(b->ng, wo) < 0.0f ? cdl_neg(b->ng) : b->ng;
    float r2;
    uint32_t n = gather(m, q, x, &r2);
    vis_origin vo = {x, nx, wo, x, CDL_VIS_LIFT * sqrtf(r2), 0};
    /* Lambertian: f = kd / pi wherever the BSDF reflects, which only the
     * signs of wi decide (no normalization, no general evaluation) */
    int lambert = b->type == CDL_MAT_DIFFUSE && !b->one_sided;
    float go = cdl_dot(wo, b->ng), so = cdl_dot(wo, b->frame.n) * (go < 0.0f ? -1.0f : 1.0f);
    cdl_vec3 fd = cdl_scale(b->kd, (float)CDL_INV_PI), zero = cdl_v3(0.0f, 0.0f, 0.0f);
    if (lambert && !q->vis.fn) {
        /* the same sum without a branch per photon (the signs of wi are as
         * good as random there, and mispredicted): rejected photons weigh 0 */
        if (!(go != 0.0f && so > 0.0f) || !n)
            return zero;
        float sg = go < 0.0f ? -1.0f : 1.0f;
        cdl_vec3 ngs = cdl_scale(b->ng, sg), nss = cdl_scale(b->frame.n, sg);
        float pr = 0.0f, pg = 0.0f, pb = 0.0f;
        for (uint32_t i = 0; i < n; i++) {
            const cdl_photon *ph = &m->ph[q->idx[i]];
            float w = kernel_w(q->kernel, q->d2[i], r2);
            cdl_vec3 wi = cdl_oct_decode_raw(ph->wi & 0x3fffffffu, 15);
            int keep = w > 0.0f && !left_out(q, ph) && cdl_dot(wi, ngs) > 0.0f && cdl_dot(wi, nss) > 0.0f;
            w = keep ? w : 0.0f;
            pr += ph->power[0] * w, pg += ph->power[1] * w, pb += ph->power[2] * w;
        }
        return cdl_scale(cdl_mul(fd, cdl_v3(pr, pg, pb)), 1.0f / kernel_area(q->kernel, r2));
    }
    for (uint32_t i = 0; i < n; i++) {
        const cdl_photon *ph = &m->ph[q->idx[i]];
        float w = kernel_w(q->kernel, q->d2[i], r2);
        if (!(w > 0.0f) || left_out(q, ph))
            continue;
        cdl_vec3 f;
        if (lambert) {
            cdl_vec3 wi = cdl_oct_decode_raw(ph->wi & 0x3fffffffu, 15);
            float gi = cdl_dot(wi, b->ng), si = cdl_dot(wi, b->frame.n) * (go < 0.0f ? -1.0f : 1.0f);
            f = go * gi > 0.0f && so > 0.0f && si > 0.0f ? fd : zero;
        } else {
            f = cdl_bsdf_eval(b, wo, cdl_photon_wi(ph), 0);
        }
        if (cdl_is_black(f) || !visible(q, &vo, ph))
            continue;
        L = cdl_add(L, cdl_scale(cdl_mul(f, cdl_v3(ph->power[0], ph->power[1], ph->power[2])), w));
    }
    return n ? cdl_scale(L, 1.0f / kernel_area(q->kernel, r2)) : L;
}

static cdl_vec3 irradiance(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, cdl_vec3 nrm, cdl_vec3 wx,
                           float *r2_out)
{
    cdl_vec3 E = cdl_v3(0.0f, 0.0f, 0.0f);
    float r2 = 0.0f;
    uint32_t n = gather(m, q, x, &r2);
    *r2_out = r2;
    vis_origin vo = {x, nrm, wx, x, CDL_VIS_LIFT * sqrtf(r2), 0};
    for (uint32_t i = 0; i < n; i++) {
        const cdl_photon *ph = &m->ph[q->idx[i]];
        float w = kernel_w(q->kernel, q->d2[i], r2);
        if (!(w > 0.0f) || left_out(q, ph) ||
            cdl_dot(cdl_photon_n(ph), nrm) < -0.5f || cdl_dot(cdl_photon_wi(ph), nrm) <= 0.0f ||
            !visible(q, &vo, ph))
            continue;
        E = cdl_add(E, cdl_scale(cdl_v3(ph->power[0], ph->power[1], ph->power[2]), w));
    }
    return n ? cdl_scale(E, 1.0f / kernel_area(q->kernel, r2)) : E;
}

cdl_vec3 cdl_pmap_irradiance(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, cdl_vec3 nrm)
{
    float r2;
    return irradiance(m, q, x, nrm, nrm, &r2);
}

typedef struct flux_ctx {
    const cdl_photon_map *m;
    const cdl_pm_query *q;
    const cdl_bsdf *b;
    cdl_vec3 wo, nx, phi;
    vis_origin vo;
    uint32_t n;
} flux_ctx;

static void flux_visit(void *ctx, uint32_t i, float d2)
{
    (void)d2;
    flux_ctx *c = ctx;
    const cdl_photon *ph = &c->m->ph[i];
    /* a photon from the far side of a thin wall arrived against nx */
    if (left_out(c->q, ph) || cdl_dot(cdl_photon_n(ph), c->nx) <= 0.0f)
        return;
    c->n++;
    cdl_vec3 f = cdl_bsdf_eval(c->b, c->wo, cdl_photon_wi(ph), 0);
    if (cdl_is_black(f) || !visible(c->q, &c->vo, ph))
        return;
    c->phi = cdl_add(c->phi, cdl_mul(f, cdl_v3(ph->power[0], ph->power[1], ph->power[2])));
}

uint32_t cdl_pmap_flux(const cdl_photon_map *m, const cdl_pm_query *q, float r2, cdl_vec3 x, cdl_vec3 wo,
                       const cdl_bsdf *b, cdl_vec3 *phi)
{
    *phi = cdl_v3(0.0f, 0.0f, 0.0f);
    if (!m->n || !m->built || !(r2 > 0.0f))
        return 0;
    cdl_vec3 nx = cdl_dot(b->ng, wo) < 0.0f ? cdl_neg(b->ng) : b->ng;
    flux_ctx c = {m, q, b, wo, nx, cdl_v3(0.0f, 0.0f, 0.0f), {x, nx, wo, x, CDL_VIS_LIFT * sqrtf(r2), 0}, 0};
    cdl_kd_ball(&m->kd, x, r2, flux_visit, &c);
    *phi = c.phi;
    return c.n;
}

/* 1 in `every` photons carries an irradiance point, picked by a hash of its
 * position: a thinning that does not depend on where the other photons lie. */
static int carries_point(const cdl_photon *ph, uint32_t every)
{
    uint32_t b[3];
    memcpy(b, ph->p, sizeof b);
    uint64_t h = cdl_mix64(((uint64_t)b[0] << 32 | b[1]) ^ cdl_mix64(b[2]));
    return h % every == 0;
}

int cdl_irr_build(cdl_irr_map *im, const cdl_photon_map *global, const cdl_photon_map *caustic,
                  uint32_t every, const cdl_pm_query *qt, cdl_error *err)
{
    uint32_t k = qt->k;
    cdl_irr_free(im);
    if (every < 2)
        return cdl_error_set(err, CDL_ERR_USAGE, "precompute", 0,
                             "must be 0 (off) or at least 2: the photons that carry points cannot also "
                             "estimate there");
    /* A lookup takes the point nearest to where a gather ray lands, so no
     * other point lies nearer: estimated from the points' own photons, the
     * value would miss those (low where photons are sparse; with the point's
     * own photon at the kernel's peak, high). The points' photons and the
     * estimating ones are therefore disjoint, the latter carrying
     * every / (every - 1) times their flux. */
    uint32_t n = 0;
    for (uint32_t i = 0; i < global->n; i++)
        n += (uint32_t)carries_point(&global->ph[i], every);
    cdl_photon_map *est = &im->est;
    im->pt = malloc(sizeof(cdl_irr_point) * (n ? n : 1));
    int rc = im->pt ? 0 : cdl_error_set(err, CDL_ERR_SYSTEM, "photon map", 0, "out of memory for %u points", n);
    uint32_t np = 0;
    for (uint32_t i = 0; !rc && i < global->n; i++) {
        const cdl_photon *ph = &global->ph[i];
        if (carries_point(ph, every)) {
            cdl_irr_point *p = &im->pt[np++];
            memcpy(p->p, ph->p, sizeof p->p);
            p->n = cdl_oct_encode_bits(cdl_photon_n(ph), 16);
            p->wi = cdl_oct_encode_bits(cdl_photon_wi(ph), 16);
        } else {
            rc = cdl_pmap_append(est, ph, 1, err);
        }
    }
    if (!rc) {
        cdl_pmap_scale(est, (float)every / (float)(every - 1));
        rc = cdl_pmap_build(est, err);
    }
    if (rc) {
        cdl_irr_free(im);
        return rc;
    }
    int fail = 0;
#pragma omp parallel
    {
        uint32_t *idx = malloc(sizeof(uint32_t) * k);
        float *d2 = malloc(sizeof(float) * k);
        cdl_pm_query q = {k, qt->max_r2, qt->kernel, 0, idx, d2, qt->vis, qt->max_depth, NULL, 0, qt->shrink};
        if (!idx || !d2) {
#pragma omp atomic write
            fail = 1;
        }
#pragma omp for schedule(dynamic, 256)
        for (int64_t i = 0; i < (int64_t)n; i++) {
            if (!idx || !d2)
                continue;
            cdl_irr_point *p = &im->pt[i];
            cdl_vec3 x = cdl_v3(p->p[0], p->p[1], p->p[2]), nrm = cdl_oct_decode_bits(p->n, 16);
            cdl_vec3 wx = cdl_oct_decode_bits(p->wi, 16);
            float r2 = 0.0f, r2c = 0.0f;
            cdl_vec3 E = irradiance(est, &q, x, nrm, wx, &r2);
            if (caustic->n)
                E = cdl_add(E, irradiance(caustic, &q, x, nrm, wx, &r2c));
            /* the point stands for the larger of its two discs */
            p->r2 = r2 > r2c ? r2 : r2c;
            p->E[0] = E.x;
            p->E[1] = E.y;
            p->E[2] = E.z;
        }
        free(idx);
        free(d2);
    }
    im->n = n;
    if (fail) {
        cdl_irr_free(im);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photon map", 0, "out of memory");
    }
    if (cdl_kd_build(&im->kd, n ? im->pt[0].p : NULL, sizeof(cdl_irr_point) / sizeof(float), n, err)) {
        cdl_irr_free(im);
        return err->code;
    }
    cdl_irr_point *sorted = malloc(sizeof(cdl_irr_point) * (n ? n : 1));
    if (!sorted) {
        cdl_irr_free(im);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photon map", 0, "out of memory");
    }
    for (uint32_t i = 0; i < n; i++)
        sorted[i] = im->pt[im->kd.idx[i]];
    free(im->pt);
    im->pt = sorted;
    im->kd.pts = n ? im->pt[0].p : NULL;
    cdl_kd_make_identity(&im->kd);
    return 0;
}

void cdl_irr_free(cdl_irr_map *im)
{
    cdl_kd_free(&im->kd);
    free(im->pt);
    cdl_pmap_free(&im->est);
    memset(im, 0, sizeof *im);
}

static int irr_usable(const cdl_irr_point *p, float d2, int own_radius, cdl_vec3 x, cdl_vec3 n, cdl_vec3 wx,
                      cdl_vis vis)
{
    cdl_vec3 pn = cdl_oct_decode_bits(p->n, 16);
    if ((own_radius && !(d2 < p->r2)) || !(cdl_dot(pn, n) > 0.9f))
        return 0;
    if (!vis.fn)
        return 1;
    cdl_vec3 o = vis.origin(vis.ctx, x, n, wx, CDL_VIS_LIFT * sqrtf(d2));
    return vis.fn(vis.ctx, o, cdl_v3(p->p[0], p->p[1], p->p[2]), cdl_oct_decode_bits(p->wi, 16));
}

cdl_vec3 cdl_irr_lookup(const cdl_irr_map *im, cdl_vec3 x, cdl_vec3 n, cdl_vec3 wx, float max_r2, int own_radius,
                        cdl_vis vis, int *found)
{
    uint32_t idx[8];
    float d2[8];
    *found = 0;
    if (!im->n)
        return cdl_v3(0.0f, 0.0f, 0.0f);
    /* the nearest point almost always serves: one cheap 1-NN search first */
    uint32_t m = cdl_kd_knn(&im->kd, x, 1, max_r2, idx, d2), tried = m ? idx[0] : UINT32_MAX;
    if (m && irr_usable(&im->pt[idx[0]], d2[0], own_radius, x, n, wx, vis)) {
        *found = 1;
        return cdl_v3(im->pt[idx[0]].E[0], im->pt[idx[0]].E[1], im->pt[idx[0]].E[2]);
    }
    m = m ? cdl_kd_knn(&im->kd, x, 8, max_r2, idx, d2) : 0;
    for (uint32_t i = 0; i < m; i++) {
        const cdl_irr_point *p = &im->pt[idx[i]];
        if (idx[i] != tried && irr_usable(p, d2[i], own_radius, x, n, wx, vis)) {
            *found = 1;
            return cdl_v3(p->E[0], p->E[1], p->E[2]);
        }
    }
    return cdl_v3(0.0f, 0.0f, 0.0f);
}
