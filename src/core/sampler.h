/* Padded, Owen-scrambled Sobol sampler (Burley 2020, "Practical hash-based
 * Owen scrambling"). Each 1D or 2D request uses the first two dimensions of
 * the Sobol sequence (a (0,2)-sequence), with the sample index shuffled and
 * the points scrambled by hashes of (seed, pixel, dimension). Every pair
 * of dimensions is then stratified over passes like a (0,2)-sequence at
 * every power of two, and progressive rendering keeps that property: the
 * sample index is the pass number. */
#ifndef CDL_SAMPLER_H
#define CDL_SAMPLER_H

#include <stdint.h>

#include "core/rng.h"

typedef enum cdl_sampler_kind { CDL_SAMPLER_SOBOL, CDL_SAMPLER_INDEPENDENT } cdl_sampler_kind;

typedef struct cdl_sampler {
    uint64_t key;   /* hash of (seed, pixel or path) */
    uint32_t index; /* sample (pass) number */
    uint32_t rindex; /* index with its bits reversed (every draw scrambles it) */
    uint32_t dim;
    uint32_t cheap; /* draws of cdl_sampler_cheap so far */
    cdl_sampler_kind kind;
    cdl_rng rng;    /* CDL_SAMPLER_INDEPENDENT: plain PCG32 stream */
} cdl_sampler;

#if defined(__GFNI__) && defined(__SSE2__)
#include <immintrin.h>
#endif

static inline uint32_t cdl_reverse_bits(uint32_t x)
{
#if defined(__GFNI__) && defined(__SSE2__)
    /* GF(2) affine transform with the anti-diagonal matrix reverses the bits
     * of each byte; a byte swap finishes the job (3 instructions) */
    __m128i v = _mm_cvtsi32_si128((int)x);
    v = _mm_gf2p8affine_epi64_epi8(v, _mm_set1_epi64x((long long)0x8040201008040201ULL), 0);
    return __builtin_bswap32((uint32_t)_mm_cvtsi128_si32(v));
#else
    x = (x << 16) | (x >> 16);
    x = ((x & 0x00ff00ffu) << 8) | ((x & 0xff00ff00u) >> 8);
    x = ((x & 0x0f0f0f0fu) << 4) | ((x & 0xf0f0f0f0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xccccccccu) >> 2);
    x = ((x & 0x55555555u) << 1) | ((x & 0xaaaaaaaau) >> 1);
    return x;
#endif
}

/* Laine-Karras hash: output bit j depends only on input bits <= j. On a
 * bit-reversed value that is an Owen scramble (each digit permuted
 * depending on the digits above it). */
static inline uint32_t cdl_lk_hash(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

/* Sobol dimension 1 in reversed bit order (dimension 0 reversed is the
 * index itself). Its generator matrix is Pascal's triangle mod 2, i.e.
 * the polynomial map p(t) -> p(t + 1), done in five butterfly steps since
 * (t + 1)^(2^k) = t^(2^k) + 1 (mod 2). */
static inline uint32_t cdl_sobol_dim1_reversed(uint32_t i)
{
    i ^= (i & 0xaaaaaaaau) >> 1;
    i ^= (i & 0xccccccccu) >> 2;
    i ^= (i & 0xf0f0f0f0u) >> 4;
    i ^= (i & 0xff00ff00u) >> 8;
    i ^= (i & 0xffff0000u) >> 16;
    return i;
}

static inline float cdl_u32_to_float(uint32_t x)
{
    return (float)(x >> 8) * 0x1p-24f;
}

/* stream identifies the pixel (or light path); index is the pass. */
static inline void cdl_sampler_start(cdl_sampler *s, cdl_sampler_kind kind, uint64_t seed,
                                     uint64_t stream, uint32_t index)
{
    s->kind = kind;
    s->key = cdl_mix64(seed * 0x9e3779b97f4a7c15ULL ^ cdl_mix64(stream));
    s->index = index;
    s->rindex = cdl_reverse_bits(index);
    s->dim = 0;
    s->cheap = 0;
    s->rng.state = s->rng.inc = 0;
    if (kind == CDL_SAMPLER_INDEPENDENT)
        cdl_rng_seed(&s->rng, seed, cdl_mix64(stream) ^ ((uint64_t)index << 40) ^ index);
}

/* Dimension dim's scramble of the reversed pass rindex (a function of
 * key, dim and rindex alone) and its seeds: reversed, the hash is the
 * request's shuffled index, an Owen scramble of the index bits, so every
 * aligned block of 2^k passes stays a (0,k,2)-net. */
static inline uint32_t cdl_sobol_hash(uint64_t key, uint32_t rindex, uint32_t dim, uint32_t *s1, uint32_t *s2)
{
    uint64_t h = cdl_mix64(key + (uint64_t)dim * 0x9e3779b97f4a7c15ULL);
    *s1 = (uint32_t)(h >> 32);
    *s2 = ((uint32_t)h ^ 0x9e3779b9u) * 0x85ebca6bu ^ *s1;
    return cdl_lk_hash(rindex, (uint32_t)h);
}

/* The request's first number from its hash x. */
static inline float cdl_sobol_u(uint32_t x, uint32_t s1)
{
    return cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(cdl_reverse_bits(x), s1)));
}

/* Both numbers of a 2D request from its hash x. */
static inline void cdl_sobol_uv(uint32_t x, uint32_t s1, uint32_t s2, float *u, float *v)
{
#if defined(__GFNI__) && defined(__SSE4_1__)
    /* Same bits, fewer instructions: the index reversal and the first
     * three (in-byte) butterfly steps of dimension 1 are one GF(2) affine
     * map per byte each (matrix 0xff5533110f050301 = steps o reversal);
     * the byte swap commutes with them. Both numbers' last reversal and
     * conversion share one register. */
    const __m128i swap = _mm_set_epi8(12, 13, 14, 15, 8, 9, 10, 11, 4, 5, 6, 7, 0, 1, 2, 3);
    const __m128i rev = _mm_set1_epi64x((long long)0x8040201008040201ULL);
    __m128i t = _mm_cvtsi32_si128((int)x);
    uint32_t i = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi8(_mm_gf2p8affine_epi64_epi8(t, rev, 0), swap));
    __m128i j = _mm_shuffle_epi8(
        _mm_gf2p8affine_epi64_epi8(t, _mm_set1_epi64x((long long)0xff5533110f050301ULL), 0), swap);
    j = _mm_xor_si128(j, _mm_and_si128(_mm_srli_epi32(j, 8), _mm_set1_epi32(0x00ff00ff)));
    j = _mm_xor_si128(j, _mm_srli_epi32(j, 16));
    uint32_t hu = cdl_lk_hash(i, s1), hv = cdl_lk_hash((uint32_t)_mm_cvtsi128_si32(j), s2);
    __m128i w = _mm_insert_epi32(_mm_cvtsi32_si128((int)hu), (int)hv, 1);
    w = _mm_shuffle_epi8(_mm_gf2p8affine_epi64_epi8(w, rev, 0), swap);
    __m128 f = _mm_mul_ps(_mm_cvtepi32_ps(_mm_srli_epi32(w, 8)), _mm_set1_ps(0x1p-24f));
    *u = _mm_cvtss_f32(f);
    *v = _mm_cvtss_f32(_mm_movehdup_ps(f));
#else
    uint32_t i = cdl_reverse_bits(x);
    *u = cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(i, s1)));
    *v = cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(cdl_sobol_dim1_reversed(i), s2)));
#endif
}

/* The second number alone. */
static inline float cdl_sobol_v(uint32_t x, uint32_t s2)
{
    return cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(cdl_sobol_dim1_reversed(cdl_reverse_bits(x)), s2)));
}

/* The current dimension's hash. */
static inline uint32_t cdl_sampler_next(cdl_sampler *s, uint32_t *s1, uint32_t *s2)
{
    return cdl_sobol_hash(s->key, s->rindex, s->dim++, s1, s2);
}

static inline float cdl_sampler_1d(cdl_sampler *s)
{
    if (s->kind == CDL_SAMPLER_INDEPENDENT)
        return cdl_rng_float(&s->rng);
    uint32_t s1, s2;
    uint32_t x = cdl_sampler_next(s, &s1, &s2);
    return cdl_sobol_u(x, s1);
}

/* A decision that gains nothing from stratification (Russian roulette):
 * a plain hash of the state, consuming no dimension. */
static inline float cdl_sampler_cheap(cdl_sampler *s)
{
    if (s->kind == CDL_SAMPLER_INDEPENDENT)
        return cdl_rng_float(&s->rng);
    /* key stays fixed per pixel (the scrambles must not change between
     * passes); the pass index makes each pass's decision independent. */
    uint64_t h = cdl_mix64(s->key ^ ((uint64_t)s->index << 32) ^ (0xc2b2ae35u + s->cheap++));
    return cdl_u32_to_float((uint32_t)h);
}

static inline void cdl_sampler_2d(cdl_sampler *s, float *u, float *v)
{
    if (s->kind == CDL_SAMPLER_INDEPENDENT) {
        *u = cdl_rng_float(&s->rng);
        *v = cdl_rng_float(&s->rng);
        return;
    }
    uint32_t s1, s2;
    uint32_t x = cdl_sampler_next(s, &s1, &s2);
    cdl_sobol_uv(x, s1, s2, u, v);
}

/* A path vertex's numbers, requested as 2D, 2D, 1D, 2D (light choice,
 * point on the light, lobe, direction) and read as u[0..6]. The Sobol
 * sampler's depend on their dimension alone, so two are left to be
 * computed if read (cdl_vertex_number_late): a Lambertian vertex never
 * reads its lobe's (u[4]), nor a choice among lights of equal power its
 * second (u[1]). The independent sampler's stream keeps its order: all
 * drawn here. */
typedef struct cdl_vertex_numbers {
    float u[7];
    int sobol;
    uint64_t key; /* copies: no store the compiler cannot see through changes them */
    uint32_t rindex, dim;
    uint32_t x0, s2; /* u[1]'s hash and seed (the light choice's dimension) */
} cdl_vertex_numbers;

/* always inline: path draws it at every vertex, and a call cost it 5 % */
__attribute__((always_inline)) static inline cdl_vertex_numbers cdl_vertex_numbers_draw(cdl_sampler *s)
{
    cdl_vertex_numbers v;
    v.sobol = s->kind == CDL_SAMPLER_SOBOL;
    v.key = s->key;
    v.rindex = s->rindex;
    v.dim = s->dim;
    if (v.sobol) {
        uint32_t s1, s2, x;
        v.x0 = cdl_sobol_hash(v.key, v.rindex, v.dim, &s1, &v.s2);
        v.u[0] = cdl_sobol_u(v.x0, s1);
        x = cdl_sobol_hash(v.key, v.rindex, v.dim + 1, &s1, &s2);
        cdl_sobol_uv(x, s1, s2, &v.u[2], &v.u[3]);
        x = cdl_sobol_hash(v.key, v.rindex, v.dim + 3, &s1, &s2);
        cdl_sobol_uv(x, s1, s2, &v.u[5], &v.u[6]);
        v.u[1] = v.u[4] = 0.0f; /* never read: cdl_vertex_number_late */
        s->dim += 4;
        return v;
    }
    v.x0 = v.s2 = 0;
    cdl_sampler_2d(s, &v.u[0], &v.u[1]);
    cdl_sampler_2d(s, &v.u[2], &v.u[3]);
    v.u[4] = cdl_sampler_1d(s);
    cdl_sampler_2d(s, &v.u[5], &v.u[6]);
    return v;
}

/* u[1] or u[4] (k), the bits cdl_sampler_2d, cdl_sampler_1d gave them. */
static inline float cdl_vertex_number_late(const cdl_vertex_numbers *v, int k)
{
    if (!v->sobol)
        return v->u[k];
    if (k == 1)
        return cdl_sobol_v(v->x0, v->s2);
    uint32_t s1, s2, x = cdl_sobol_hash(v->key, v->rindex, v->dim + 2, &s1, &s2);
    return cdl_sobol_u(x, s1);
}

#endif
