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
 * only needs no mask.
 *
 * Cost (issue 29): one traversal per ray, as the report rasterizes
 * "during the ray traversal": a batch of rays at a time, in parallel over
 * the rays, each ray's traversal yields the frustum's samples and the
 * feasible ones (cdl_skd_splat_visit_both); the frustum's are rasterized,
 * the feasible ones filtered against the ray's buffer right away, and the
 * survivors (weights and 1 / z, compressed to their lanes) kept per ray.
 * The batch then splats part by part as without masks: each part replays its rays' kept splats in ray order, so every sample
 * sums its splats in the same order. A cell holds the front sample as
 * one 64-bit key, distance bits over the sample's index (z >= 0: the
 * float's bits order as the float), so z-min with the index's tie-break
 * is one unsigned min and a row of cells one masked SIMD min. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif
#include <omp.h>

#include "core/grow.h"
#include "integrators/splat/mask.h"

#define MASK_G 32

/* A traversal batch held until the ray's buffer is known: the frustum's
 * lanes with their z, or the feasible ones with w and 1 / z. */
typedef struct mask_held {
    uint32_t first, mask;
    float z[16];
} mask_held;
typedef struct mask_feas {
    uint32_t first, mask;
    float w[16], iz[16];
} mask_feas;
/* A kept batch: its lanes' w then 1 / z from val[off], packed. */
typedef struct mask_rec {
    uint32_t first, keep, off;
} mask_rec;
/* A ray's kept batches in one part: rec[rec0, rec0 + n) of a worker. */
typedef struct mask_seg {
    uint32_t part, rec0, n;
} mask_seg;
typedef struct mask_pentry {
    uint32_t w, ray, rec0, n; /* worker, ray in the batch, its records */
} mask_pentry;

/* Per thread: what one ray's traversal holds, the buffer, and the kept
 * splats of the batch's rays it took. */
typedef struct mask_worker {
    mask_held *held;
    mask_feas *feas;
    mask_rec *rec;
    float *val;
    mask_seg *seg;
    uint64_t *grid; /* MASK_G^2 cells: distance bits << 32 | sample, UINT64_MAX empty */
    uint32_t nh, caph, nf, capf, nrec, caprec, nval, capval, nseg, capseg;
    int oom;
} mask_worker;

struct splat_mask {
    uint32_t first;     /* the batch's first ray */
    float rho;          /* the eye samples' median footprint: the smallest cell worth having */
    float *pw;          /* per eye sample (tree order) its footprint, contiguous for the leaf loops */
    float *ax[6];       /* and the semi-axes of the surface patch it stands for (see rasterize) */
    uint32_t npw;
    mask_worker *w;
    int nw;
    uint32_t *rth;      /* per ray of the batch: the worker that took it, */
    uint32_t *rseg0, *rnseg; /* its segments */
    uint32_t *pstart, *pcur, npart; /* per part: its entries in plist, in ray order */
    mask_pentry *plist;
    uint32_t cappl;
};

int splat_mask_alloc(splat_state *s, cdl_error *err)
{
    if (s->mask)
        return 0;
    splat_mask *m = s->mask = calloc(1, sizeof *m);
    if (m) {
        m->rth = malloc(sizeof *m->rth * SPLAT_MASK_BATCH);
        m->rseg0 = malloc(sizeof *m->rseg0 * SPLAT_MASK_BATCH);
        m->rnseg = malloc(sizeof *m->rnseg * SPLAT_MASK_BATCH);
    }
    if (!m || !m->rth || !m->rseg0 || !m->rnseg)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the visibility masks");
    return 0;
}

static void worker_free(mask_worker *w)
{
    free(w->held);
    free(w->feas);
    free(w->rec);
    free(w->val);
    free(w->seg);
    free(w->grid);
}

void splat_mask_free(splat_state *s)
{
    splat_mask *m = s->mask;
    if (!m)
        return;
    for (int i = 0; i < m->nw; i++)
        worker_free(&m->w[i]);
    free(m->w);
    free(m->rth);
    free(m->rseg0);
    free(m->rnseg);
    free(m->pstart);
    free(m->pcur);
    free(m->plist);
    free(m->pw);
    for (int c = 0; c < 6; c++)
        free(m->ax[c]);
    free(m);
    s->mask = NULL;
}

size_t splat_mask_bytes(const splat_state *s)
{
    const splat_mask *m = s->mask;
    if (!m)
        return 0;
    size_t b = (size_t)SPLAT_MASK_BATCH * 12 + 7 * sizeof(float) * (size_t)m->npw +
               (size_t)m->cappl * sizeof(mask_pentry) + (size_t)(2 * m->npart + 1) * sizeof(uint32_t);
    for (int i = 0; i < m->nw; i++) {
        const mask_worker *w = &m->w[i];
        b += (size_t)w->caph * sizeof(mask_held) + (size_t)w->capf * sizeof(mask_feas) +
             (size_t)w->caprec * sizeof(mask_rec) + (size_t)w->capval * sizeof(float) +
             (size_t)w->capseg * sizeof(mask_seg) + (w->grid ? MASK_G * MASK_G * sizeof(uint64_t) : 0);
    }
    return b;
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

/* The traversal's batches: the frustum's (occluders) and the feasible
 * ones, held until the ray's buffer is known. */
static void collect(void *ctx, uint32_t first, uint32_t m, uint32_t any, const float *z, uint32_t feasible,
                    const float *w, const float *iz)
{
    (void)m;
    mask_worker *x = ctx;
    if (any) {
        if (cdl_grow((void **)&x->held, &x->caph, x->nh + 1, sizeof *x->held)) {
            x->oom = 1;
            return;
        }
        mask_held *e = &x->held[x->nh++];
        e->first = first;
        e->mask = any;
        memcpy(e->z, z, sizeof e->z);
    }
    if (feasible) {
        if (cdl_grow((void **)&x->feas, &x->capf, x->nf + 1, sizeof *x->feas)) {
            x->oom = 1;
            return;
        }
        mask_feas *e = &x->feas[x->nf++];
        e->first = first;
        e->mask = feasible;
        memcpy(e->w, w, sizeof e->w);
        memcpy(e->iz, iz, sizeof e->iz);
    }
}

/* Whether the held samples that can hide anything (not on the surface the
 * ray leaves) lie on one plane: within a quarter of the smallest footprint
 * of the first one's plane, normals within 0.1 degree. No sample of a
 * plane hides another (the filter's test needs one behind another's
 * tangent plane by its footprint), so such a ray needs no mask. The
 * largest distance only grows and the smallest footprint only shrinks
 * sample by sample, so testing them over a whole batch at once decides
 * the same. */
static int one_plane(const splat_state *s, const cdl_photon_ray *r, const mask_held *h, uint32_t nh)
{
    const cdl_skd *t = &s->tree;
    const float *pw = s->mask->pw;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z;
    uint32_t k = 0, q0 = UINT32_MAX;
    for (; k < nh && q0 == UINT32_MAX; k++)
        for (uint32_t mask = h[k].mask; mask; mask &= mask - 1) {
            uint32_t q = h[k].first + (uint32_t)__builtin_ctz(mask);
            float so = (t->p[0][q] - ox) * t->nrm[0][q] + (t->p[1][q] - oy) * t->nrm[1][q] +
                       (t->p[2][q] - oz) * t->nrm[2][q];
            if (fabsf(so) > pw[q]) { /* not the origin's surface (as rasterize) */
                q0 = q;
                break;
            }
        }
    if (q0 == UINT32_MAX)
        return 1;
    const float p0x = t->p[0][q0], p0y = t->p[1][q0], p0z = t->p[2][q0];
    const float n0x = t->nrm[0][q0], n0y = t->nrm[1][q0], n0z = t->nrm[2][q0];
    float dmax = 0.0f, pmin = INFINITY;
    for (k = k ? k - 1 : 0; k < nh; k++) {
        const uint32_t b = h[k].first, mask = h[k].mask;
        const float *px = t->p[0] + b, *py = t->p[1] + b, *pz = t->p[2] + b;
        const float *nx = t->nrm[0] + b, *ny = t->nrm[1] + b, *nz = t->nrm[2] + b, *pb = pw + b;
        int bent = 0;
#pragma omp simd reduction(max : dmax) reduction(min : pmin) reduction(| : bent)
        for (uint32_t i = 0; i < 16; i++) {
            float so = (px[i] - ox) * nx[i] + (py[i] - oy) * ny[i] + (pz[i] - oz) * nz[i];
            int ok = (int)(mask >> i & 1u) & (fabsf(so) > pb[i]);
            float d = fabsf((px[i] - p0x) * n0x + (py[i] - p0y) * n0y + (pz[i] - p0z) * n0z);
            bent |= ok & (nx[i] * n0x + ny[i] * n0y + nz[i] * n0z < 0.9999985f);
            dmax = ok && d > dmax ? d : dmax;
            pmin = ok && pb[i] < pmin ? pb[i] : pmin;
        }
        if (bent || dmax > 0.25f * pmin)
            return 0;
    }
    return 1;
}

/* z-min of a cell with key (a branch-free select: the loads forward
 * from the stores of the lanes before, which hit the same cells). */
static inline void cell_min(uint64_t *c, uint64_t key) { *c = key < *c ? key : *c; }

static inline uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static inline float bits_float(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* One held batch into the ray's buffer (g x g cells, frame U, V). */
static void rasterize(const splat_state *s, const cdl_photon_ray *r, const float *U, const float *V, int g,
                      uint64_t *grid, const mask_held *hb)
{
    const cdl_skd *t = &s->tree;
    const splat_mask *mk = s->mask;
    const uint32_t first = hb->first;
    const float *zz = hb->z;
    const float ics = 0.5f * (float)g;
    const float h0 = r->h0, dh = r->dh, len = r->len;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first;
    const float *nx = t->nrm[0] + first, *ny = t->nrm[1] + first, *nz = t->nrm[2] + first, *pw = mk->pw + first;
    const float *ax[6];
    for (int c = 0; c < 6; c++)
        ax[c] = mk->ax[c] + first;
    int box[4][16], keep[16];
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
    uint32_t live = 0;
    for (int i = 0; i < 16; i++)
        live |= (uint32_t)(keep[i] != 0) << i;
    for (uint32_t mask = hb->mask & live; mask; mask &= mask - 1) {
        int i = __builtin_ctz(mask);
        /* + 0: -0 becomes +0, whose bits order with the rest */
        uint64_t key = (uint64_t)float_bits(zz[i] + 0.0f) << 32 | (first + (uint32_t)i);
        const int a0 = box[0][i], a1 = box[1][i], b0 = box[2][i], b1 = box[3][i];
        if (a1 < a0 || b1 < b0)
            continue;
        if (a1 - a0 <= 1 && b1 - b0 <= 1) {
            /* at most 2 x 2 cells, most of them: the 4 corners, a
             * narrower box repeating some (z-min twice changes nothing) */
            uint64_t *r0 = grid + b0 * g, *r1 = grid + b1 * g;
            cell_min(r0 + a0, key);
            cell_min(r0 + a1, key);
            cell_min(r1 + a0, key);
            cell_min(r1 + a1, key);
            continue;
        }
        for (int b = b0; b <= b1; b++)
            for (int a = a0; a <= a1; a++)
                cell_min(grid + b * g + a, key);
    }
}

/* Drops from a feasible batch the samples the ray's buffer hides. */
static uint32_t filter(const splat_state *s, const cdl_photon_ray *r, const float *U, const float *V, int g,
                       const uint64_t *grid, const mask_feas *fb)
{
    const splat_mask *m = s->mask;
    const cdl_skd *t = &s->tree;
    const uint32_t first = fb->first, mask = fb->mask;
    const float *iz = fb->iz;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float h0 = r->h0, dh = r->dh, len = r->len, ics = 0.5f * (float)g, half = ics;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = m->pw + first;
    int cell[16], zb[16];
    uint32_t occ[16];
    /* each lane's cell, 16 at a time (-1: outside the grid) */
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        float z = iz[i] > 0.0f ? 1.0f / iz[i] : 0.0f;
        float ex = px[i] - ox - z * dx, ey = py[i] - oy - z * dy, ez = pz[i] - oz - z * dz;
        float ih = ics / (h0 + dh * (z < len ? z : len));
        float u = (ex * U[0] + ey * U[1] + ez * U[2]) * ih + half, v = (ex * V[0] + ey * V[1] + ez * V[2]) * ih + half;
        int in = u >= 0.0f && v >= 0.0f && u < (float)g && v < (float)g;
        cell[i] = in ? (int)v * g + (int)u : -1;
        zb[i] = (int32_t)float_bits(z - pw[i]);
    }
    /* a candidate has a front sample (not itself) nearer by more than its
     * footprint: distances >= 0 order as their bits, and a negative
     * z - pw (a negative int) has none nearer */
#if defined(__AVX512F__)
    const __m512i c = _mm512_loadu_si512(cell), none = _mm512_set1_epi64(-1);
    const __mmask16 in = _mm512_mask_cmpge_epi32_mask((__mmask16)mask, c, _mm512_setzero_si512());
    __m512i klo = _mm512_mask_i32gather_epi64(none, (__mmask8)in, _mm512_castsi512_si256(c), grid, 8);
    __m512i khi = _mm512_mask_i32gather_epi64(none, (__mmask8)(in >> 8), _mm512_extracti64x4_epi64(c, 1), grid, 8);
    /* the keys' low halves (samples) and high halves (distance bits) */
    const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    __m512i o = _mm512_permutex2var_epi32(klo, even, khi);
    __m512i zk = _mm512_permutex2var_epi32(klo, _mm512_add_epi32(even, _mm512_set1_epi32(1)), khi);
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    __mmask16 cm = _mm512_mask_cmpneq_epi32_mask(in, o, _mm512_set1_epi32(-1));
    cm = _mm512_mask_cmpneq_epi32_mask(cm, o, _mm512_add_epi32(lane, _mm512_set1_epi32((int)first)));
    cm = _mm512_mask_cmplt_epi32_mask(cm, zk, _mm512_loadu_si512(zb));
    _mm512_storeu_si512(occ, o);
    uint32_t hit = cm;
#else
    uint32_t hit = 0;
    for (int i = 0; i < 16; i++) {
        if (!(mask >> i & 1u) || cell[i] < 0)
            continue;
        uint64_t key = grid[cell[i]];
        occ[i] = (uint32_t)key;
        hit |= (uint32_t)((occ[i] != UINT32_MAX) & (occ[i] != first + (uint32_t)i) &
                          ((int32_t)(uint32_t)(key >> 32) < zb[i])) << i;
    }
#endif
    uint32_t keep = mask;
    for (hit &= mask; hit; hit &= hit - 1) {
        uint32_t i = (uint32_t)__builtin_ctz(hit), o = occ[i];
        /* hidden if the sample lies on the far side of the occluder's
         * tangent plane from the ray's origin; an occluder whose plane
         * holds the origin (the surface the ray leaves) hides nothing */
        float rho = pw[i], nx = t->nrm[0][o], ny = t->nrm[1][o], nz = t->nrm[2][o];
        float so = (ox - t->p[0][o]) * nx + (oy - t->p[1][o]) * ny + (oz - t->p[2][o]) * nz;
        float sy = (px[i] - t->p[0][o]) * nx + (py[i] - t->p[1][o]) * ny + (pz[i] - t->p[2][o]) * nz;
        if (fabsf(so) > m->pw[o] && (so > 0.0f ? sy < -rho : sy > rho))
            keep &= ~(1u << i);
    }
    return keep;
}

/* Packs the kept lanes' w and 1 / z at val (2 popcount(keep) floats). */
static inline void pack(float *val, uint32_t keep, const float *w, const float *iz)
{
#if defined(__AVX512F__)
    const __mmask16 k = (__mmask16)keep;
    const __mmask16 lo = (__mmask16)((1u << __builtin_popcount(keep)) - 1u);
    const int n = __builtin_popcount(keep);
    _mm512_mask_storeu_ps(val, lo, _mm512_maskz_compress_ps(k, _mm512_loadu_ps(w)));
    _mm512_mask_storeu_ps(val + n, lo, _mm512_maskz_compress_ps(k, _mm512_loadu_ps(iz)));
#else
    uint32_t n = (uint32_t)__builtin_popcount(keep), j = 0;
    for (; keep; keep &= keep - 1, j++) {
        int i = __builtin_ctz(keep);
        val[j] = w[i];
        val[n + j] = iz[i];
    }
#endif
}

/* The inverse: 16 lanes, 0 where not kept. */
static inline void unpack(const float *val, uint32_t keep, float *w, float *iz)
{
#if defined(__AVX512F__)
    const __mmask16 k = (__mmask16)keep;
    const __mmask16 lo = (__mmask16)((1u << __builtin_popcount(keep)) - 1u);
    const int n = __builtin_popcount(keep);
    _mm512_storeu_ps(w, _mm512_maskz_expand_ps(k, _mm512_maskz_loadu_ps(lo, val)));
    _mm512_storeu_ps(iz, _mm512_maskz_expand_ps(k, _mm512_maskz_loadu_ps(lo, val + n)));
#else
    uint32_t n = (uint32_t)__builtin_popcount(keep), j = 0;
    for (int i = 0; i < 16; i++) {
        int in = (int)(keep >> i & 1u);
        w[i] = in ? val[j] : 0.0f;
        iz[i] = in ? val[n + j] : 0.0f;
        j += (uint32_t)in;
    }
#endif
}

typedef struct build_count {
    uint64_t tested, weighed, nodes, rasterized, masks, masked;
} build_count;

/* Ray k of the batch on worker wid: one traversal, its mask if the
 * frustum holds more than one plane, and its surviving splats kept. */
static void build_ray(splat_state *s, uint32_t wid, uint32_t k, int flags, build_count *bc)
{
    splat_mask *m = s->mask;
    mask_worker *x = &m->w[wid];
    const cdl_photon_ray *r = &s->rays.r[m->first + k];
    cdl_splat_ray sr = splat_ray_of(s, r);
    cdl_skd_count cnt = {0, 0, 0};
    x->nh = x->nf = 0;
    cdl_skd_splat_visit_both(&s->tree, &sr, flags, collect, x, &cnt);
    bc->tested += cnt.tested;
    bc->weighed += cnt.weighed;
    bc->nodes += cnt.nodes;
    m->rth[k] = wid;
    m->rseg0[k] = x->nseg;
    m->rnseg[k] = 0;
    if (x->oom)
        return;
    cdl_frame f = cdl_frame_from(r->d);
    const float U[3] = {f.t.x, f.t.y, f.t.z}, V[3] = {f.b.x, f.b.y, f.b.z};
    float hmax = r->h0 + r->dh * r->len;
    int g = 0; /* no mask unless the frustum holds more than one plane */
    if (hmax > 0.0f && !one_plane(s, r, x->held, x->nh)) {
        bc->masks++;
        g = MASK_G;
        if (2.0f * hmax < (float)g * m->rho)
            g = (int)ceilf(2.0f * hmax / m->rho);
        g = g < 1 ? 1 : g;
        if (x->nf) { /* nothing to filter: no buffer either */
            for (int c = 0; c < g * g; c++)
                x->grid[c] = UINT64_MAX;
            for (uint32_t b = 0; b < x->nh; b++) {
                rasterize(s, r, U, V, g, x->grid, &x->held[b]);
                bc->rasterized += (uint64_t)__builtin_popcount(x->held[b].mask);
            }
        }
    }
    const cdl_skd_part *parts = s->tree.parts;
    const uint32_t np = s->tree.nparts;
    uint32_t p = 0, cur = UINT32_MAX;
    for (uint32_t j = 0; j < x->nf; j++) {
        const mask_feas *fb = &x->feas[j];
        uint32_t keep = g ? filter(s, r, U, V, g, x->grid, fb) : fb->mask;
        bc->masked += (uint64_t)__builtin_popcount(fb->mask & ~keep);
        if (!keep)
            continue;
        while (p + 1 < np && fb->first >= parts[p].hi)
            p++;
        uint32_t nv = 2 * (uint32_t)__builtin_popcount(keep);
        if (cdl_grow((void **)&x->rec, &x->caprec, x->nrec + 1, sizeof *x->rec) ||
            cdl_grow((void **)&x->val, &x->capval, x->nval + nv, sizeof *x->val)) {
            x->oom = 1;
            return;
        }
        if (cur == UINT32_MAX || x->seg[cur].part != p) {
            if (cdl_grow((void **)&x->seg, &x->capseg, x->nseg + 1, sizeof *x->seg)) {
                x->oom = 1;
                return;
            }
            cur = x->nseg++;
            x->seg[cur] = (mask_seg){p, x->nrec, 0};
            m->rnseg[k]++;
        }
        x->rec[x->nrec++] = (mask_rec){fb->first, keep, x->nval};
        pack(x->val + x->nval, keep, fb->w, fb->iz);
        x->nval += nv;
        x->seg[cur].n++;
    }
}

/* Workers for every thread, each with its buffer; their kept splats
 * emptied for a new batch. */
static int workers(splat_mask *m)
{
    int nth = omp_get_max_threads();
    if (nth > m->nw) {
        mask_worker *w = realloc(m->w, sizeof *w * (size_t)nth);
        if (!w)
            return -1;
        memset(w + m->nw, 0, sizeof *w * (size_t)(nth - m->nw));
        m->w = w;
        m->nw = nth;
    }
    for (int i = 0; i < m->nw; i++) {
        mask_worker *w = &m->w[i];
        if (!w->grid && !(w->grid = malloc(sizeof *w->grid * MASK_G * MASK_G)))
            return -1;
        w->nrec = w->nval = w->nseg = 0;
        w->oom = 0;
    }
    return 0;
}

/* Every part's entries, ray by ray (a counting sort of the segments). */
static int by_part(splat_mask *m, uint32_t nparts, uint32_t n)
{
    if (m->npart < nparts || !m->pstart) {
        free(m->pstart);
        free(m->pcur);
        m->pstart = malloc(sizeof *m->pstart * ((size_t)nparts + 1));
        m->pcur = malloc(sizeof *m->pcur * ((size_t)nparts + 1));
        m->npart = nparts;
        if (!m->pstart || !m->pcur) {
            m->npart = 0;
            return -1;
        }
    }
    memset(m->pcur, 0, sizeof *m->pcur * ((size_t)nparts + 1));
    uint32_t total = 0;
    for (uint32_t k = 0; k < n; k++) {
        const mask_seg *sg = m->w[m->rth[k]].seg + m->rseg0[k];
        for (uint32_t j = 0; j < m->rnseg[k]; j++)
            m->pcur[sg[j].part]++;
        total += m->rnseg[k];
    }
    if (cdl_grow((void **)&m->plist, &m->cappl, total, sizeof *m->plist))
        return -1;
    for (uint32_t p = 0, at = 0; p <= nparts; p++) {
        uint32_t c = p < nparts ? m->pcur[p] : 0;
        m->pstart[p] = m->pcur[p] = at;
        at += c;
    }
    for (uint32_t k = 0; k < n; k++) {
        const mask_seg *sg = m->w[m->rth[k]].seg + m->rseg0[k];
        for (uint32_t j = 0; j < m->rnseg[k]; j++)
            m->plist[m->pcur[sg[j].part]++] = (mask_pentry){m->rth[k], k, sg[j].rec0, sg[j].n};
    }
    return 0;
}

int splat_mask_build(splat_state *s, uint32_t first, uint32_t n, int flags)
{
    splat_mask *m = s->mask;
    m->first = first;
    if (workers(m))
        return CDL_ERR_SYSTEM;
    build_count bc = {0, 0, 0, 0, 0, 0};
#pragma omp parallel
    {
        build_count c = {0, 0, 0, 0, 0, 0};
        uint32_t wid = (uint32_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 64)
        for (uint32_t k = 0; k < n; k++)
            build_ray(s, wid, k, flags, &c);
#pragma omp critical(splat_mask_count)
        {
            bc.tested += c.tested, bc.weighed += c.weighed, bc.nodes += c.nodes;
            bc.rasterized += c.rasterized, bc.masks += c.masks, bc.masked += c.masked;
        }
    }
    for (int i = 0; i < m->nw; i++)
        if (m->w[i].oom)
            return CDL_ERR_SYSTEM;
    if (by_part(m, s->tree.nparts, n))
        return CDL_ERR_SYSTEM;
    s->st.mask_tested += bc.tested;
    s->st.tested += bc.weighed;
    s->st.nodes += bc.nodes;
    s->st.rasterized += bc.rasterized;
    s->st.mask_rays += bc.masks;
    s->st.masked += bc.masked;
    return 0;
}

void splat_mask_replay(const splat_state *s, uint32_t part, splat_mask_fn fn, void *ctx)
{
    const splat_mask *m = s->mask;
    if (part >= m->npart)
        return;
    for (uint32_t e = m->pstart[part]; e < m->pstart[part + 1]; e++) {
        const mask_pentry *pe = &m->plist[e];
        const mask_worker *x = &m->w[pe->w];
        for (uint32_t j = pe->rec0; j < pe->rec0 + pe->n; j++) {
            const mask_rec *rc = &x->rec[j];
            float w[16], iz[16];
            unpack(x->val + rc->off, rc->keep, w, iz);
            fn(ctx, m->first + pe->ray, rc->first, rc->keep, w, iz);
        }
    }
}
