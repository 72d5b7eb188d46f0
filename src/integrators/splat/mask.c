/* splat's visibility mask (Herzog et al. 2007, §8.1, proposed there as
 * future work): before a photon ray splats, the eye samples inside its
 * frustum, whatever their facing, are rasterized into a small occlusion
 * buffer in the kernel's plane: lateral offsets from the ray divided by
 * the kernel's radius at their depth (the cone's own perspective, so a
 * blocker near the narrow origin hides only what lies behind it), on at
 * most MASK_G x MASK_G cells, no finer than the samples' median
 * footprint. Each sample covers the surface patch its pixel sees (the
 * masking density: an ellipse, longer on surfaces seen at a grazing
 * angle, so a surface leaves no holes), and a cell keeps the sample
 * nearest the ray's origin. A feasible sample is then fed only if the
 * front sample of its cell does not hide it: that occluder lies nearer
 * along the ray and the sample lies behind the occluder's tangent plane
 * (seen from the ray's origin) by more than its own footprint, so a
 * surface never shadows its own neighbours. Only occluders the camera sees
 * count (they must be eye samples), as the report says; the surface the
 * ray leaves is no occluder, and a frustum holding one plane's samples
 * only needs no mask. Masks are built a batch of rays at a time,
 * each ray on its own (deterministic), then the batch splats part by part
 * as without them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/grow.h"
#include "integrators/splat/mask.h"

#define MASK_G 32
#define FRAME 7 /* floats per ray: U, V, g (cells over the kernel's unit disc, each 2 / g wide) */

struct splat_mask {
    uint32_t first;     /* the batch's first ray */
    float rho;          /* the eye samples' median footprint: the smallest cell worth having */
    float *pw;          /* per eye sample (tree order) its footprint, contiguous for the leaf loops */
    float *ax[6];       /* and the semi-axes of the surface patch it stands for (see rasterize) */
    uint32_t npw;
    uint32_t *occ;      /* per ray: MASK_G^2 cells, the front sample or UINT32_MAX */
    float *zmin;        /* its distance along the ray */
    float *frame;       /* per ray: U, V (perpendicular to d), the grid's side g (0: no mask) */
};

int splat_mask_alloc(splat_state *s, cdl_error *err)
{
    const size_t batch = SPLAT_MASK_BATCH;
    if (s->mask)
        return 0;
    splat_mask *m = s->mask = calloc(1, sizeof *m);
    if (m) {
        m->occ = malloc(sizeof *m->occ * batch * MASK_G * MASK_G);
        m->zmin = malloc(sizeof *m->zmin * batch * MASK_G * MASK_G);
        m->frame = malloc(sizeof *m->frame * batch * FRAME);
    }
    if (!m || !m->occ || !m->zmin || !m->frame)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the visibility masks");
    return 0;
}

void splat_mask_free(splat_state *s)
{
    if (!s->mask)
        return;
    free(s->mask->occ);
    free(s->mask->zmin);
    free(s->mask->frame);
    free(s->mask->pw);
    for (int c = 0; c < 6; c++)
        free(s->mask->ax[c]);
    free(s->mask);
    s->mask = NULL;
}

size_t splat_mask_bytes(const splat_state *s)
{
    return s->mask ? (size_t)SPLAT_MASK_BATCH * (MASK_G * MASK_G * 8 + FRAME * sizeof(float)) +
                         7 * sizeof(float) * s->mask->npw
                   : 0;
}

typedef struct build_ctx {
    const splat_state *s;
    const cdl_photon_ray *r;
    const float *fr;
    uint32_t *occ;
    float *zmin;
    const float *pw, *const *ax;
    uint64_t n; /* samples rasterized */
} build_ctx;

/* The frustum's samples of one ray, kept a leaf batch at a time until it
 * is known whether they lie on more than one plane (per thread). */
typedef struct held {
    uint32_t first, mask;
    float zz[16];
} held;

typedef struct hold_ctx {
    const splat_state *s;
    const cdl_photon_ray *r;
    held *b;
    uint32_t n, cap;
    int oom;
} hold_ctx;

static void hold(void *ctx, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *zz)
{
    (void)m, (void)w;
    hold_ctx *h = ctx;
    if (h->oom)
        return;
    if (cdl_grow((void **)&h->b, &h->cap, h->n + 1, sizeof *h->b)) {
        h->oom = 1;
        return;
    }
    held *e = &h->b[h->n++];
    e->first = first;
    e->mask = mask;
    memcpy(e->zz, zz, sizeof e->zz);
}

/* Whether the held samples that can hide anything (not on the surface the
 * ray leaves) lie on one plane: within a quarter of the smallest footprint
 * of the first one's plane, normals within 0.1 degree. No sample of a
 * plane hides another (the filter's test needs one behind another's
 * tangent plane by its footprint), so such a ray needs no mask. */
static int one_plane(const hold_ctx *h)
{
    const cdl_skd *t = &h->s->tree;
    const float *pw = h->s->mask->pw;
    const cdl_vec3 o = h->r->o;
    int have = 0, flat = 1;
    float p0[3] = {0, 0, 0}, n0[3] = {0, 0, 0}, dmax = 0.0f, pmin = INFINITY;
    for (uint32_t k = 0; k < h->n && flat; k++)
        for (uint32_t mask = h->b[k].mask; mask; mask &= mask - 1) {
            uint32_t q = h->b[k].first + (uint32_t)__builtin_ctz(mask);
            float p[3] = {t->p[0][q], t->p[1][q], t->p[2][q]}, n[3] = {t->nrm[0][q], t->nrm[1][q], t->nrm[2][q]};
            float so = (p[0] - o.x) * n[0] + (p[1] - o.y) * n[1] + (p[2] - o.z) * n[2];
            if (!(fabsf(so) > pw[q]))
                continue; /* as rasterize: the origin's surface */
            if (!have) {
                memcpy(p0, p, sizeof p0);
                memcpy(n0, n, sizeof n0);
                have = 1;
            }
            float d = fabsf((p[0] - p0[0]) * n0[0] + (p[1] - p0[1]) * n0[1] + (p[2] - p0[2]) * n0[2]);
            dmax = d > dmax ? d : dmax;
            pmin = pw[q] < pmin ? pw[q] : pmin;
            if (n[0] * n0[0] + n[1] * n0[1] + n[2] * n0[2] < 0.9999985f || dmax > 0.25f * pmin) {
                flat = 0;
                break;
            }
        }
    return flat;
}

static void rasterize(void *ctx, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *zz)
{
    (void)m, (void)w;
    build_ctx *x = ctx;
    const cdl_skd *t = &x->s->tree;
    const float *U = x->fr, *V = x->fr + 3, ics = 0.5f * x->fr[6];
    const float h0 = x->r->h0, dh = x->r->dh, len = x->r->len;
    const int g = (int)x->fr[6];
    const float ox = x->r->o.x, oy = x->r->o.y, oz = x->r->o.z, dx = x->r->d.x, dy = x->r->d.y, dz = x->r->d.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first;
    const float *nx = t->nrm[0] + first, *ny = t->nrm[1] + first, *nz = t->nrm[2] + first, *pw = x->pw + first;
    const float *ax[6];
    for (int c = 0; c < 6; c++)
        ax[c] = x->ax[c] + first;
    int box[4][16], keep[16];
    x->n += (uint64_t)__builtin_popcount(mask);
    /* the cells each lane covers, 16 at a time (lanes past m are masked) */
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        float Dx = px[i] - ox, Dy = py[i] - oy, Dz = pz[i] - oz, z = zz[i];
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        /* the surface the ray leaves hides nothing, and in the cells
         * around the ray it would stand in front of what does */
        float so = Dx * nx[i] + Dy * ny[i] + Dz * nz[i];
        keep[i] = fabsf(so) > pw[i];
        /* in the kernel's plane: lateral offsets over the radius at z */
        float ih = ics / (h0 + dh * (z < len ? z : len));
        float u = (ex * U[0] + ey * U[1] + ez * U[2]) * ih + 0.5f * (float)g;
        float v = (ex * V[0] + ey * V[1] + ez * V[2]) * ih + 0.5f * (float)g;
        /* the patch's ellipse seen along d: its half extents in u and v */
        float t1 = ax[0][i] * U[0] + ax[1][i] * U[1] + ax[2][i] * U[2], b1 = ax[3][i] * U[0] + ax[4][i] * U[1] + ax[5][i] * U[2];
        float t2 = ax[0][i] * V[0] + ax[1][i] * V[1] + ax[2][i] * V[2], b2 = ax[3][i] * V[0] + ax[4][i] * V[1] + ax[5][i] * V[2];
        float fu = sqrtf(t1 * t1 + b1 * b1) * ih, fv = sqrtf(t2 * t2 + b2 * b2) * ih;
        /* + 1 so truncation floors; clamped to the grid */
        /* (comparisons, not fminf: the loop stays vectorized) */
        float u0 = u - fu + 1.0f, u1 = u + fu + 1.0f, v0 = v - fv + 1.0f, v1 = v + fv + 1.0f, G = (float)g;
        u0 = u0 > 1.0f ? u0 : 1.0f, u1 = u1 > 0.0f ? u1 : 0.0f, v0 = v0 > 1.0f ? v0 : 1.0f, v1 = v1 > 0.0f ? v1 : 0.0f;
        box[0][i] = (int)(u0 < G ? u0 : G) - 1;
        box[1][i] = (int)(u1 < G ? u1 : G) - 1;
        box[2][i] = (int)(v0 < G ? v0 : G) - 1;
        box[3][i] = (int)(v1 < G ? v1 : G) - 1;
    }
    for (; mask; mask &= mask - 1) {
        int i = __builtin_ctz(mask);
        if (!keep[i])
            continue;
        uint32_t q = first + (uint32_t)i;
        float z = zz[i];
        for (int b = box[2][i]; b <= box[3][i]; b++)
            for (int a = box[0][i]; a <= box[1][i]; a++) {
                int c = b * g + a;
                if (z < x->zmin[c] || (z == x->zmin[c] && q < x->occ[c])) {
                    x->zmin[c] = z;
                    x->occ[c] = q;
                }
            }
    }
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int splat_mask_prepare(splat_state *s)
{
    /* cells finer than the samples' spacing only cost clearing and
     * rasterizing: the median footprint of a strided subset bounds them */
    splat_mask *m = s->mask;
    if (m->npw < s->tree.n) {
        /* 16 lanes of padding: the leaf loops read whole batches */
        m->npw = 0;
        free(m->pw);
        m->pw = calloc((size_t)s->tree.n + 16, sizeof *m->pw);
        int ok = m->pw != NULL;
        for (int c = 0; c < 6; c++) {
            free(m->ax[c]);
            ok &= (m->ax[c] = calloc((size_t)s->tree.n + 16, sizeof *m->ax[c])) != NULL;
        }
        if (!ok)
            return CDL_ERR_SYSTEM;
        m->npw = s->tree.n;
    }
    /* a sample stands for the patch a pixel covers: a disc of radius
     * 0.6 pw across its view ray, landed on the surface: an ellipse whose
     * axis along the view is 1 / cos longer, at most 5x: a grazing
     * surface leaves holes beyond that, and longer patches widen every
     * shadow they cast (measured: 20x removed 99.9 % of the leak under a
     * plate seen edge-on, but doubled the Cornell box's direct-light
     * error) */
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->tree.n; q++) {
        const splat_eye *e = &s->eye[q];
        float r = 0.6f * e->pw, c = fabsf(cdl_dot(e->wo, e->f.n));
        float r2 = r / (c > 0.2f ? c : 0.2f);
        m->pw[q] = e->pw;
        m->ax[0][q] = r2 * e->f.t.x, m->ax[1][q] = r2 * e->f.t.y, m->ax[2][q] = r2 * e->f.t.z;
        m->ax[3][q] = r * e->f.b.x, m->ax[4][q] = r * e->f.b.y, m->ax[5][q] = r * e->f.b.z;
    }
    uint32_t n = s->tree.n < 4096 ? s->tree.n : 4096, step = n ? s->tree.n / n : 1;
    float *f = malloc(sizeof *f * (n ? n : 1));
    m->rho = 0.0f; /* without memory: the full grid */
    if (!f)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        f[i] = m->pw[(size_t)i * step];
    qsort(f, n, sizeof *f, cmp_float);
    m->rho = n ? f[n / 2] : 0.0f;
    free(f);
    return 0;
}

int splat_mask_build(splat_state *s, uint32_t first, uint32_t n)
{
    splat_mask *m = s->mask;
    m->first = first;
    uint64_t tested = 0, rasterized = 0, masks = 0;
#pragma omp parallel reduction(+ : tested, rasterized, masks)
    {
    hold_ctx h = {s, NULL, NULL, 0, 0, 0};
#pragma omp for schedule(dynamic, 64)
    for (uint32_t k = 0; k < n; k++) {
        const cdl_photon_ray *r = &s->rays.r[first + k];
        float *fr = m->frame + (size_t)k * FRAME;
        cdl_frame f = cdl_frame_from(r->d);
        float hmax = r->h0 + r->dh * r->len;
        int g = MASK_G;
        if (2.0f * hmax < g * m->rho)
            g = (int)ceilf(2.0f * hmax / m->rho);
        g = g < 1 ? 1 : g;
        fr[0] = f.t.x, fr[1] = f.t.y, fr[2] = f.t.z;
        fr[3] = f.b.x, fr[4] = f.b.y, fr[5] = f.b.z;
        fr[6] = 0.0f; /* no mask unless the frustum holds more than one plane */
        if (!(hmax > 0.0f))
            continue;
        cdl_splat_ray sr = splat_ray_of(s, r);
        cdl_skd_count cnt = {0, 0};
        h.r = r;
        h.n = 0;
        h.oom = 0;
        cdl_skd_splat_visit(&s->tree, UINT32_MAX, &sr, CDL_SKD_ANY, hold, &h, &cnt);
        tested += cnt.tested;
        if (!h.oom && one_plane(&h))
            continue;
        fr[6] = (float)g;
        masks++;
        uint32_t *occ = m->occ + (size_t)k * MASK_G * MASK_G;
        float *zmin = m->zmin + (size_t)k * MASK_G * MASK_G;
        for (int c = 0; c < g * g; c++) {
            occ[c] = UINT32_MAX;
            zmin[c] = INFINITY;
        }
        build_ctx x = {s, r, fr, occ, zmin, m->pw, (const float *const *)m->ax, 0};
        if (h.oom) /* no memory to hold them: traverse again */
            cdl_skd_splat_visit(&s->tree, UINT32_MAX, &sr, CDL_SKD_ANY, rasterize, &x, &cnt);
        else
            for (uint32_t b = 0; b < h.n; b++)
                rasterize(&x, h.b[b].first, 16, h.b[b].mask, NULL, h.b[b].zz);
        rasterized += x.n;
    }
    free(h.b);
    }
    s->st.mask_tested += tested;
    s->st.rasterized += rasterized;
    s->st.mask_rays += masks;
    return 0;
}

uint32_t splat_mask_filter(const splat_state *s, uint32_t ray, uint32_t first, uint32_t mask, const float *iz)
{
    const splat_mask *m = s->mask;
    const cdl_skd *t = &s->tree;
    const cdl_photon_ray *r = &s->rays.r[ray];
    uint32_t k = ray - m->first;
    const float *fr = m->frame + (size_t)k * FRAME, *U = fr, *V = fr + 3;
    const int g = (int)fr[6];
    if (!g)
        return mask; /* one plane in the frustum: nothing hidden */
    const uint32_t *occ = m->occ + (size_t)k * MASK_G * MASK_G;
    const float *zmin = m->zmin + (size_t)k * MASK_G * MASK_G;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float h0 = r->h0, dh = r->dh, len = r->len, ics = 0.5f * (float)g, half = ics;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first;
    int cell[16];
    float zz[16];
    /* each lane's cell, 16 at a time (-1: outside the grid) */
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        float z = iz[i] > 0.0f ? 1.0f / iz[i] : 0.0f;
        float ex = px[i] - ox - z * dx, ey = py[i] - oy - z * dy, ez = pz[i] - oz - z * dz;
        float ih = ics / (h0 + dh * (z < len ? z : len));
        float u = (ex * U[0] + ey * U[1] + ez * U[2]) * ih + half, v = (ex * V[0] + ey * V[1] + ez * V[2]) * ih + half;
        int in = u >= 0.0f && v >= 0.0f && u < (float)g && v < (float)g;
        cell[i] = in ? (int)v * g + (int)u : -1;
        zz[i] = z;
    }
    uint32_t keep = mask;
    for (; mask; mask &= mask - 1) {
        uint32_t i = (uint32_t)__builtin_ctz(mask), q = first + i;
        if (cell[i] < 0)
            continue;
        uint32_t o = occ[cell[i]];
        float rho = m->pw[q];
        if (o == UINT32_MAX || o == q || !(zmin[cell[i]] < zz[i] - rho))
            continue;
        /* hidden if the sample lies on the far side of the occluder's
         * tangent plane from the ray's origin; an occluder whose plane
         * holds the origin (the surface the ray leaves) hides nothing */
        float nx = t->nrm[0][o], ny = t->nrm[1][o], nz = t->nrm[2][o];
        float so = (ox - t->p[0][o]) * nx + (oy - t->p[1][o]) * ny + (oz - t->p[2][o]) * nz;
        float sy = (px[i] - t->p[0][o]) * nx + (py[i] - t->p[1][o]) * ny + (pz[i] - t->p[2][o]) * nz;
        float rho_o = m->pw[o];
        if (fabsf(so) > rho_o && (so > 0.0f ? sy < -rho : sy > rho))
            keep &= ~(1u << i);
    }
    return keep;
}
