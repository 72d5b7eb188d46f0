/* splat's radiance maps (Herzog et al. 2007, §6.1): per eye sample, the
 * light its photon splats bring, in one of three forms:
 *   direct     the BSDF applied per splat (exact, the cost grows with the
 *              splats on glossy samples),
 *   histogram  irradiance per icosahedron face of incoming directions (20
 *              strata in world space), the BSDF applied once per stratum at
 *              its centre at the end,
 *   sh         the 16 spherical-harmonics coefficients of L cos in world
 *              space (the basis evaluated once per photon ray), rotated to
 *              the sample's frame at the end and dotted with the material's
 *              BSDF table (eq. 6.3, 6.4).
 * Splatting runs part by part of the eye-sample tree, each part on one
 * thread meeting the rays in their order: the maps do not depend on the
 * thread count. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "integrators/splat/maps.h"
#include "integrators/splat/mask.h"
#include "integrators/splat/occlusion.h"

/* The 20 face centres of an icosahedron. */
static void icosahedron(cdl_vec3 *c)
{
    const float g = 1.6180339887f;
    cdl_vec3 v[12];
    int n = 0;
    for (int s1 = -1; s1 <= 1; s1 += 2)
        for (int s2 = -1; s2 <= 1; s2 += 2) {
            v[n++] = cdl_v3(0.0f, (float)s1, (float)s2 * g);
            v[n++] = cdl_v3((float)s1, (float)s2 * g, 0.0f);
            v[n++] = cdl_v3((float)s2 * g, 0.0f, (float)s1);
        }
    int f = 0;
    for (int i = 0; i < 12; i++)
        for (int j = i + 1; j < 12; j++)
            for (int k = j + 1; k < 12; k++) {
                cdl_vec3 a = cdl_sub(v[i], v[j]), b = cdl_sub(v[j], v[k]), d = cdl_sub(v[i], v[k]);
                if (fabsf(cdl_dot(a, a) - 4.0f) < 1e-3f && fabsf(cdl_dot(b, b) - 4.0f) < 1e-3f &&
                    fabsf(cdl_dot(d, d) - 4.0f) < 1e-3f && f < SPLAT_STRATA)
                    c[f++] = cdl_normalize(cdl_add(cdl_add(v[i], v[j]), v[k]));
            }
}

/* The glossy maps (splat_gmap_at): the histogram is stored as one image
 * per stratum (a ray's splats all go to its stratum: neighbouring samples,
 * neighbouring entries), SH per sample (a splat writes all 16). */
#define gmap_at splat_gmap_at

static int stratum(const splat_state *s, cdl_vec3 w)
{
    int best = 0;
    float bd = -2.0f;
    for (int i = 0; i < SPLAT_STRATA; i++) {
        float d = cdl_dot(w, s->strata[i]);
        if (d > bd) {
            bd = d;
            best = i;
        }
    }
    return best;
}

int splat_maps_init(splat_state *s, cdl_error *err)
{
    s->K = s->opt.splat.mode == CDL_SPLAT_HISTOGRAM ? SPLAT_STRATA : s->opt.splat.mode == CDL_SPLAT_SH ? CDL_SH_N : 1;
    icosahedron(s->strata);
    if (s->opt.splat.mode != CDL_SPLAT_SH)
        return 0;
    if (cdl_sh_rot_init(&s->rot))
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "spherical-harmonics rotation is ill-conditioned");
    const cdl_scene *sc = s->scene;
    s->tables = malloc(sizeof *s->tables * (sc->nmats ? sc->nmats : 1));
    if (!s->tables)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the BSDF tables");
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t m = 0; m < (int64_t)sc->nmats; m++)
        if (!cdl_mat_is_delta(sc->mats[m].type))
            cdl_bsdf_sh_build(&s->tables[m], &sc->mats[m]);
    return 0;
}

int splat_maps_alloc(splat_state *s, cdl_error *err)
{
    size_t n = (size_t)s->nslots + 16;
    if (!s->nsum) {
        for (int c = 0; c < 3; c++)
            s->E[c] = malloc(sizeof(float) * n);
        s->izsum = malloc(sizeof(float) * n);
        s->nsum = malloc(sizeof(float) * n);
        s->gloss = malloc(sizeof(uint32_t) * n);
        s->gbits = malloc(sizeof(uint32_t) * (n / 32 + 3));
        if (!s->E[0] || !s->E[1] || !s->E[2] || !s->izsum || !s->nsum || !s->gloss || !s->gbits)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the radiance maps");
    }
    uint32_t ng = 0;
    for (uint32_t q = 0; q < s->neye; q++)
        s->gloss[q] = s->eye[q].bsdf == SPLAT_LAMBERT ? SPLAT_LAMBERT : ng++;
    for (uint32_t q = s->neye; q < s->neye + 16; q++)
        s->gloss[q] = SPLAT_LAMBERT;
    memset(s->gbits, 0, sizeof(uint32_t) * ((s->neye + 16) / 32 + 3));
    for (uint32_t q = 0; q < s->neye; q++)
        s->gbits[q / 32] |= (uint32_t)(s->gloss[q] != SPLAT_LAMBERT) << (q % 32);
    s->nglossy = ng;
    if (ng > s->gcap || !s->gmap) {
        free(s->gmap);
        free(s->gb);
        s->gcap = ng > s->gcap ? ng + ng / 8 : s->gcap;
        s->gmap = malloc(sizeof(float) * 3 * s->K * (s->gcap ? s->gcap : 1));
        s->gb = malloc(sizeof *s->gb * (s->gcap ? s->gcap : 1));
        if (!s->gmap || !s->gb)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the radiance maps");
    }
    /* the glossy samples' BSDFs in tree order: splats and the resolve
     * read them there */
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->neye; q++)
        if (s->gloss[q] != SPLAT_LAMBERT)
            s->gb[s->gloss[q]] = s->sb[s->eye[q].bsdf];
    if (s->want_bw && !s->bw) {
        s->bw = malloc(sizeof(float) * SPLAT_BW * n);
        if (!s->bw)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the bandwidth picture");
    }
    return 0;
}

size_t splat_maps_bytes(const splat_state *s)
{
    size_t n = s->nsum ? (size_t)s->nslots + 16 : 0;
    return (n ? (n / 32 + 3) * sizeof(uint32_t) : 0) +
           n * (5 * sizeof(float) + sizeof(uint32_t) + (s->bw ? SPLAT_BW * sizeof(float) : 0)) +
           (s->gmap ? (size_t)s->gcap * (s->K * 3 * sizeof(float) + sizeof(cdl_bsdf)) : 0);
}

void splat_terms_of(splat_terms *t, const splat_state *s, const cdl_photon_ray *r)
{
    t->r = r;
    t->wi = cdl_neg(r->d);
    t->ready = 1;
    if (s->opt.splat.mode == CDL_SPLAT_SH) {
        float y[CDL_SH_N];
        cdl_sh_eval(t->wi, y);
        for (int k = 0; k < CDL_SH_N; k++) {
            t->sh[k * 3] = y[k] * r->flux.x;
            t->sh[k * 3 + 1] = y[k] * r->flux.y;
            t->sh[k * 3 + 2] = y[k] * r->flux.z;
        }
    } else if (s->opt.splat.mode == CDL_SPLAT_HISTOGRAM) {
        t->stratum = stratum(s, t->wi);
    }
}

/* Glossy sample q (map entry g) takes weight w of the ray in t. */
static void add_glossy(splat_state *s, splat_terms *t, uint32_t q, uint32_t g, float w)
{
    if (!t->ready)
        splat_terms_of(t, s, t->r);
    const int mode = s->opt.splat.mode;
    const cdl_vec3 flux = t->r->flux;
    if (mode == CDL_SPLAT_SH) {
        float *mp = gmap_at(s, g, 0);
        for (int k = 0; k < CDL_SH_N * 3; k++)
            mp[k] += w * t->sh[k];
    } else if (mode == CDL_SPLAT_HISTOGRAM) {
        float *mp = gmap_at(s, g, t->stratum);
        mp[0] += w * flux.x;
        mp[1] += w * flux.y;
        mp[2] += w * flux.z;
    } else {
        cdl_vec3 f = cdl_bsdf_eval(&s->gb[g], s->eye[q].wo, t->wi, 0);
        float *mp = gmap_at(s, g, 0);
        mp[0] += w * f.x * flux.x;
        mp[1] += w * f.y * flux.y;
        mp[2] += w * f.z * flux.z;
    }
}

void splat_maps_add(splat_state *s, splat_terms *t, uint32_t q, float w, float iz)
{
    const cdl_vec3 flux = t->r->flux;
    s->E[0][q] += w * flux.x;
    s->E[1][q] += w * flux.y;
    s->E[2][q] += w * flux.z;
    s->izsum[q] += iz;
    s->nsum[q] += 1.0f;
    if (s->gloss[q] != SPLAT_LAMBERT)
        add_glossy(s, t, q, s->gloss[q], w);
}

/* The ray being splatted through one part. */
typedef struct ray_ctx {
    splat_state *s;
    splat_terms t;
    uint32_t ray;
    uint64_t splats, occluded, occl_rays, masked;
    int mk;      /* the ray has a visibility mask: 1, set up in mr: 2 */
    mask_ray mr;
} ray_ctx;

#if defined(__AVX512F__)
/* The histogram entries of a whole batch's glossy samples (gall: all of
 * them, glossy: the feasible ones) at once: glossy indices follow tree
 * order, so theirs are gloss[first of them] on, consecutive, and their RGB
 * entries one run of 3 popcount(gall) floats in the stratum's image. The
 * weights are compressed to that run and spread over its channels; the
 * infeasible samples' entries take 0 (w * flux with the scalar loop's
 * rounding: one fused multiply-add per entry). */
static void glossy_run(const splat_state *s, float *mp, uint32_t first, uint32_t gall, uint32_t glossy, const float *w,
                       cdl_vec3 flux)
{
    static const int32_t ix[3][16] = {{0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5},
                                      {5, 5, 6, 6, 6, 7, 7, 7, 8, 8, 8, 9, 9, 9, 10, 10},
                                      {10, 11, 11, 11, 12, 12, 12, 13, 13, 13, 14, 14, 14, 15, 15, 15}};
    const __m512 fr = _mm512_set1_ps(flux.x), fg = _mm512_set1_ps(flux.y), fb = _mm512_set1_ps(flux.z);
    /* lane l of chunk t holds channel (16 t + l) % 3 */
    const __m512 f[3] = {_mm512_mask_mov_ps(_mm512_mask_mov_ps(fr, 0x4924, fb), 0x2492, fg),
                         _mm512_mask_mov_ps(_mm512_mask_mov_ps(fr, 0x2492, fb), 0x9249, fg),
                         _mm512_mask_mov_ps(_mm512_mask_mov_ps(fr, 0x9249, fb), 0x4924, fg)};
    float *m = mp + 3 * (size_t)s->gloss[first + (uint32_t)__builtin_ctz(gall)];
    __m512 wc = _mm512_maskz_compress_ps((__mmask16)gall, _mm512_maskz_loadu_ps((__mmask16)glossy, w));
    uint32_t n = 3 * (uint32_t)__builtin_popcount(gall);
    for (uint32_t t = 0; 16 * t < n; t++) {
        uint32_t rem = n - 16 * t;
        __mmask16 k = (__mmask16)(rem >= 16 ? 0xffffu : (1u << rem) - 1u);
        __m512 v = _mm512_permutexvar_ps(_mm512_loadu_si512(ix[t]), wc);
        _mm512_mask_storeu_ps(m + 16 * t, k, _mm512_fmadd_ps(v, f[t], _mm512_maskz_loadu_ps(k, m + 16 * t)));
    }
}
#endif

/* The feasible glossy samples of a batch (bit i: sample first + i): the
 * ray's light in their maps; gall: all its glossy samples if the batch is
 * whole, else 0. */
static void splat_glossy(ray_ctx *c, uint32_t first, uint32_t glossy, uint32_t gall, const float *w)
{
    splat_state *s = c->s;
    if (s->opt.splat.mode == CDL_SPLAT_HISTOGRAM) { /* add_glossy's, the stratum's image found once */
        if (!c->t.ready)
            splat_terms_of(&c->t, s, c->t.r);
        float *mp = gmap_at(s, 0, c->t.stratum);
        const cdl_vec3 flux = c->t.r->flux;
#if defined(__AVX512F__)
        if (gall && __builtin_popcount(glossy) > 2) {
            glossy_run(s, mp, first, gall, glossy, w, flux);
            return;
        }
#else
        (void)gall;
#endif
        for (; glossy; glossy &= glossy - 1) {
            uint32_t i = (uint32_t)__builtin_ctz(glossy);
            float *m = mp + 3 * (size_t)s->gloss[first + i];
            m[0] += w[i] * flux.x;
            m[1] += w[i] * flux.y;
            m[2] += w[i] * flux.z;
        }
        return;
    }
    if (s->opt.splat.mode == CDL_SPLAT_SH) { /* add_glossy's, inline */
        if (!c->t.ready)
            splat_terms_of(&c->t, s, c->t.r);
        const float *sh = c->t.sh;
        for (; glossy; glossy &= glossy - 1) {
            uint32_t i = (uint32_t)__builtin_ctz(glossy);
            float *m = gmap_at(s, s->gloss[first + i], 0), wi = w[i];
            for (int k = 0; k < CDL_SH_N * 3; k++)
                m[k] += wi * sh[k];
        }
        return;
    }
    for (; glossy; glossy &= glossy - 1) {
        uint32_t i = (uint32_t)__builtin_ctz(glossy), q = first + i;
        add_glossy(c->s, &c->t, q, c->s->gloss[q], w[i]);
    }
}

/* aov bandwidth: the kernel-weighted bandwidth of the rays per sample. */
static void splat_bandwidth(ray_ctx *c, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *iz)
{
    const cdl_photon_ray *r = c->t.r;
    for (uint32_t i = 0; i < m; i++) {
        if (!(mask >> i & 1u))
            continue;
        float *b = &c->s->bw[(size_t)(first + i) * SPLAT_BW];
        float z = iz[i] > 0.0f ? 1.0f / iz[i] : 0.0f;
        float h = r->h0 + r->dh * (z < r->len ? z : r->len);
        int d = r->depth == 2 ? 0 : r->depth == 3 ? 1 : -1;
        if (d >= 0) {
            b[2 * d] += w[i] * h;
            b[2 * d + 1] += w[i];
        }
        b[4] += w[i] * h;
        b[5] += w[i];
    }
}

/* A batch of 16 lanes from the tree (or a ray's kept splats, with the
 * visibility mask): every feasible one gets the ray's irradiance, glossy
 * ones their map entries too. whole: all 16 lanes are this part's (plain
 * loads and stores); else lanes past m, or outside the mask, may be
 * another thread's and are left alone. izsum is the cache's
 * (splat_maps_add): iz is read only by the occlusion test and the
 * bandwidth picture. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void splat_batch(ray_ctx *c, uint32_t first, uint32_t m, int whole, uint32_t mask, const float *w,
                               const float *iz)
{
    splat_state *s = c->s;
    if (s->occl) {
        uint32_t seen = splat_occl_filter(s, c->t.r, first, mask, iz, &c->occl_rays);
        c->occluded += (uint64_t)__builtin_popcount(mask & ~seen);
        if (!(mask = seen))
            return;
    }
    float *er = s->E[0] + first, *eg = s->E[1] + first, *eb = s->E[2] + first;
    float *ns = s->nsum + first;
    /* the splat counts are the filter's only (the cache counts its own) */
    const int count = s->opt.splat.filter > 0.0f;
    uint64_t gb;
    memcpy(&gb, s->gbits + first / 32, sizeof gb);
    const uint32_t glossy = (uint32_t)(gb >> (first % 32)) & mask;
#if defined(__AVX512F__)
    const __mmask16 k = (__mmask16)mask;
    const __m512 wv = _mm512_loadu_ps(w);
    const cdl_vec3 flux = c->t.r->flux;
    if (whole) { /* unfed lanes rewritten unchanged */
        _mm512_storeu_ps(er, _mm512_mask3_fmadd_ps(wv, _mm512_set1_ps(flux.x), _mm512_loadu_ps(er), k));
        _mm512_storeu_ps(eg, _mm512_mask3_fmadd_ps(wv, _mm512_set1_ps(flux.y), _mm512_loadu_ps(eg), k));
        _mm512_storeu_ps(eb, _mm512_mask3_fmadd_ps(wv, _mm512_set1_ps(flux.z), _mm512_loadu_ps(eb), k));
    } else {
        _mm512_mask_storeu_ps(er, k, _mm512_fmadd_ps(wv, _mm512_set1_ps(flux.x), _mm512_maskz_loadu_ps(k, er)));
        _mm512_mask_storeu_ps(eg, k, _mm512_fmadd_ps(wv, _mm512_set1_ps(flux.y), _mm512_maskz_loadu_ps(k, eg)));
        _mm512_mask_storeu_ps(eb, k, _mm512_fmadd_ps(wv, _mm512_set1_ps(flux.z), _mm512_maskz_loadu_ps(k, eb)));
    }
    if (count)
        _mm512_mask_storeu_ps(ns, k, _mm512_add_ps(_mm512_set1_ps(1.0f), _mm512_maskz_loadu_ps(k, ns)));
    c->splats += (uint64_t)__builtin_popcount(mask);
#else
    (void)whole; /* the loop below touches fed lanes only */
    const float fr = c->t.r->flux.x, fg = c->t.r->flux.y, fb = c->t.r->flux.z;
    for (uint32_t i = 0; i < m; i++) {
        if (!(mask >> i & 1u))
            continue;
        er[i] += w[i] * fr;
        eg[i] += w[i] * fg;
        eb[i] += w[i] * fb;
        ns[i] += count ? 1.0f : 0.0f;
        c->splats++;
    }
#endif
    if (glossy)
        splat_glossy(c, first, glossy, whole ? (uint32_t)(gb >> (first % 32)) & 0xffffu : 0, w);
    if (s->want_bw)
        splat_bandwidth(c, first, m, mask, w, iz);
}

/* A leaf range from the tree: its 16-lane blocks with feasible samples,
 * without a call each. */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void range_of(void *ctx, uint32_t first, uint32_t n, const uint16_t *mask, const float *w, const float *iz,
                            const int masks)
{
    ray_ctx *c = ctx;
    for (uint32_t j = 0; j * 16 < n; j++)
        if (mask[j]) {
            uint32_t m = n - 16 * j < 16 ? n - 16 * j : 16, k = mask[j];
            if (masks && c->mk) { /* the visibility mask's filter (set up at the ray's first splat in this part) */
                if (c->mk == 1)
                    c->mk = 1 + splat_mask_ray(c->s, c->ray, &c->mr);
                uint32_t kept = splat_mask_filter(&c->mr, first + 16 * j, k);
                c->masked += (uint64_t)__builtin_popcount(k & ~kept);
                if (!(k = kept))
                    continue;
            }
            splat_batch(c, first + 16 * j, m, m == 16, k, w + 16 * j, iz + 16 * j);
        }
}

static void splat_range(void *ctx, uint32_t first, uint32_t n, const uint16_t *mask, const float *w, const float *iz)
{
    range_of(ctx, first, n, mask, w, iz, 0);
}

/* The same for a ray that may have a visibility mask. */
static void splat_range_mask(void *ctx, uint32_t first, uint32_t n, const uint16_t *mask, const float *w,
                             const float *iz)
{
    range_of(ctx, first, n, mask, w, iz, 1);
}

/* n floats at p zeroed by all threads (tens of MiB, first touched here
 * in a pass's first band). */
static void zero(float *p, size_t n)
{
    const size_t step = (size_t)1 << 16;
#pragma omp parallel for schedule(static) if (n > 4 * step)
    for (size_t i = 0; i < n; i += step)
        memset(p + i, 0, sizeof(float) * (n - i < step ? n - i : step));
}

void splat_maps_clear(splat_state *s)
{
    size_t n = (size_t)s->neye + 16;
    for (int c = 0; c < 3; c++)
        zero(s->E[c], n);
    zero(s->izsum, n);
    zero(s->nsum, n);
    zero(s->gmap, 3 * s->K * (size_t)s->nglossy);
    if (s->want_bw)
        zero(s->bw, SPLAT_BW * n);
}

/* Per ray the parts (up to 64) whose box the box of its frustum's segment
 * meets, a little wider than the traversal's own clip (which rejects the
 * others too, after its set-up): with small kernels most frusta miss most
 * parts, and a part's pass over the rays then reads 8 bytes a ray instead
 * of the ray. NULL: every part (more than 64, or no memory). */
static uint64_t *parts_reached(const splat_state *s)
{
    const uint32_t np = s->tree.nparts;
    uint64_t *reach = np <= 64 ? malloc(sizeof *reach * (s->rays.n ? s->rays.n : 1)) : NULL;
    if (!reach)
        return NULL;
    const float cap = s->opt.splat.cap > 0.0f ? s->opt.splat.cap : 1.0f; /* as splat_ray_of's */
#pragma omp parallel for schedule(static)
    for (uint32_t k = 0; k < s->rays.n; k++) {
        const cdl_photon_ray *r = &s->rays.r[k];
        const float hmax = r->h0 + r->dh * r->len, t1 = r->len + cap * hmax;
        const float o[3] = {r->o.x, r->o.y, r->o.z}, d[3] = {r->d.x, r->d.y, r->d.z};
        float lo[3], hi[3];
        for (int a = 0; a < 3; a++) {
            float e = o[a] + t1 * d[a], g = 1.001f * hmax + 1e-5f * (fabsf(o[a]) + fabsf(e));
            lo[a] = (o[a] < e ? o[a] : e) - g;
            hi[a] = (o[a] > e ? o[a] : e) + g;
        }
        uint64_t m = 0;
        for (uint32_t p = 0; p < np; p++) {
            const cdl_skd_part *pt = &s->tree.parts[p];
            int meet = 1;
            for (int a = 0; a < 3; a++)
                meet &= !(lo[a] > pt->bmax[a]) & !(hi[a] < pt->bmin[a]);
            m |= (uint64_t)meet << p;
        }
        reach[k] = m;
    }
    return reach;
}

/* What the parts' splatting counts. */
typedef struct splat_sums {
    uint64_t splats, tested, nodes, occluded, occl_rays, masked;
} splat_sums;

/* Part `part`'s splats of rays [k0, k1), in their order. */
static void splat_part(splat_state *s, uint32_t part, uint32_t k0, uint32_t k1, const uint64_t *reach, int flags,
                       splat_sums *sum)
{
    cdl_skd_count cnt = {0, 0, 0};
    ray_ctx c;
    c.s = s;
    c.ray = UINT32_MAX;
    c.splats = c.occluded = c.occl_rays = c.masked = 0;
    c.mk = 0;
    const uint64_t bit = part < 64 ? (uint64_t)1 << part : 0;
    for (uint32_t k = k0; k < k1 && !cdl_cancelled(s->cancel); k++) {
        if (reach && !(reach[k] & bit))
            continue;
        const cdl_photon_ray *r = &s->rays.r[k];
        cdl_splat_ray sr = splat_ray_of(s, r);
        c.t.r = r;
        c.t.ready = 0;
        c.ray = k;
        c.mk = s->mask && splat_mask_has(s, k);
        cdl_skd_splat_visit_range(&s->tree, part, &sr, flags, c.mk ? splat_range_mask : splat_range, &c, &cnt);
    }
    sum->splats += c.splats;
    sum->masked += c.masked;
    sum->occluded += c.occluded;
    sum->occl_rays += c.occl_rays;
    sum->tested += cnt.tested;
    sum->nodes += cnt.nodes;
}

/* The visibility masks' rays are built in chunks of this many. */
#define MASK_CHUNK 16u

int splat_maps_splat(splat_state *s)
{
    splat_maps_clear(s);
    const int flags = (s->opt.splat.cull ? CDL_SKD_CULL : 0) | (s->opt.splat.slabs ? CDL_SKD_SLABS : 0) |
                      (s->occl || s->want_bw ? 0 : CDL_SKD_NOIZ);
    const uint32_t n = s->rays.n, np = s->tree.nparts;
    uint64_t *reach = parts_reached(s);
    uint32_t *order = malloc(sizeof *order * (np ? np : 1));
    if (!order || (s->mask && (splat_mask_prepare(s) || splat_mask_begin(s)))) {
        free(order);
        free(reach);
        return CDL_ERR_SYSTEM;
    }
    /* the parts with the most samples first: a part's cost grows with its
     * samples, and the threads then finish together (in tree order the
     * last large part ran alone for 7 % of the Cornell box's splatting);
     * each part sums its splats in ray order, so the image is the same */
    for (uint32_t j = 0; j < np; j++) {
        uint32_t p = j, m = s->tree.parts[p].hi - s->tree.parts[p].lo, i = j;
        for (; i > 0 && s->tree.parts[order[i - 1]].hi - s->tree.parts[order[i - 1]].lo < m; i--)
            order[i] = order[i - 1];
        order[i] = p;
    }
    /* with visibility masks, a batch of rays at a time (their buffers stay
     * in cache): the parts splat one batch while the threads that run out
     * of parts build the next one's buffers (the occluders in each
     * frustum) */
    const uint32_t batch = s->mask ? SPLAT_MASK_BATCH : (n ? n : 1), nb = (n + batch - 1) / batch;
    uint64_t splats = 0, tested = 0, nodes = 0, occluded = 0, occl_rays = 0, masked = 0;
#pragma omp parallel reduction(+ : splats, tested, nodes, occluded, occl_rays, masked)
    {
        splat_sums mine = {0, 0, 0, 0, 0, 0};
        if (s->mask) {
            const uint32_t k1 = n < batch ? n : batch;
#pragma omp for schedule(dynamic, 1)
            for (uint32_t k = 0; k < k1; k += MASK_CHUNK)
                splat_mask_build(s, k, k1 - k < MASK_CHUNK ? k1 : k + MASK_CHUNK);
        }
        for (uint32_t b = 0; b < nb; b++) {
            const uint32_t k0 = b * batch, k1 = n - k0 < batch ? n : k0 + batch;
            const uint32_t k2 = n - k1 < batch ? n : k1 + batch;
            const uint32_t nc = s->mask ? (k2 - k1 + MASK_CHUNK - 1) / MASK_CHUNK : 0;
#pragma omp for schedule(dynamic, 1)
            for (uint32_t j = 0; j < np + nc; j++)
                if (j < np)
                    splat_part(s, order[j], k0, k1, reach, flags, &mine);
                else {
                    const uint32_t lo = k1 + (j - np) * MASK_CHUNK;
                    splat_mask_build(s, lo, k2 - lo < MASK_CHUNK ? k2 : lo + MASK_CHUNK);
                }
            /* (the loop's barrier: this batch's splats are done) */
            if (s->mask)
                splat_mask_recycle(s, k0);
        }
        splats += mine.splats, tested += mine.tested, nodes += mine.nodes;
        occluded += mine.occluded, occl_rays += mine.occl_rays, masked += mine.masked;
    }
    free(order);
    free(reach);
    if (s->mask && splat_mask_end(s))
        return CDL_ERR_SYSTEM;
    s->st.splats += splats;
    s->st.occluded += occluded;
    s->st.masked += masked;
    s->st.occl_rays += occl_rays;
    s->st.tested += tested;
    s->st.nodes += nodes;
    return 0;
}

/* The stratum's centre, moved just above the horizon of n if it lies
 * below: the photons counted there all arrived from above. */
static cdl_vec3 above(cdl_vec3 w, cdl_vec3 n)
{
    float c = cdl_dot(w, n);
    if (c > 0.05f)
        return w;
    return cdl_normalize(cdl_add(w, cdl_scale(n, 0.05f - c)));
}

void splat_maps_resolve(splat_state *s)
{
    const int mode = s->opt.splat.mode;
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->neye; q++) {
        const splat_eye *e = &s->eye[q];
        const uint32_t g = s->gloss[q];
        cdl_vec3 L;
        if (g == SPLAT_LAMBERT) {
            L = cdl_mul(cdl_scale(e->kd, (float)CDL_INV_PI), cdl_v3(s->E[0][q], s->E[1][q], s->E[2][q]));
        } else if (mode == CDL_SPLAT_DIRECT) {
            const float *m = gmap_at(s, g, 0);
            L = cdl_v3(m[0], m[1], m[2]);
        } else if (mode == CDL_SPLAT_HISTOGRAM) {
            L = cdl_v3(0.0f, 0.0f, 0.0f);
            for (int k = 0; k < SPLAT_STRATA; k++) {
                const float *mk = gmap_at(s, g, k);
                cdl_vec3 Ek = cdl_v3(mk[0], mk[1], mk[2]);
                if (cdl_is_black(Ek))
                    continue;
                cdl_vec3 wi = above(s->strata[k], e->f.n);
                L = cdl_add(L, cdl_mul(cdl_bsdf_eval(&s->gb[g], e->wo, wi, 0), Ek));
            }
        } else {
            float loc[CDL_SH_N * 3], c[CDL_SH_N * 3];
            cdl_sh_rotate(&s->rot, e->f, gmap_at(s, g, 0), loc, 3);
            cdl_bsdf_sh_lookup(&s->tables[e->mat], cdl_dot(e->wo, e->f.n), e->kd, c);
            float acc[3] = {0.0f, 0.0f, 0.0f};
            for (int k = 0; k < CDL_SH_N; k++)
                for (int ch = 0; ch < 3; ch++)
                    acc[ch] += c[k * 3 + ch] * loc[k * 3 + ch];
            L = cdl_v3(fmaxf(acc[0], 0.0f), fmaxf(acc[1], 0.0f), fmaxf(acc[2], 0.0f));
        }
        L = cdl_mul(L, e->weight);
        /* pixels take their samples in tree order: one pixel's samples may
         * sit in different parts, so this sum runs after the parallel loop;
         * E holds the sample's radiance until then */
        s->E[0][q] = L.x;
        s->E[1][q] = L.y;
        s->E[2][q] = L.z;
    }
    for (uint32_t q = 0; q < s->neye; q++) {
        uint32_t p = s->eye[q].pixel;
        s->pix[p] = cdl_add(s->pix[p], cdl_v3(s->E[0][q], s->E[1][q], s->E[2][q]));
    }
}
