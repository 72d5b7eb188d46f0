/* The visibility mask on one photon ray (see mask.c for what the mask
 * is): its occluders rasterized into its buffer, and its feasible samples
 * filtered through it. A cell keeps the occluder nearest the origin; a
 * feasible sample is hidden when that one lies nearer by more than the
 * sample's footprint and has the sample behind its tangent plane. The
 * loops run 16 lanes at a time (AVX-512 where there is, else plain loops
 * the compiler vectorizes). */
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

/* Each feasible lane's cell (-1: outside the grid) and z - pw as bits,
 * the filter's threshold: a front sample whose distance bits are below it
 * is nearer by more than the footprint (distances >= 0 order as their
 * bits; a negative z - pw is a negative int, below every distance). */
static inline void cells16(const mask_ray *x, uint32_t first, int *cell, int32_t *zb)
{
    const cdl_skd *t = x->ft;
    const cdl_photon_ray *r = x->r;
    const float *U = x->U, *V = x->V;
    const int g = x->g;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float h0 = r->h0, dh = r->dh, len = r->len, ics = 0.5f * (float)g, half = ics;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = x->fpw + first;
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        /* z as the occluders have theirs (the traversal's) */
        float Dx = px[i] - ox, Dy = py[i] - oy, Dz = pz[i] - oz, z = Dx * dx + Dy * dy + Dz * dz;
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        float ih = ics / (h0 + dh * (z < len ? z : len));
        float u = (ex * U[0] + ey * U[1] + ez * U[2]) * ih + half, v = (ex * V[0] + ey * V[1] + ez * V[2]) * ih + half;
        int in = u >= 0.0f && v >= 0.0f && u < (float)g && v < (float)g;
        cell[i] = in ? (int)v * g + (int)u : -1;
        zb[i] = (int32_t)float_bits(z - pw[i]);
    }
}

/* z-min of a cell with key (a branch-free select: the loads forward
 * from the stores of the lanes before, which hit the same cells). */
static inline void cell_min(uint64_t *c, uint64_t key) { *c = key < *c ? key : *c; }

/* The lanes of [first, first + 16) in `lanes` that get rasterized, with
 * their keys' distance bits zk (+ 0: -0 becomes +0, whose bits order with
 * the rest), the cells they cover (box: columns a0, a1 and rows b0, b1,
 * inclusive; c0, da, db: a box of at most 2 x 2 cells as its corners) and
 * small / large: the lanes whose box is at most 2 x 2 cells or larger. */
typedef struct lane_cells {
    uint32_t zk[16];
    int box[4][16], c0[16], da[16], db[16];
    uint32_t small, large;
} lane_cells;

#if defined(__AVX512F__)
/* Per lane, its columns of the window from A0 (8 bits) and its rows from
 * B0 (bits). */
static inline void window_bits(const lane_cells *L, int A0, int B0, __m512i *cols, __m512i *rows)
{
    const __m512i one = _mm512_set1_epi32(1), two = _mm512_set1_epi32(2);
    const __m512i a0 = _mm512_loadu_si512(L->box[0]), a1 = _mm512_loadu_si512(L->box[1]);
    const __m512i b0 = _mm512_loadu_si512(L->box[2]), b1 = _mm512_loadu_si512(L->box[3]);
    *cols = _mm512_sllv_epi32(_mm512_sub_epi32(_mm512_sllv_epi32(two, _mm512_sub_epi32(a1, a0)), one),
                              _mm512_sub_epi32(a0, _mm512_set1_epi32(A0)));
    *rows = _mm512_sllv_epi32(_mm512_sub_epi32(_mm512_sllv_epi32(two, _mm512_sub_epi32(b1, b0)), one),
                              _mm512_sub_epi32(b0, _mm512_set1_epi32(B0)));
}
#endif

#if defined(__AVX512F__)
/* The batch's boxes when they lie within 8 columns from A0 and R rows
 * from B0 (R = 2, 4 or 8, a constant: the loops unroll): the window's
 * rows z-min in registers, a row's 8 cells one vector, each sample a
 * masked min per row (its columns in the rows it covers), then one
 * update of the grid per row. Scalar updates of the grid each load what
 * the one before stored: a chain of store forwards. */
static inline void window8(const mask_ray *x, uint32_t first, uint32_t live, const lane_cells *L, int A0, int B0,
                           int B1, const int R)
{
    __m512i cols, rows;
    window_bits(L, A0, B0, &cols, &rows);
    uint8_t km[8][16];
    for (int r = 0; r < R; r++) {
        __mmask16 in = _mm512_test_epi32_mask(rows, _mm512_set1_epi32(1 << r));
        _mm_storeu_si128((__m128i *)km[r], _mm512_cvtepi32_epi8(_mm512_maskz_mov_epi32(in, cols)));
    }
    uint64_t key[16];
    const __m512i z = _mm512_loadu_si512(L->zk);
    const __m512i idx = x->id ? _mm512_loadu_si512(x->id + first)
                              : _mm512_add_epi32(_mm512_set1_epi32((int)first),
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

uint32_t splat_mask_rasterize(const mask_ray *x, const mask_held *hb)
{
    return (uint32_t)__builtin_popcount(splat_mask_rasterize_z(x, hb->first, hb->mask, hb->z));
}

/* The low word of lane i's key: its index. */
static inline uint32_t key_lo(const mask_ray *x, uint32_t first, int i)
{
    return x->id ? x->id[first + (uint32_t)i] : first + (uint32_t)i;
}

/* sides: whether to drop the lanes whose plane holds the origin or that
 * hide nothing from its side (else the caller's lanes are such already:
 * collect's) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline uint32_t cells_of_lanes(const mask_ray *x, uint32_t first, uint32_t lanes, const float *zz, lane_cells *L,
                                      const int sides)
{
    const cdl_skd *t = x->t;
    const cdl_photon_ray *r = x->r;
    const float *U = x->U, *V = x->V;
    const int g = x->g;
    /* lanes nearer than the reach */
    uint32_t near = 0;
#if defined(__AVX512F__)
    __m512i zb = _mm512_castps_si512(_mm512_add_ps(_mm512_loadu_ps(zz), _mm512_setzero_ps()));
    near = _mm512_mask_cmplt_epi32_mask((__mmask16)lanes, zb, _mm512_set1_epi32(x->reach));
    _mm512_storeu_si512(L->zk, zb);
#else
    for (int i = 0; i < 16; i++) {
        L->zk[i] = float_bits(zz[i] + 0.0f);
        near |= (uint32_t)((int32_t)L->zk[i] < x->reach) << i;
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
    /* the sides of its plane an origin may lie on for a sample to hide
     * anything (bit 0 in front, bit 1 behind); all without x->side */
    int side[16], kind[16];
    for (int i = 0; sides && i < 16; i++)
        side[i] = x->side ? x->side[first + (uint32_t)i] : 3;
    int(*box)[16] = L->box;
    int *c0 = L->c0, *da = L->da, *db = L->db;
    /* the cells each lane covers, 16 at a time (lanes past m are masked) */
#pragma omp simd
    for (int i = 0; i < 16; i++) {
        float Dx = px[i] - ox, Dy = py[i] - oy, Dz = pz[i] - oz, z = zz[i];
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        /* the surface the ray leaves hides nothing, and in the cells
         * around the ray it would stand in front of what does */
        float so = Dx * nx[i] + Dy * ny[i] + Dz * nz[i];
        /* (so > 0: the origin lies behind the plane) */
        int keep = !sides || ((fabsf(so) > pw[i]) & ((so > 0.0f ? side[i] >> 1 : side[i]) & 1));
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
    L->small = small & near, L->large = large & near;
    return L->small | L->large;
}

#if defined(__AVX512F__)
/* Whether the live lanes' boxes fit a window of 8 x 8 cells: its first
 * column and rows from B0 to B1. */
static inline int window_of(const lane_cells *L, uint32_t live, int *A0, int *B0, int *B1)
{
    /* the live boxes' extremes in one reduction: a lane's a0, b0, 255 - a1
     * and 255 - b1 (all in [0, g)) as its bytes, their minima */
    const __m512i ff = _mm512_set1_epi32(255);
    __m512i pk = _mm512_or_si512(
        _mm512_or_si512(_mm512_loadu_si512(L->box[0]), _mm512_slli_epi32(_mm512_loadu_si512(L->box[2]), 8)),
        _mm512_or_si512(_mm512_slli_epi32(_mm512_sub_epi32(ff, _mm512_loadu_si512(L->box[1])), 16),
                        _mm512_slli_epi32(_mm512_sub_epi32(ff, _mm512_loadu_si512(L->box[3])), 24)));
    pk = _mm512_mask_mov_epi32(_mm512_set1_epi32(-1), (__mmask16)live, pk);
    __m256i h = _mm256_min_epu8(_mm512_castsi512_si256(pk), _mm512_extracti64x4_epi64(pk, 1));
    __m128i q = _mm_min_epu8(_mm256_castsi256_si128(h), _mm256_extracti128_si256(h, 1));
    q = _mm_min_epu8(q, _mm_shuffle_epi32(q, 0x4e));
    q = _mm_min_epu8(q, _mm_shuffle_epi32(q, 0xb1));
    const uint32_t e = (uint32_t)_mm_cvtsi128_si32(q);
    *A0 = (int)(e & 255u), *B0 = (int)(e >> 8 & 255u), *B1 = 255 - (int)(e >> 24);
    return 255 - (int)(e >> 16 & 255u) - *A0 < 8 && *B1 - *B0 < 8;
}

#endif

uint32_t splat_mask_rasterize_z(const mask_ray *x, uint32_t first, uint32_t lanes, const float *zz)
{
    const int g = x->g;
    uint64_t *grid = x->grid;
    lane_cells L;
    const uint32_t live = cells_of_lanes(x, first, lanes, zz, &L, 1);
    if (!live)
        return 0;
    const uint32_t *zk = L.zk;
#if defined(__AVX512F__)
    int A0, B0, B1;
    if (!x->plain && window_of(&L, live, &A0, &B0, &B1)) {
        if (B1 - B0 < 2)
            window8(x, first, live, &L, A0, B0, B1, 2);
        else if (B1 - B0 < 4)
            window8(x, first, live, &L, A0, B0, B1, 4);
        else
            window8(x, first, live, &L, A0, B0, B1, 8);
        return live;
    }
#endif
    for (uint32_t m = L.small; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        uint64_t key = (uint64_t)zk[i] << 32 | key_lo(x, first, i);
        uint64_t *c = grid + L.c0[i];
        cell_min(c, key);
        cell_min(c + L.da[i], key);
        cell_min(c + L.db[i], key);
        cell_min(c + L.db[i] + L.da[i], key);
    }
    for (uint32_t m = L.large; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        uint64_t key = (uint64_t)zk[i] << 32 | key_lo(x, first, i);
        for (int b = L.box[2][i]; b <= L.box[3][i]; b++)
            for (int a = L.box[0][i]; a <= L.box[1][i]; a++)
                cell_min(grid + b * g + a, key);
    }
    return live;
}

static inline void cell_min32(uint32_t *c, uint32_t key) { *c = key < *c ? key : *c; }

#if defined(__AVX512F__)
/* window8 for 32-bit keys: a register holds two rows of the window (8
 * columns each), so RP registers hold 2 RP rows. */
static inline void window16(const mask_ray *x, uint32_t live, const lane_cells *L, const uint32_t *key, int A0, int B0,
                            int B1, const int RP)
{
    __m512i cols, rows;
    window_bits(L, A0, B0, &cols, &rows);
    /* per lane and register its cells: columns of the even row, then of
     * the odd one 8 bits up */
    uint16_t km[4][16];
    for (int j = 0; j < RP; j++) {
        const __mmask16 e = _mm512_test_epi32_mask(rows, _mm512_set1_epi32(1 << 2 * j));
        const __mmask16 o = _mm512_test_epi32_mask(rows, _mm512_set1_epi32(2 << 2 * j));
        const __m512i m = _mm512_or_si512(_mm512_maskz_mov_epi32(e, cols), _mm512_maskz_slli_epi32(o, cols, 8));
        _mm256_storeu_si256((__m256i *)km[j], _mm512_cvtepi32_epi16(m));
    }
    __m512i acc[4], alt[4];
    for (int j = 0; j < RP; j++)
        acc[j] = alt[j] = _mm512_set1_epi32(-1);
    uint32_t m = live;
    for (; m & (m - 1); m &= m - 1) {
        int i = __builtin_ctz(m);
        m &= m - 1;
        int k = __builtin_ctz(m);
        const __m512i a = _mm512_set1_epi32((int)key[i]), b = _mm512_set1_epi32((int)key[k]);
        for (int j = 0; j < RP; j++) {
            acc[j] = _mm512_mask_min_epu32(acc[j], km[j][i], acc[j], a);
            alt[j] = _mm512_mask_min_epu32(alt[j], km[j][k], alt[j], b);
        }
    }
    if (m) {
        int i = __builtin_ctz(m);
        const __m512i a = _mm512_set1_epi32((int)key[i]);
        for (int j = 0; j < RP; j++)
            acc[j] = _mm512_mask_min_epu32(acc[j], km[j][i], acc[j], a);
    }
    const int g = x->g;
    const __mmask8 in = (__mmask8)(g - A0 >= 8 ? 0xffu : (1u << (g - A0)) - 1u);
    for (int j = 0; j < RP; j++) {
        const __m512i v = _mm512_min_epu32(acc[j], alt[j]);
        const int r = B0 + 2 * j;
        if (r <= B1) {
            uint32_t *c = x->grid32 + (ptrdiff_t)r * g + A0;
            _mm256_mask_storeu_epi32(c, in, _mm256_min_epu32(_mm256_maskz_loadu_epi32(in, c), _mm512_castsi512_si256(v)));
        }
        if (r + 1 <= B1) {
            uint32_t *c = x->grid32 + (ptrdiff_t)(r + 1) * g + A0;
            _mm256_mask_storeu_epi32(c, in,
                                     _mm256_min_epu32(_mm256_maskz_loadu_epi32(in, c), _mm512_extracti64x4_epi64(v, 1)));
        }
    }
}
#endif

uint32_t splat_mask_rasterize_planes(const mask_ray *x, uint32_t first, uint32_t lanes, const float *zz,
                                     const uint8_t *pid)
{
    const int g = x->g;
    uint32_t *grid = x->grid32;
    lane_cells L;
    const uint32_t live = cells_of_lanes(x, first, lanes, zz, &L, 0);
    if (!live)
        return 0;
    /* the keys: distance bits over the plane in the low bits */
    uint32_t key[16];
    for (int i = 0; i < 16; i++)
        key[i] = (L.zk[i] & ~(uint32_t)(MASK_PLANES - 1)) | pid[i];
#if defined(__AVX512F__)
    int A0, B0, B1;
    if (!x->plain && window_of(&L, live, &A0, &B0, &B1)) {
        if (B1 - B0 < 2)
            window16(x, live, &L, key, A0, B0, B1, 1);
        else if (B1 - B0 < 4)
            window16(x, live, &L, key, A0, B0, B1, 2);
        else
            window16(x, live, &L, key, A0, B0, B1, 4);
        return live;
    }
#endif
    for (uint32_t m = L.small; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        uint32_t *c = grid + L.c0[i];
        cell_min32(c, key[i]);
        cell_min32(c + L.da[i], key[i]);
        cell_min32(c + L.db[i], key[i]);
        cell_min32(c + L.db[i] + L.da[i], key[i]);
    }
    for (uint32_t m = L.large; m; m &= m - 1) {
        int i = __builtin_ctz(m);
        for (int b = L.box[2][i]; b <= L.box[3][i]; b++)
            for (int a = L.box[0][i]; a <= L.box[1][i]; a++)
                cell_min32(grid + b * g + a, key[i]);
    }
    return live;
}

/* The filter of a ray with planes (see mask_ray): a lane is hidden when
 * its cell's front occluder lies nearer by more than its footprint (the
 * distance taken at the top of the 5 bits the plane replaced) and the
 * lane lies beyond that one's plane by more than its footprint. */
static uint32_t filter_planes(const mask_ray *x, uint32_t first, uint32_t mask)
{
    const cdl_skd *t = x->ft;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = x->fpw + first;
    int cell[16];
    int32_t zb[16];
    cells16(x, first, cell, zb);
#if defined(__AVX512F__)
    const __m512i c = _mm512_loadu_si512(cell), low = _mm512_set1_epi32(MASK_PLANES - 1);
    const __mmask16 in = _mm512_mask_cmpge_epi32_mask((__mmask16)mask, c, _mm512_setzero_si512());
    /* the filled cells from the bits in two registers: no gather where none is */
    const __m512i w = _mm512_permutex2var_epi32(_mm512_loadu_si512(x->occ), _mm512_srli_epi32(c, 5),
                                                _mm512_loadu_si512(x->occ + 16));
    const __mmask16 oc =
        _mm512_mask_test_epi32_mask(in, _mm512_srlv_epi32(w, _mm512_and_si512(c, _mm512_set1_epi32(31))), _mm512_set1_epi32(1));
    if (!oc)
        return mask;
    const __m512i v = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(INT32_MAX), oc, c, (const int *)x->cz, 4);
    const __mmask16 cm = _mm512_mask_cmplt_epi32_mask(oc, _mm512_or_si512(v, low), _mm512_loadu_si512(zb));
    if (!cm)
        return mask;
    const __m512i k = _mm512_and_si512(v, low);
    const float *T = x->tab;
    const __m512 nx = _mm512_permutex2var_ps(_mm512_loadu_ps(T), k, _mm512_loadu_ps(T + 16));
    const __m512 ny = _mm512_permutex2var_ps(_mm512_loadu_ps(T + 32), k, _mm512_loadu_ps(T + 48));
    const __m512 nz = _mm512_permutex2var_ps(_mm512_loadu_ps(T + 64), k, _mm512_loadu_ps(T + 80));
    const __m512 d = _mm512_permutex2var_ps(_mm512_loadu_ps(T + 96), k, _mm512_loadu_ps(T + 112));
    const __m512 sy = _mm512_fmadd_ps(_mm512_loadu_ps(pz), nz,
                                      _mm512_fmadd_ps(_mm512_loadu_ps(py), ny, _mm512_fmsub_ps(_mm512_loadu_ps(px), nx, d)));
    return mask & ~(uint32_t)_mm512_mask_cmp_ps_mask(cm, sy, _mm512_loadu_ps(pw), _CMP_GT_OQ);
#else
    uint32_t keep = mask;
    for (uint32_t m = mask; m; m &= m - 1) {
        int i = __builtin_ctz(m), c = cell[i];
        if (c < 0 || !(x->occ[c >> 5] >> (c & 31) & 1u))
            continue;
        uint32_t v = x->cz[c], k = v & (MASK_PLANES - 1);
        if ((int32_t)(v | (MASK_PLANES - 1)) >= zb[i])
            continue;
        const float *T = x->tab;
        float sy = px[i] * T[k] + py[i] * T[MASK_PLANES + k] + pz[i] * T[2 * MASK_PLANES + k] - T[3 * MASK_PLANES + k];
        if (sy > pw[i])
            keep &= ~(1u << i);
    }
    return keep;
#endif
}

uint32_t splat_mask_filter(const mask_ray *x, uint32_t first, uint32_t mask)
{
    if (x->tab)
        return filter_planes(x, first, mask);
    const cdl_skd *t = x->ft;
    const float ox = x->r->o.x, oy = x->r->o.y, oz = x->r->o.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first, *pw = x->fpw + first;
    int cell[16];
    int32_t zb[16];
    cells16(x, first, cell, zb);
    /* candidates: a front occluder nearer by more than the lane's
     * footprint (so not the lane itself; an empty cell's distance bits are
     * INT32_MAX) */
#if defined(__AVX512F__)
    const __m512i c = _mm512_loadu_si512(cell);
    const __mmask16 in = _mm512_mask_cmpge_epi32_mask((__mmask16)mask, c, _mm512_setzero_si512());
    const __m512i zk = _mm512_mask_i32gather_epi32(_mm512_set1_epi32(INT32_MAX), in, c, (const int *)x->zg, 4);
    const __mmask16 cm = _mm512_mask_cmplt_epi32_mask(in, zk, _mm512_loadu_si512(zb));
    if (!cm)
        return mask;
    const __m512i o = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), cm, c, (const int *)x->ig, 4);
    /* hidden if the sample lies on the far side of the occluder's
     * tangent plane from the ray's origin (by its footprint; the origin
     * lies off that plane by more than the occluder's: it was rasterized) */
    const __m512 zero = _mm512_setzero_ps();
    __m512 nx = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[0], 4);
    __m512 ny = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[1], 4);
    __m512 nz = _mm512_mask_i32gather_ps(zero, cm, o, t->nrm[2], 4);
    __m512 qx = _mm512_mask_i32gather_ps(zero, cm, o, t->p[0], 4);
    __m512 qy = _mm512_mask_i32gather_ps(zero, cm, o, t->p[1], 4);
    __m512 qz = _mm512_mask_i32gather_ps(zero, cm, o, t->p[2], 4);
    __m512 so = _mm512_fmadd_ps(_mm512_sub_ps(_mm512_set1_ps(oz), qz), nz,
                         _mm512_fmadd_ps(_mm512_sub_ps(_mm512_set1_ps(oy), qy), ny,
                                         _mm512_mul_ps(_mm512_sub_ps(_mm512_set1_ps(ox), qx), nx)));
    __m512 sy = _mm512_fmadd_ps(_mm512_sub_ps(_mm512_loadu_ps(pz), qz), nz,
                                _mm512_fmadd_ps(_mm512_sub_ps(_mm512_loadu_ps(py), qy), ny,
                                                _mm512_mul_ps(_mm512_sub_ps(_mm512_loadu_ps(px), qx), nx)));
    __m512 rho = _mm512_loadu_ps(pw);
    __mmask16 hide = cm;
    __mmask16 pos = _mm512_cmp_ps_mask(so, zero, _CMP_GT_OQ);
    hide &= (__mmask16)((pos & _mm512_cmp_ps_mask(sy, _mm512_sub_ps(zero, rho), _CMP_LT_OQ)) |
                        (~pos & _mm512_cmp_ps_mask(sy, rho, _CMP_GT_OQ)));
    return mask & ~(uint32_t)hide;
#else
    uint32_t hit = 0;
    for (int i = 0; i < 16; i++)
        if ((mask >> i & 1u) && cell[i] >= 0)
            hit |= (uint32_t)((int32_t)x->zg[cell[i]] < zb[i]) << i;
    uint32_t keep = mask;
    for (; hit; hit &= hit - 1) {
        uint32_t i = (uint32_t)__builtin_ctz(hit), o = x->ig[cell[i]];
        /* hidden if the sample lies on the far side of the occluder's
         * tangent plane from the ray's origin */
        float rho = pw[i], nx = t->nrm[0][o], ny = t->nrm[1][o], nz = t->nrm[2][o];
        float so = (ox - t->p[0][o]) * nx + (oy - t->p[1][o]) * ny + (oz - t->p[2][o]) * nz;
        float sy = (px[i] - t->p[0][o]) * nx + (py[i] - t->p[1][o]) * ny + (pz[i] - t->p[2][o]) * nz;
        if (so > 0.0f ? sy < -rho : sy > rho)
            keep &= ~(1u << i);
    }
    return keep;
#endif
}
