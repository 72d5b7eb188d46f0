/* The visibility mask on one photon ray (see mask.c for what the mask
 * is): most rays need no buffer, and the tests that show it are cheaper
 * than the buffer. A frustum holding one plane needs none (one_plane).
 * Nor does one where no sample could hide a feasible one whatever the
 * buffer holds (hiders, which also marks the samples that may): a hider lies nearer than the sample by more
 * than its footprint and has the sample behind its tangent plane, and
 * for a hider's normal n the feasible samples' extremes of p . n +- pw
 * bound that for all of them at once; on faceted surfaces a frustum
 * meets few distinct normals. A sample at least as far along the ray as
 * every feasible one minus its footprint (reach) hides nothing and, being
 * behind whatever it would shadow, unveils nothing either: it is not
 * rasterized. The loops run 16 lanes at a time (AVX-512 where there is,
 * else plain loops the compiler vectorizes). */
#include <math.h>
#include <stddef.h>
#include <string.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "integrators/splat/mask_ray.h"

static inline uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

#if defined(__AVX512F__)
/* (p - o) . n of batch b's lanes, and p, n. */
typedef struct lanes16 {
    __m512 px, py, pz, nx, ny, nz, so;
} lanes16;

static inline lanes16 load16(const cdl_skd *t, uint32_t b, const cdl_photon_ray *r)
{
    lanes16 l;
    l.px = _mm512_loadu_ps(t->p[0] + b), l.py = _mm512_loadu_ps(t->p[1] + b), l.pz = _mm512_loadu_ps(t->p[2] + b);
    l.nx = _mm512_loadu_ps(t->nrm[0] + b), l.ny = _mm512_loadu_ps(t->nrm[1] + b), l.nz = _mm512_loadu_ps(t->nrm[2] + b);
    __m512 Dx = _mm512_sub_ps(l.px, _mm512_set1_ps(r->o.x)), Dy = _mm512_sub_ps(l.py, _mm512_set1_ps(r->o.y)),
           Dz = _mm512_sub_ps(l.pz, _mm512_set1_ps(r->o.z));
    l.so = _mm512_fmadd_ps(Dz, l.nz, _mm512_fmadd_ps(Dy, l.ny, _mm512_mul_ps(Dx, l.nx)));
    return l;
}

static inline __m512 dot16(__m512 x, __m512 y, __m512 z, float a, float b, float c)
{
    return _mm512_fmadd_ps(z, _mm512_set1_ps(c), _mm512_fmadd_ps(y, _mm512_set1_ps(b), _mm512_mul_ps(x, _mm512_set1_ps(a))));
}
#endif

/* Within a quarter of the smallest footprint of the first one's plane,
 * normals within 0.1 degree, not counting the surface the ray leaves
 * (within a footprint of the origin: no occluder). No sample of a plane
 * hides another (the filter needs one behind another's tangent plane by
 * its footprint). The largest distance only grows and the smallest
 * footprint only shrinks sample by sample, so a whole batch is tested at
 * once. */
int splat_mask_one_plane(const mask_ray *x, const mask_held *h, uint32_t nh)
{
    const cdl_skd *t = x->t;
    const float *pw = x->pw;
    const float ox = x->r->o.x, oy = x->r->o.y, oz = x->r->o.z;
    uint32_t k = 0, q0 = UINT32_MAX;
    for (; k < nh && q0 == UINT32_MAX; k++)
        for (uint32_t mask = h[k].mask; mask; mask &= mask - 1) {
            uint32_t q = h[k].first + (uint32_t)__builtin_ctz(mask);
            float so = (t->p[0][q] - ox) * t->nrm[0][q] + (t->p[1][q] - oy) * t->nrm[1][q] +
                       (t->p[2][q] - oz) * t->nrm[2][q];
            if (fabsf(so) > pw[q]) {
                q0 = q;
                break;
            }
        }
    if (q0 == UINT32_MAX)
        return 1;
    const float p0x = t->p[0][q0], p0y = t->p[1][q0], p0z = t->p[2][q0];
    const float n0x = t->nrm[0][q0], n0y = t->nrm[1][q0], n0z = t->nrm[2][q0];
#if defined(__AVX512F__)
    const __m512 thr = _mm512_set1_ps(0.9999985f);
    __m512 dmax = _mm512_setzero_ps(), pmin = _mm512_set1_ps(INFINITY);
    for (k--; k < nh; k++) {
        const uint32_t b = h[k].first;
        lanes16 l = load16(t, b, x->r);
        __m512 pb = _mm512_loadu_ps(pw + b);
        __mmask16 ok = _mm512_mask_cmp_ps_mask((__mmask16)h[k].mask, _mm512_abs_ps(l.so), pb, _CMP_GT_OQ);
        __m512 d = _mm512_abs_ps(dot16(_mm512_sub_ps(l.px, _mm512_set1_ps(p0x)), _mm512_sub_ps(l.py, _mm512_set1_ps(p0y)),
                                       _mm512_sub_ps(l.pz, _mm512_set1_ps(p0z)), n0x, n0y, n0z));
        if (_mm512_mask_cmp_ps_mask(ok, dot16(l.nx, l.ny, l.nz, n0x, n0y, n0z), thr, _CMP_LT_OQ))
            return 0;
        /* max and min return their second operand on a NaN: none enters */
        dmax = _mm512_mask_max_ps(dmax, ok, d, dmax);
        pmin = _mm512_mask_min_ps(pmin, ok, pb, pmin);
        if (_mm512_reduce_max_ps(dmax) > 0.25f * _mm512_reduce_min_ps(pmin))
            return 0;
    }
#else
    float dmax = 0.0f, pmin = INFINITY;
    for (k--; k < nh; k++) {
        const uint32_t b = h[k].first, mask = h[k].mask;
        const float *px = t->p[0] + b, *py = t->p[1] + b, *pz = t->p[2] + b;
        const float *nx = t->nrm[0] + b, *ny = t->nrm[1] + b, *nz = t->nrm[2] + b, *pb = pw + b;
        int bent = 0;
        for (uint32_t i = 0; i < 16; i++) {
            float so = (px[i] - ox) * nx[i] + (py[i] - oy) * ny[i] + (pz[i] - oz) * nz[i];
            if (!(mask >> i & 1u) || !(fabsf(so) > pb[i]))
                continue;
            float d = fabsf((px[i] - p0x) * n0x + (py[i] - p0y) * n0y + (pz[i] - p0z) * n0z);
            bent |= nx[i] * n0x + ny[i] * n0y + nz[i] * n0z < 0.9999985f;
            dmax = d > dmax ? d : dmax;
            pmin = pb[i] < pmin ? pb[i] : pmin;
        }
        if (bent || dmax > 0.25f * pmin)
            return 0;
    }
#endif
    return 1;
}

/* Each feasible lane's cell (-1: outside the grid) and z - pw as bits,
 * the filter's threshold: a front sample whose distance bits are below it
 * is nearer by more than the footprint (distances >= 0 order as their
 * bits; a negative z - pw is a negative int, below every distance). */
static inline void cells16(const mask_ray *x, const mask_feas *fb, int *cell, int32_t *zb)
{
    const cdl_skd *t = x->t;
    const cdl_photon_ray *r = x->r;
    const uint32_t first = fb->first;
    const float *iz = fb->iz, *U = x->U, *V = x->V;
    const int g = x->g;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float h0 = r->h0, dh = r->dh, len = r->len, ics = 0.5f * (float)g, half = ics;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = x->pw + first;
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
}

void splat_mask_reach(mask_ray *x, const mask_feas *f, uint32_t nf)
{
    int32_t reach = INT32_MIN;
#if defined(__AVX512F__)
    /* the same division and subtraction 16 lanes at a time */
    __m512i rv = _mm512_set1_epi32(INT32_MIN);
    for (uint32_t j = 0; j < nf; j++) {
        const __m512 iz = _mm512_loadu_ps(f[j].iz);
        const __m512 z = _mm512_maskz_div_ps(_mm512_cmp_ps_mask(iz, _mm512_setzero_ps(), _CMP_GT_OQ),
                                             _mm512_set1_ps(1.0f), iz);
        const __m512 b = _mm512_sub_ps(z, _mm512_loadu_ps(x->pw + f[j].first));
        rv = _mm512_mask_max_epi32(rv, (__mmask16)f[j].mask, rv, _mm512_castps_si512(b));
    }
    reach = _mm512_reduce_max_epi32(rv);
#else
    for (uint32_t j = 0; j < nf; j++) {
        const float *iz = f[j].iz, *pw = x->pw + f[j].first;
        for (uint32_t mask = f[j].mask; mask; mask &= mask - 1) {
            int i = __builtin_ctz(mask);
            float z = iz[i] > 0.0f ? 1.0f / iz[i] : 0.0f; /* as cells16 */
            int32_t b = (int32_t)float_bits(z - pw[i]);
            reach = b > reach ? b : reach;
        }
    }
#endif
    x->reach = reach;
}

/* The feasible samples' extremes along a hider's normal n: the least
 * p . n + pw and the largest p . n - pw. */
typedef struct bound {
    float n[3], lo, hi;
} bound;

static bound bound_of(const mask_ray *x, const mask_feas *f, uint32_t nf, float nx, float ny, float nz)
{
    const cdl_skd *t = x->t;
    bound b = {{nx, ny, nz}, INFINITY, -INFINITY};
#if defined(__AVX512F__)
    __m512 lo = _mm512_set1_ps(INFINITY), hi = _mm512_set1_ps(-INFINITY);
    for (uint32_t j = 0; j < nf; j++) {
        const uint32_t q = f[j].first;
        const __mmask16 k = (__mmask16)f[j].mask;
        __m512 d = dot16(_mm512_loadu_ps(t->p[0] + q), _mm512_loadu_ps(t->p[1] + q), _mm512_loadu_ps(t->p[2] + q), nx, ny, nz);
        __m512 pb = _mm512_loadu_ps(x->pw + q);
        lo = _mm512_mask_min_ps(lo, k, _mm512_add_ps(d, pb), lo);
        hi = _mm512_mask_max_ps(hi, k, _mm512_sub_ps(d, pb), hi);
    }
    b.lo = _mm512_reduce_min_ps(lo);
    b.hi = _mm512_reduce_max_ps(hi);
#else
    for (uint32_t j = 0; j < nf; j++)
        for (uint32_t mask = f[j].mask; mask; mask &= mask - 1) {
            uint32_t q = f[j].first + (uint32_t)__builtin_ctz(mask);
            float d = t->p[0][q] * nx + t->p[1][q] * ny + t->p[2][q] * nz;
            b.lo = fminf(b.lo, d + x->pw[q]);
            b.hi = fmaxf(b.hi, d - x->pw[q]);
        }
#endif
    return b;
}

#define BOUNDS 8 /* distinct hider normals a ray may meet before it just builds its buffer */

/* The bound of normal n among the *nb made so far, made if new; -1 past
 * BOUNDS. */
static int bound_find(bound *bd, int *nb, const mask_ray *x, const mask_feas *f, uint32_t nf, float nx, float ny,
                      float nz)
{
    int e = 0;
    while (e < *nb && !(bd[e].n[0] == nx && bd[e].n[1] == ny && bd[e].n[2] == nz))
        e++;
    if (e == *nb) {
        if (*nb == BOUNDS)
            return -1;
        bd[(*nb)++] = bound_of(x, f, nf, nx, ny, nz);
    }
    return e;
}

/* The filter hides feasible y behind front sample o when o is nearer by
 * more than pw_y, the origin lies off o's plane by more than pw_o and y
 * lies behind it by more than pw_y: (p_y - p_o) . n_o < -pw_y with the
 * origin in front (p_y . n + pw_y < p_o . n), > pw_y with it behind.
 * Every lane that may be such an o (by rounding too: eps) is a hider. */
int splat_mask_hiders(const mask_ray *x, mask_held *h, uint32_t nh, const mask_feas *f, uint32_t nf)
{
    const cdl_skd *t = x->t;
    const float eps = x->eps;
    bound bd[BOUNDS];
    int nb = 0;
    uint32_t any = 0;
    for (uint32_t k = 0; k < nh; k++) {
        const uint32_t b = h[k].first;
        uint32_t hid = 0;
#if defined(__AVX512F__)
        lanes16 l = load16(t, b, x->r);
        __m512 pb = _mm512_sub_ps(_mm512_loadu_ps(x->pw + b), _mm512_set1_ps(eps));
        __mmask16 rel = _mm512_mask_cmp_ps_mask((__mmask16)h[k].mask, _mm512_abs_ps(l.so), pb, _CMP_GT_OQ);
        __m512i zk = _mm512_castps_si512(_mm512_add_ps(_mm512_loadu_ps(h[k].z), _mm512_setzero_ps()));
        rel = _mm512_mask_cmplt_epi32_mask(rel, zk, _mm512_set1_epi32(x->reach));
        while (rel) {
            int i = __builtin_ctz(rel);
            float nx = t->nrm[0][b + (uint32_t)i], ny = t->nrm[1][b + (uint32_t)i], nz = t->nrm[2][b + (uint32_t)i];
            __mmask16 same = _mm512_mask_cmp_ps_mask(rel, l.nx, _mm512_set1_ps(nx), _CMP_EQ_OQ);
            same = _mm512_mask_cmp_ps_mask(same, l.ny, _mm512_set1_ps(ny), _CMP_EQ_OQ);
            same = _mm512_mask_cmp_ps_mask(same, l.nz, _mm512_set1_ps(nz), _CMP_EQ_OQ);
            if (!(same >> i & 1u)) { /* not a number */
                hid |= 1u << i;
                rel &= (__mmask16) ~(1u << i);
                continue;
            }
            int e = bound_find(bd, &nb, x, f, nf, nx, ny, nz);
            if (e < 0) {
                hid |= rel;
                break;
            }
            __m512 d = dot16(l.px, l.py, l.pz, nx, ny, nz);
            __mmask16 front = _mm512_mask_cmp_ps_mask(same, l.so, _mm512_set1_ps(eps), _CMP_LT_OQ);
            __mmask16 back = _mm512_mask_cmp_ps_mask(same, l.so, _mm512_set1_ps(-eps), _CMP_GT_OQ);
            hid |= _mm512_mask_cmp_ps_mask(front, _mm512_set1_ps(bd[e].lo), _mm512_add_ps(d, _mm512_set1_ps(eps)), _CMP_LT_OQ) |
                   _mm512_mask_cmp_ps_mask(back, _mm512_set1_ps(bd[e].hi), _mm512_sub_ps(d, _mm512_set1_ps(eps)), _CMP_GT_OQ);
            rel &= (__mmask16)~same;
        }
#else
        for (uint32_t mask = h[k].mask; mask; mask &= mask - 1) {
            int i = __builtin_ctz(mask);
            uint32_t q = b + (uint32_t)i;
            float nx = t->nrm[0][q], ny = t->nrm[1][q], nz = t->nrm[2][q];
            float so = (t->p[0][q] - x->r->o.x) * nx + (t->p[1][q] - x->r->o.y) * ny + (t->p[2][q] - x->r->o.z) * nz;
            if (!(fabsf(so) > x->pw[q] - eps) || !((int32_t)float_bits(h[k].z[i] + 0.0f) < x->reach))
                continue;
            int e = nx == nx && ny == ny && nz == nz ? bound_find(bd, &nb, x, f, nf, nx, ny, nz) : -1;
            float d = t->p[0][q] * nx + t->p[1][q] * ny + t->p[2][q] * nz;
            if (e < 0 || (so < eps && bd[e].lo < d + eps) || (so > -eps && bd[e].hi > d - eps))
                hid |= 1u << i;
        }
#endif
        h[k].hide = hid;
        any |= hid;
    }
    return any != 0;
}

/* z-min of a cell with key (a branch-free select: the loads forward
 * from the stores of the lanes before, which hit the same cells). */
static inline void cell_min(uint64_t *c, uint64_t key) { *c = key < *c ? key : *c; }

#if defined(__AVX512F__)
/* The batch's boxes when they lie within 8 columns from A0 and R rows
 * from B0 (R = 2, 4 or 8, a constant: the loops unroll): the window's
 * rows z-min in registers, a row's 8 cells one vector, each sample a
 * masked min per row (its columns in the rows it covers), then one
 * update of the grid per row. Scalar updates of the grid each load what
 * the one before stored: a chain of store forwards. */
static inline void window8(const mask_ray *x, uint32_t first, uint32_t live, const int (*box)[16], const uint32_t *zk,
                           int A0, int B0, int B1, const int R)
{
    const __m512i one = _mm512_set1_epi32(1), two = _mm512_set1_epi32(2);
    const __m512i a0 = _mm512_loadu_si512(box[0]), a1 = _mm512_loadu_si512(box[1]);
    const __m512i b0 = _mm512_loadu_si512(box[2]), b1 = _mm512_loadu_si512(box[3]);
    /* per lane its columns and rows in the window, as bits */
    const __m512i cols = _mm512_sllv_epi32(_mm512_sub_epi32(_mm512_sllv_epi32(two, _mm512_sub_epi32(a1, a0)), one),
                                           _mm512_sub_epi32(a0, _mm512_set1_epi32(A0)));
    const __m512i rows = _mm512_sllv_epi32(_mm512_sub_epi32(_mm512_sllv_epi32(two, _mm512_sub_epi32(b1, b0)), one),
                                           _mm512_sub_epi32(b0, _mm512_set1_epi32(B0)));
    uint8_t km[8][16];
    for (int r = 0; r < R; r++) {
        __mmask16 in = _mm512_test_epi32_mask(rows, _mm512_set1_epi32(1 << r));
        _mm_storeu_si128((__m128i *)km[r], _mm512_cvtepi32_epi8(_mm512_maskz_mov_epi32(in, cols)));
    }
    uint64_t key[16];
    const __m512i z = _mm512_loadu_si512(zk);
    const __m512i idx = _mm512_add_epi32(_mm512_set1_epi32((int)first),
                                         _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15));
    _mm512_storeu_si512(key, _mm512_or_si512(_mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_castsi512_si256(z)), 32),
                                             _mm512_cvtepu32_epi64(_mm512_castsi512_si256(idx))));
    _mm512_storeu_si512(key + 8,
                        _mm512_or_si512(_mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(z, 1)), 32),
                                        _mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(idx, 1))));
    /* two sets of rows, the lanes taken in pairs: half the chain of mins */
    __m512i acc[8], alt[8];
    for (int r = 0; r < R; r++)
        acc[r] = alt[r] = _mm512_set1_epi64(-1);
    uint32_t m = live;
    for (; m & (m - 1); m &= m - 1) {
        int i = __builtin_ctz(m);
        m &= m - 1;
        int j = __builtin_ctz(m);
        const __m512i k = _mm512_set1_epi64((long long)key[i]), l = _mm512_set1_epi64((long long)key[j]);
        for (int r = 0; r < R; r++) {
            acc[r] = _mm512_mask_min_epu64(acc[r], (__mmask8)km[r][i], acc[r], k);
            alt[r] = _mm512_mask_min_epu64(alt[r], (__mmask8)km[r][j], alt[r], l);
        }
    }
    if (m) {
        int i = __builtin_ctz(m);
        const __m512i k = _mm512_set1_epi64((long long)key[i]);
        for (int r = 0; r < R; r++)
            acc[r] = _mm512_mask_min_epu64(acc[r], (__mmask8)km[r][i], acc[r], k);
    }
    const int g = x->g;
    const __mmask8 in = (__mmask8)(g - A0 >= 8 ? 0xffu : (1u << (g - A0)) - 1u);
    for (int r = 0; r <= B1 - B0; r++) {
        uint64_t *c = x->grid + (ptrdiff_t)(B0 + r) * g + A0;
        _mm512_mask_storeu_epi64(c, in, _mm512_min_epu64(_mm512_maskz_loadu_epi64(in, c), _mm512_min_epu64(acc[r], alt[r])));
    }
}
#endif

uint32_t splat_mask_rasterize(const mask_ray *x, const mask_held *hb) { return splat_mask_rasterize_lanes(x, hb, hb->mask); }

uint32_t splat_mask_rasterize_lanes(const mask_ray *x, const mask_held *hb, uint32_t lanes)
{
    const cdl_skd *t = x->t;
    const cdl_photon_ray *r = x->r;
    const uint32_t first = hb->first;
    const float *zz = hb->z, *U = x->U, *V = x->V;
    const int g = x->g;
    uint64_t *grid = x->grid;
    /* lanes nearer than the reach, as their key's distance bits (+ 0: -0
     * becomes +0, whose bits order with the rest) */
    uint32_t zk[16], near = 0;
#if defined(__AVX512F__)
    __m512i zb = _mm512_castps_si512(_mm512_add_ps(_mm512_loadu_ps(zz), _mm512_setzero_ps()));
    near = _mm512_mask_cmplt_epi32_mask((__mmask16)lanes, zb, _mm512_set1_epi32(x->reach));
    _mm512_storeu_si512(zk, zb);
#else
    for (int i = 0; i < 16; i++) {
        zk[i] = float_bits(zz[i] + 0.0f);
        near |= (uint32_t)((int32_t)zk[i] < x->reach) << i;
    }
    near &= lanes;
#endif
    if (!near)
        return 0;
    const float ics = 0.5f * (float)g;
    const float h0 = r->h0, dh = r->dh, len = r->len;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first;
    const float *nx = t->nrm[0] + first, *ny = t->nrm[1] + first, *nz = t->nrm[2] + first, *pw = x->pw + first;
    const float *ax[6];
    for (int c = 0; c < 6; c++)
        ax[c] = x->ax[c] + first;
    int box[4][16], c0[16], da[16], db[16], kind[16];
    /* the cells each lane covers, 16 at a time (lanes past m are masked) */
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        float Dx = px[i] - ox, Dy = py[i] - oy, Dz = pz[i] - oz, z = zz[i];
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        /* the surface the ray leaves hides nothing, and in the cells
         * around the ray it would stand in front of what does */
        float so = Dx * nx[i] + Dy * ny[i] + Dz * nz[i];
        int keep = fabsf(so) > pw[i];
        /* in the kernel's plane: lateral offsets over the radius at z */
        float ih = ics / (h0 + dh * (z < len ? z : len));
        float u = (ex * U[0] + ey * U[1] + ez * U[2]) * ih + 0.5f * (float)g;
        float v = (ex * V[0] + ey * V[1] + ez * V[2]) * ih + 0.5f * (float)g;
        /* the patch's ellipse seen along d: its half extents in u and v */
        float t1 = ax[0][i] * U[0] + ax[1][i] * U[1] + ax[2][i] * U[2], s1 = ax[3][i] * U[0] + ax[4][i] * U[1] + ax[5][i] * U[2];
        float t2 = ax[0][i] * V[0] + ax[1][i] * V[1] + ax[2][i] * V[2], s2 = ax[3][i] * V[0] + ax[4][i] * V[1] + ax[5][i] * V[2];
        float fu = sqrtf(t1 * t1 + s1 * s1) * ih, fv = sqrtf(t2 * t2 + s2 * s2) * ih;
        /* + 1 so truncation floors; clamped to the grid */
        /* (comparisons, not fminf: the loop stays vectorized) */
        float u0 = u - fu + 1.0f, u1 = u + fu + 1.0f, v0 = v - fv + 1.0f, v1 = v + fv + 1.0f, G = (float)g;
        u0 = u0 > 1.0f ? u0 : 1.0f, u1 = u1 > 0.0f ? u1 : 0.0f, v0 = v0 > 1.0f ? v0 : 1.0f, v1 = v1 > 0.0f ? v1 : 0.0f;
        int a0 = (int)(u0 < G ? u0 : G) - 1, a1 = (int)(u1 < G ? u1 : G) - 1;
        int b0 = (int)(v0 < G ? v0 : G) - 1, b1 = (int)(v1 < G ? v1 : G) - 1;
        box[0][i] = a0, box[1][i] = a1, box[2][i] = b0, box[3][i] = b1;
        /* most boxes are at most 2 x 2 cells: their corner cells (a
         * narrower box repeats some; z-min twice changes nothing) */
        c0[i] = b0 * g + a0;
        da[i] = a1 - a0;
        db[i] = (b1 - b0) * g;
        int some = keep & (a1 >= a0) & (b1 >= b0);
        kind[i] = some ? (a1 - a0 <= 1) & (b1 - b0 <= 1) ? 1 : 2 : 0;
    }
    uint32_t small = 0, large = 0;
    for (int i = 0; i < 16; i++) {
        small |= (uint32_t)(kind[i] == 1) << i;
        large |= (uint32_t)(kind[i] == 2) << i;
    }
    small &= near, large &= near;
#if defined(__AVX512F__)
    const uint32_t live = small | large;
    if (live && !x->plain) {
        /* the live boxes' extremes in one reduction: a lane's a0, b0,
         * 255 - a1 and 255 - b1 (all in [0, g)) as its bytes, their minima */
        const __m512i ff = _mm512_set1_epi32(255);
        __m512i pk = _mm512_or_si512(
            _mm512_or_si512(_mm512_loadu_si512(box[0]), _mm512_slli_epi32(_mm512_loadu_si512(box[2]), 8)),
            _mm512_or_si512(_mm512_slli_epi32(_mm512_sub_epi32(ff, _mm512_loadu_si512(box[1])), 16),
                            _mm512_slli_epi32(_mm512_sub_epi32(ff, _mm512_loadu_si512(box[3])), 24)));
        pk = _mm512_mask_mov_epi32(_mm512_set1_epi32(-1), (__mmask16)live, pk);
        __m256i h = _mm256_min_epu8(_mm512_castsi512_si256(pk), _mm512_extracti64x4_epi64(pk, 1));
        __m128i q = _mm_min_epu8(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
        q = _mm_min_epu8(q, _mm_shuffle_epi32(q, 0x4e));
        q = _mm_min_epu8(q, _mm_shuffle_epi32(q, 0xb1));
        const uint32_t e = (uint32_t)_mm_cvtsi128_si32(q);
        const int A0 = (int)(e & 255u), B0 = (int)(e >> 8 & 255u);
        const int A1 = 255 - (int)(e >> 16 & 255u), B1 = 255 - (int)(e >> 24);
        if (A1 - A0 < 8 && B1 - B0 < 8) {
            if (B1 - B0 < 2)
                window8(x, first, live, box, zk, A0, B0, B1, 2);
            else if (B1 - B0 < 4)
                window8(x, first, live, box, zk, A0, B0, B1, 4);
            else
                window8(x, first, live, box, zk, A0, B0, B1, 8);
            return (uint32_t)__builtin_popcount(live);
        }
    }
#endif
    for (uint32_t m = small; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        uint64_t key = (uint64_t)zk[i] << 32 | (first + (uint32_t)i);
        uint64_t *c = grid + c0[i];
        cell_min(c, key);
        cell_min(c + da[i], key);
        cell_min(c + db[i], key);
        cell_min(c + db[i] + da[i], key);
    }
    for (uint32_t m = large; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        uint64_t key = (uint64_t)zk[i] << 32 | (first + (uint32_t)i);
        for (int b = box[2][i]; b <= box[3][i]; b++)
            for (int a = box[0][i]; a <= box[1][i]; a++)
                cell_min(grid + b * g + a, key);
    }
    return (uint32_t)__builtin_popcount(small | large);
}

uint32_t splat_mask_filter(const mask_ray *x, const mask_feas *fb, uint32_t *front)
{
    const cdl_skd *t = x->t;
    const uint64_t *grid = x->grid;
    const uint32_t first = fb->first, mask = fb->mask;
    const float ox = x->r->o.x, oy = x->r->o.y, oz = x->r->o.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = x->pw + first;
    int cell[16];
    int32_t zb[16];
    cells16(x, fb, cell, zb);
    /* candidates: a front sample, not the lane itself, nearer by more
     * than the lane's footprint */
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
    if (!cm)
        return mask;
    /* hidden if the sample lies on the far side of the occluder's
     * tangent plane from the ray's origin (by its footprint); an occluder
     * whose plane holds the origin (the surface the ray leaves) hides
     * nothing */
    const __m512 zero = _mm512_setzero_ps();
    __m512 nx = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[0], 4);
    __m512 ny = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[1], 4);
    __m512 nz = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[2], 4);
    __m512 qx = _mm512_mask_i32gather_ps(zero, cm, o, t->p[0], 4);
    __m512 qy = _mm512_mask_i32gather_ps(zero, cm, o, t->p[1], 4);
    __m512 qz = _mm512_mask_i32gather_ps(zero, cm, o, t->p[2], 4);
    __m512 pwo = _mm512_mask_i32gather_ps(zero, cm, o, x->pw, 4);
    __m512 so = _mm512_fmadd_ps(_mm512_sub_ps(_mm512_set1_ps(oz), qz), nz,
                         _mm512_fmadd_ps(_mm512_sub_ps(_mm512_set1_ps(oy), qy), ny,
                                         _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(ox), qx), nx)));
    __m512 sy = _mm512_fmadd_ps(_mm512_sub_ps(_mm512_loadu_ps(pz), qz), nz,
                                _mm512_fmadd_ps(_mm512_sub_ps(_mm512_loadu_ps(py), qy), ny,
                                                _mm512_mul_ps(_mm512_sub_ps(_mm512_loadu_ps(px), qx), nx)));
    __m512 rho = _mm512_loadu_ps(pw);
    __mmask16 hide = _mm512_mask_cmp_ps_mask(cm, _mm512_abs_ps(so), pwo, _CMP_GT_OQ);
    __mmask16 pos = _mm512_cmp_ps_mask(so, zero, _CMP_GT_OQ);
    hide &= (__mmask16)((pos & _mm512_cmp_ps_mask(sy, _mm512_sub_ps(zero, rho), _CMP_LT_OQ)) |
                        (~pos & _mm512_cmp_ps_mask(sy, rho, _CMP_GT_OQ)));
    if (hide) {
        uint32_t f = (uint32_t)_mm512_mask_reduce_max_epu32(hide, zk);
        *front = f > *front ? f : *front;
    }
    return mask & ~(uint32_t)hide;
#else
    uint32_t hit = 0, occ[16], ozb[16];
    for (int i = 0; i < 16; i++) {
        if (!(mask >> i & 1u) || cell[i] < 0)
            continue;
        uint64_t key = grid[cell[i]];
        occ[i] = (uint32_t)key;
        ozb[i] = (uint32_t)(key >> 32);
        hit |= (uint32_t)((occ[i] != UINT32_MAX) & (occ[i] != first + (uint32_t)i) &
                          ((int32_t)(uint32_t)(key >> 32) < zb[i])) << i;
    }
    uint32_t keep = mask;
    for (; hit; hit &= hit - 1) {
        uint32_t i = (uint32_t)__builtin_ctz(hit), o = occ[i];
        /* hidden if the sample lies on the far side of the occluder's
         * tangent plane from the ray's origin; an occluder whose plane
         * holds the origin (the surface the ray leaves) hides nothing */
        float rho = pw[i], nx = t->nrm[0][o], ny = t->nrm[1][o], nz = t->nrm[2][o];
        float so = (ox - t->p[0][o]) * nx + (oy - t->p[1][o]) * ny + (oz - t->p[2][o]) * nz;
        float sy = (px[i] - t->p[0][o]) * nx + (py[i] - t->p[1][o]) * ny + (pz[i] - t->p[2][o]) * nz;
        if (fabsf(so) > x->pw[o] && (so > 0.0f ? sy < -rho : sy > rho)) {
            keep &= ~(1u << i);
            *front = ozb[i] > *front ? ozb[i] : *front;
        }
    }
    return keep;
#endif
}
