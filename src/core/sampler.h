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

/* Shuffled index of dimension dim (a function of key, dim and the
 * reversed pass rindex alone): an Owen scramble of the index bits, so
 * every aligned block of 2^k passes stays a (0,k,2)-net. */
static inline uint32_t cdl_sobol_index(uint64_t key, uint32_t rindex, uint32_t dim, uint32_t *s1, uint32_t *s2)
{
    uint64_t h = cdl_mix64(key + (uint64_t)dim * 0x9e3779b97f4a7c15ULL);
    *s1 = (uint32_t)(h >> 32);
    *s2 = ((uint32_t)h ^ 0x9e3779b9u) * 0x85ebca6bu ^ *s1;
    return cdl_reverse_bits(cdl_lk_hash(rindex, (uint32_t)h));
}

/* The two numbers of a request from its shuffled index. */
static inline float cdl_sobol_u(uint32_t i, uint32_t s1)
{
    return cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(i, s1)));
}

static inline float cdl_sobol_v(uint32_t i, uint32_t s2)
{
    return cdl_u32_to_float(cdl_reverse_bits(cdl_lk_hash(cdl_sobol_dim1_reversed(i), s2)));
}

/* Shuffled index for the current dimension. */
static inline uint32_t cdl_sampler_next(cdl_sampler *s, uint32_t *s1, uint32_t *s2)
{
    return cdl_sobol_index(s->key, s->rindex, s->dim++, s1, s2);
}

static inline float cdl_sampler_1d(cdl_sampler *s)
{
    if (s->kind == CDL_SAMPLER_INDEPENDENT)
        return cdl_rng_float(&s->rng);
    uint32_t s1, s2;
    uint32_t i = cdl_sampler_next(s, &s1, &s2);
    return cdl_sobol_u(i, s1);
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
    uint32_t i = cdl_sampler_next(s, &s1, &s2);
    *u = cdl_sobol_u(i, s1);
    *v = cdl_sobol_v(i, s2);
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
} cdl_vertex_numbers;

static inline cdl_vertex_numbers cdl_vertex_numbers_draw(cdl_sampler *s)
{
    cdl_vertex_numbers v;
    v.sobol = s->kind == CDL_SAMPLER_SOBOL;
    v.key = s->key;
    v.rindex = s->rindex;
    v.dim = s->dim;
    if (v.sobol) {
        uint32_t s1, s2, i;
        i = cdl_sobol_index(v.key, v.rindex, v.dim, &s1, &s2);
        v.u[0] = cdl_sobol_u(i, s1);
        i = cdl_sobol_index(v.key, v.rindex, v.dim + 1, &s1, &s2);
        v.u[2] = cdl_sobol_u(i, s1);
        v.u[3] = cdl_sobol_v(i, s2);
        i = cdl_sobol_index(v.key, v.rindex, v.dim + 3, &s1, &s2);
        v.u[5] = cdl_sobol_u(i, s1);
        v.u[6] = cdl_sobol_v(i, s2);
        s->dim += 4;
        return v;
    }
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
    uint32_t s1, s2, i = cdl_sobol_index(v->key, v->rindex, v->dim + (k == 1 ? 0 : 2), &s1, &s2);
    return k == 1 ? cdl_sobol_v(i, s2) : cdl_sobol_u(i, s1);
}

#endif
