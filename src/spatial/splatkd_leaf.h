/* Algorithm 2's leaf test 16 samples at a time for the eye-sample
 * kd-tree's queries (splatkd_query.c), private to them: the ray's numbers
 * broadcast once for a run of tests, the sample arrays, and the test. */
#ifndef CDL_SPATIAL_SPLATKD_LEAF_H
#define CDL_SPATIAL_SPLATKD_LEAF_H

#include "spatial/splatkd.h"

#include <math.h>
#include <string.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif

/* The sample arrays (the tree's, or any laid out alike). */
typedef struct soa16 {
    const float *p[3], *n[3], *two;
} soa16;

static inline soa16 soa16_of(const cdl_skd *t)
{
    return (soa16){{t->p[0], t->p[1], t->p[2]}, {t->nrm[0], t->nrm[1], t->nrm[2]}, t->two};
}

/* The both visit's frustum test, on the way (see cdl_skd_visit_both):
 * lanes inside the frustum up to zmax and their z; culled: the leaf test
 * is not wanted. */
typedef struct any16 {
    float zmax;
    int culled;
    uint32_t mask;
    float *z;
} any16;

/* Algorithm 2's feasibility and weight for up to 16 samples from b:
 * w[i] kernel times cosine (0 where infeasible), zz[i] 1 / z; returns
 * the mask of feasible lanes; with a, the frustum test too. `plane` is a
 * constant in each caller;
 * cdl_splat_weight is the same test one sample at a time. With AVX-512
 * the 16 lanes are one register and the reciprocals rcp14 with a Newton
 * step (relative error ~1e-7); otherwise a branch-free loop that the
 * compiler vectorizes. */
#if defined(__AVX512F__)
static inline __m512 rcp_nr(__m512 x)
{
    __m512 r = _mm512_rcp14_ps(x);
    return _mm512_mul_ps(r, _mm512_fnmadd_ps(x, r, _mm512_set1_ps(2.0f)));
}

/* The ray's numbers broadcast once for a run of leaf tests (a call per
 * batch would reload them: the stores to w may alias the ray). */
typedef struct ray16 {
    __m512 ox, oy, oz, dx, dy, dz, nx, ny, nz, len, h0, dh, zmin, otol, cap, xlen;
    int otol_on;
} ray16;

static inline void ray16_of(ray16 *L, const cdl_splat_ray *r)
{
    L->ox = _mm512_set1_ps(r->o.x), L->oy = _mm512_set1_ps(r->o.y), L->oz = _mm512_set1_ps(r->o.z);
    L->dx = _mm512_set1_ps(r->d.x), L->dy = _mm512_set1_ps(r->d.y), L->dz = _mm512_set1_ps(r->d.z);
    L->nx = _mm512_set1_ps(r->on.x), L->ny = _mm512_set1_ps(r->on.y), L->nz = _mm512_set1_ps(r->on.z);
    L->len = _mm512_set1_ps(r->len), L->h0 = _mm512_set1_ps(r->h0), L->dh = _mm512_set1_ps(r->dh);
    L->zmin = _mm512_set1_ps(r->zmin), L->otol = _mm512_set1_ps(r->otol), L->cap = _mm512_set1_ps(r->cap);
    L->xlen = _mm512_set1_ps(r->len * 1.0001f);
    L->otol_on = r->otol > 0.0f;
}

/* wiz: whether zz is wanted (else left unwritten). */
static inline uint32_t weigh16(const soa16 *t, uint32_t b, uint32_t m, const ray16 *L, int plane, int wiz, float *w,
                               float *zz, any16 *a)
{
    const __m512 zero = _mm512_setzero_ps();
    const __m512 dx = L->dx, dy = L->dy, dz = L->dz;
    __m512 Dx = _mm512_sub_ps(_mm512_loadu_ps(t->p[0] + b), L->ox);
    __m512 Dy = _mm512_sub_ps(_mm512_loadu_ps(t->p[1] + b), L->oy);
    __m512 Dz = _mm512_sub_ps(_mm512_loadu_ps(t->p[2] + b), L->oz);
    __m512 z = _mm512_fmadd_ps(Dz, dz, _mm512_fmadd_ps(Dy, dy, _mm512_mul_ps(Dx, dx)));
    /* |D - z d|^2, not |D|^2 - z^2: thin kernels far along the ray would
     * lose r^2 to cancellation */
    __m512 ex = _mm512_fnmadd_ps(z, dx, Dx), ey = _mm512_fnmadd_ps(z, dy, Dy), ez = _mm512_fnmadd_ps(z, dz, Dz);
    __m512 r2 = _mm512_fmadd_ps(ez, ez, _mm512_fmadd_ps(ey, ey, _mm512_mul_ps(ex, ex))); /* >= 0 */
    __m512 h = _mm512_fmadd_ps(L->dh, _mm512_min_ps(z, L->len), L->h0);
    __m512 h2 = _mm512_mul_ps(h, h);
    __mmask16 ok = (__mmask16)(m >= 16 ? 0xffffu : (1u << m) - 1u);
    /* inside the frustum (h only shrinks beyond the hit) and in front of
     * the origin: most lanes a large range tests fail here, before the
     * normals are loaded */
    ok = _mm512_mask_cmp_ps_mask(ok, z, zero, _CMP_GE_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, r2, h2, _CMP_LT_OQ);
    if (a) {
        a->mask = _mm512_mask_cmp_ps_mask(ok, z, _mm512_set1_ps(a->zmax), _CMP_LE_OQ);
        _mm512_storeu_ps(a->z, z);
        if (a->culled)
            return 0;
    }
    if (!ok)
        return 0;
    __m512 nx = _mm512_loadu_ps(t->n[0] + b), ny = _mm512_loadu_ps(t->n[1] + b), nz = _mm512_loadu_ps(t->n[2] + b);
    __mmask16 two = _mm512_cmp_ps_mask(_mm512_loadu_ps(t->two + b), zero, _CMP_GT_OQ);
    __m512 dn = _mm512_fmadd_ps(dz, nz, _mm512_fmadd_ps(dy, ny, _mm512_mul_ps(dx, nx)));
    /* c = -|dn| for a two-sided sample (its normal turned to face the
     * ray), else dn */
    const __m512 sign = _mm512_set1_ps(-0.0f);
    __m512 c = _mm512_mask_or_ps(dn, two, dn, sign);
    __m512 zn = _mm512_fmadd_ps(Dz, L->nz, _mm512_fmadd_ps(Dy, L->ny, _mm512_mul_ps(Dx, L->nx)));
    ok = _mm512_mask_cmp_ps_mask(ok, c, zero, _CMP_LT_OQ);
    ok = _mm512_mask_cmp_ps_mask(ok, zn, zero, _CMP_GE_OQ);
    /* not the other side of the origin's sheet (see cdl_splat_ray.zmin):
     * only samples close to the origin's plane need their normal's */
    __mmask16 low = _mm512_mask_cmp_ps_mask(ok, zn, L->zmin, _CMP_LT_OQ);
    if (low) {
        __m512 non = _mm512_fmadd_ps(nz, L->nz, _mm512_fmadd_ps(ny, L->ny, _mm512_mul_ps(nx, L->nx)));
        ok &= (__mmask16)(~low | _mm512_cmp_ps_mask(non, _mm512_set1_ps(CDL_SKD_SHEET_COS), _CMP_GE_OQ));
    }
    __m512 dpn = _mm512_fmadd_ps(Dz, nz, _mm512_fmadd_ps(Dy, ny, _mm512_mul_ps(Dx, nx)));
    if (L->otol_on) /* the origin in front of a one-sided sample's plane (cdl_splat_ray.otol) */
        ok &= (__mmask16)(_mm512_cmp_ps_mask(dpn, L->otol, _CMP_LE_OQ) | two);
    __m512 beyond = _mm512_sub_ps(z, L->len);
    if (plane) {
        /* reached the sample's tangent plane ((D . n) / dn <= X, without
         * the division: with the normal turned as c's, dn < 0 and the
         * test flips), or ended within h of the sample (a neighbouring
         * surface of a concave corner); r^2 < h^2 holds from above */
        __m512 X = _mm512_fmadd_ps(_mm512_set1_ps(1e-3f), h, L->xlen);
        __m512 dpc = _mm512_mask_xor_ps(dpn, two, dpn, _mm512_andnot_ps(dn, sign));
        __mmask16 reached = _mm512_cmp_ps_mask(dpc, _mm512_mul_ps(X, c), _CMP_GE_OQ);
        __mmask16 sphere = _mm512_cmp_ps_mask(_mm512_fmadd_ps(beyond, beyond, r2), h2, _CMP_LT_OQ);
        __mmask16 within = _mm512_cmp_ps_mask(beyond, _mm512_mul_ps(L->cap, h), _CMP_LE_OQ);
        __mmask16 before = _mm512_cmp_ps_mask(beyond, zero, _CMP_LE_OQ);
        ok &= (__mmask16)(before | (within & (reached | sphere)));
    } else {
        __m512 bp = _mm512_max_ps(beyond, zero);
        h2 = _mm512_fnmadd_ps(bp, bp, h2);
        ok = _mm512_mask_cmp_ps_mask(ok, h2, zero, _CMP_GT_OQ);
        ok = _mm512_mask_cmp_ps_mask(ok, r2, h2, _CMP_LT_OQ);
    }
    if (!ok)
        return 0;
    __m512 ih2 = rcp_nr(h2);
    /* 1 - r^2 / h^2 >= 0 also where the reciprocal rounds */
    __m512 k = _mm512_mul_ps(_mm512_max_ps(_mm512_fnmadd_ps(r2, ih2, _mm512_set1_ps(1.0f)), zero), ih2);
    /* k (2 / pi) (-c) */
    _mm512_storeu_ps(w, _mm512_maskz_fnmadd_ps(ok, _mm512_mul_ps(k, _mm512_set1_ps((float)(2.0 / CDL_PI))), c, zero));
    if (wiz) {
        __mmask16 zpos = _mm512_mask_cmp_ps_mask(ok, z, zero, _CMP_GT_OQ);
        _mm512_storeu_ps(zz, _mm512_maskz_mov_ps(zpos, rcp_nr(_mm512_mask_mov_ps(_mm512_set1_ps(1.0f), zpos, z))));
    }
    return ok;
}
#else
typedef struct ray16 {
    cdl_splat_ray r;
} ray16;

static inline void ray16_of(ray16 *L, const cdl_splat_ray *r) { L->r = *r; }

static inline uint32_t weigh16(const soa16 *t, uint32_t b, uint32_t m, const ray16 *L, int plane, int wiz, float *w,
                               float *zz, any16 *a)
{
    const cdl_splat_ray *r = &L->r;
    const float ox = r->o.x, oy = r->o.y, oz = r->o.z, dx = r->d.x, dy = r->d.y, dz = r->d.z;
    const float nx0 = r->on.x, ny0 = r->on.y, nz0 = r->on.z, len = r->len, h0 = r->h0, dh = r->dh, cap = r->cap;
    const float zmin = r->zmin, otol = r->otol > 0.0f ? r->otol : INFINITY;
    const float norm = (float)(2.0 / CDL_PI);
    const float *px = t->p[0] + b, *py = t->p[1] + b, *pz = t->p[2] + b;
    const float *nx = t->n[0] + b, *ny = t->n[1] + b, *nz = t->n[2] + b;
    const float *two = t->two + b;
    const float zmax = a ? a->zmax : 0.0f;
    float zo[16];
    int in[16];
#pragma omp simd
    for (uint32_t i = 0; i < 16; i++) { /* all 16 lanes (the arrays have room): a fixed trip count */
        float Dx = px[i] - ox, Dy = py[i] - oy, Dz = pz[i] - oz;
        float dn = dx * nx[i] + dy * ny[i] + dz * nz[i];
        float c = dn - two[i] * (dn + fabsf(dn)); /* -|dn| for a two-sided sample */
        float z = Dx * dx + Dy * dy + Dz * dz;
        float zn = Dx * nx0 + Dy * ny0 + Dz * nz0;
        /* |D - z d|^2, not |D|^2 - z^2: thin kernels far along the ray
         * would lose r^2 to cancellation */
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        float r2 = ex * ex + ey * ey + ez * ez;
        float h = h0 + dh * (z < len ? z : len);
        float h2 = h * h, beyond = z - len;
        in[i] = (z >= 0.0f) & (z <= zmax) & (r2 < h2) & (i < m);
        zo[i] = z;
        float non = nx[i] * nx0 + ny[i] * ny0 + nz[i] * nz0;
        /* not the other side of the origin's sheet (see cdl_splat_ray.zmin) */
        int ok = (c < 0.0f) & (z >= 0.0f) & (zn >= 0.0f) & ((zn >= zmin) | (non >= CDL_SKD_SHEET_COS));
        float dpn = Dx * nx[i] + Dy * ny[i] + Dz * nz[i];
        ok &= (dpn <= otol) | (two[i] > 0.0f); /* cdl_splat_ray.otol */
        if (plane) {
            /* the distance tp = (D . n) / dn to the sample's tangent plane
             * against X, without the division: dn < 0 flips the test */
            float X = len * 1.0001f + 1e-3f * h;
            int reached = ((dn < 0.0f) & (dpn >= X * dn)) | ((dn >= 0.0f) & (dpn <= X * dn));
            /* reached the sample's tangent plane, or ended within h of the
             * sample (a neighbouring surface of a concave corner) */
            ok &= (beyond <= 0.0f) | ((beyond <= cap * h) & (reached | (r2 + beyond * beyond < h2)));
        } else {
            h2 -= beyond > 0.0f ? beyond * beyond : 0.0f;
        }
        ok &= (h2 > 0.0f) & (r2 < h2) & (i < m);
        float rr = r2 > 0.0f ? r2 : 0.0f;
        float wi = norm * (h2 - rr) * -c / (h2 * h2);
        w[i] = ok ? wi : 0.0f;
        if (wiz)
            zz[i] = z > 0.0f ? 1.0f / z : 0.0f;
    }
    if (a) {
        a->mask = 0;
        for (uint32_t i = 0; i < 16; i++)
            a->mask |= (uint32_t)in[i] << i;
        memcpy(a->z, zo, sizeof zo);
        if (a->culled)
            return 0;
    }
    uint32_t mask = 0;
    for (uint32_t i = 0; i < 16; i++)
        mask |= (uint32_t)(w[i] > 0.0f) << i;
    return mask;
}
#endif

#endif
