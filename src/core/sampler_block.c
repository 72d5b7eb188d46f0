#include "core/sampler_block.h"

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512BW__) && defined(__GFNI__)
#include <immintrin.h>
#define CDL_BLOCK_VECTOR 1

/* cdl_mix64 of 8 lanes */
static inline __m512i mix64x8(__m512i z)
{
    z = _mm512_add_epi64(z, _mm512_set1_epi64((long long)0x9e3779b97f4a7c15ULL));
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 30)),
                           _mm512_set1_epi64((long long)0xbf58476d1ce4e5b9ULL));
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 27)),
                           _mm512_set1_epi64((long long)0x94d049bb133111ebULL));
    return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}

/* The 16 lanes' low and high halves of two vectors of 8 64-bit lanes. */
static inline void halves(__m512i a, __m512i b, __m512i *lo, __m512i *hi)
{
    const __m512i even = _mm512_set_epi32(30, 28, 26, 24, 22, 20, 18, 16, 14, 12, 10, 8, 6, 4, 2, 0);
    const __m512i odd = _mm512_set_epi32(31, 29, 27, 25, 23, 21, 19, 17, 15, 13, 11, 9, 7, 5, 3, 1);
    *lo = _mm512_permutex2var_epi32(a, even, b);
    *hi = _mm512_permutex2var_epi32(a, odd, b);
}

static inline __m512i lk16(__m512i x, __m512i seed)
{
    x = _mm512_add_epi32(x, seed);
    x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32((int)0x6c50b47cu)));
    x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32((int)0xb82f1e52u)));
    x = _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32((int)0xc7afe638u)));
    return _mm512_xor_si512(x, _mm512_mullo_epi32(x, _mm512_set1_epi32((int)0x8d22f6e6u)));
}

static inline __m512i rev16(__m512i x)
{
    const __m512i swap = _mm512_set4_epi32(0x0c0d0e0f, 0x08090a0b, 0x04050607, 0x00010203);
    x = _mm512_gf2p8affine_epi64_epi8(x, _mm512_set1_epi64((long long)0x8040201008040201ULL), 0);
    return _mm512_shuffle_epi8(x, swap);
}

static inline __m512i dim1_rev16(__m512i i)
{
    i = _mm512_xor_si512(i, _mm512_srli_epi32(_mm512_and_si512(i, _mm512_set1_epi32((int)0xaaaaaaaau)), 1));
    i = _mm512_xor_si512(i, _mm512_srli_epi32(_mm512_and_si512(i, _mm512_set1_epi32((int)0xccccccccu)), 2));
    i = _mm512_xor_si512(i, _mm512_srli_epi32(_mm512_and_si512(i, _mm512_set1_epi32((int)0xf0f0f0f0u)), 4));
    i = _mm512_xor_si512(i, _mm512_srli_epi32(_mm512_and_si512(i, _mm512_set1_epi32((int)0xff00ff00u)), 8));
    return _mm512_xor_si512(i, _mm512_srli_epi32(i, 16));
}

static inline __m512 to_float16(__m512i x)
{
    return _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_srli_epi32(x, 8)), _mm512_set1_ps(0x1p-24f));
}

/* cdl_sobol_hash of dimension dim in 16 lanes of keys (two vectors of 8). */
static inline __m512i sobol_hash16(__m512i key_lo, __m512i key_hi, uint32_t rindex, uint32_t dim, __m512i *s1,
                                   __m512i *s2)
{
    __m512i add = _mm512_set1_epi64((long long)((uint64_t)dim * 0x9e3779b97f4a7c15ULL));
    __m512i h32, s;
    halves(mix64x8(_mm512_add_epi64(key_lo, add)), mix64x8(_mm512_add_epi64(key_hi, add)), &h32, s1);
    s = _mm512_mullo_epi32(_mm512_xor_si512(h32, _mm512_set1_epi32((int)0x9e3779b9u)),
                           _mm512_set1_epi32((int)0x85ebca6bu));
    *s2 = _mm512_xor_si512(s, *s1);
    return lk16(_mm512_set1_epi32((int)rindex), h32);
}

static inline __m512 sobol_u16(__m512i x, __m512i s1) { return to_float16(rev16(lk16(rev16(x), s1))); }

static inline void sobol_uv16(__m512i x, __m512i s1, __m512i s2, __m512 *u, __m512 *v)
{
    __m512i i = rev16(x);
    *u = to_float16(rev16(lk16(i, s1)));
    *v = to_float16(rev16(lk16(dim1_rev16(i), s2)));
}
#endif

void cdl_sampler_block_start(cdl_sampler *smp, int n, cdl_sampler_kind kind, uint64_t seed, const uint64_t *stream,
                             uint32_t index, float *jx, float *jy, cdl_numbers_ahead *ahead, int nv)
{
    nv = nv < 0 ? 0 : nv > CDL_AHEAD_MAX ? CDL_AHEAD_MAX : nv;
    ahead->nv = kind == CDL_SAMPLER_SOBOL ? nv : 0;
#ifdef CDL_BLOCK_VECTOR
    if (kind == CDL_SAMPLER_SOBOL && n > 0 && n <= CDL_SAMPLER_BLOCK) {
        uint64_t st[CDL_SAMPLER_BLOCK];
        for (int i = 0; i < CDL_SAMPLER_BLOCK; i++)
            st[i] = stream[i < n ? i : 0];
        __m512i sd = _mm512_set1_epi64((long long)(seed * 0x9e3779b97f4a7c15ULL));
        __m512i klo = mix64x8(_mm512_xor_si512(sd, mix64x8(_mm512_loadu_si512(st))));
        __m512i khi = mix64x8(_mm512_xor_si512(sd, mix64x8(_mm512_loadu_si512(st + 8))));
        uint64_t key[CDL_SAMPLER_BLOCK];
        _mm512_storeu_si512(key, klo);
        _mm512_storeu_si512(key + 8, khi);
        uint32_t rindex = cdl_reverse_bits(index);
        __m512i s1, s2, x;
        __m512 u, v;
        float fu[CDL_SAMPLER_BLOCK], fv[CDL_SAMPLER_BLOCK];
        x = sobol_hash16(klo, khi, rindex, 0, &s1, &s2);
        sobol_uv16(x, s1, s2, &u, &v);
        _mm512_storeu_ps(fu, u);
        _mm512_storeu_ps(fv, v);
        for (int i = 0; i < n; i++) {
            cdl_sampler *s = &smp[i];
            s->kind = kind;
            s->key = key[i];
            s->index = index;
            s->rindex = rindex;
            s->dim = 1;
            s->cheap = 0;
            s->rng.state = s->rng.inc = 0;
            jx[i] = fu[i];
            jy[i] = fv[i];
        }
        /* cdl_vertex_numbers_draw at dimension d = 1 + 4 j: requests d
         * (u0, late u1), d + 1 (u2, u3), d + 2 (late u4), d + 3 (u5, u6) */
        for (int j = 0; j < nv; j++) {
            uint32_t d = 1 + 4 * (uint32_t)j;
            x = sobol_hash16(klo, khi, rindex, d, &s1, &s2);
            _mm512_storeu_si512(ahead->x0[j], x);
            _mm512_storeu_si512(ahead->s2[j], s2);
            _mm512_storeu_ps(ahead->u0[j], sobol_u16(x, s1));
            x = sobol_hash16(klo, khi, rindex, d + 1, &s1, &s2);
            sobol_uv16(x, s1, s2, &u, &v);
            _mm512_storeu_ps(ahead->u2[j], u);
            _mm512_storeu_ps(ahead->u3[j], v);
            x = sobol_hash16(klo, khi, rindex, d + 3, &s1, &s2);
            sobol_uv16(x, s1, s2, &u, &v);
            _mm512_storeu_ps(ahead->u5[j], u);
            _mm512_storeu_ps(ahead->u6[j], v);
        }
        return;
    }
#endif
    for (int i = 0; i < n; i++) {
        cdl_sampler_start(&smp[i], kind, seed, stream[i], index);
        cdl_sampler_2d(&smp[i], &jx[i], &jy[i]);
        if (kind != CDL_SAMPLER_SOBOL)
            continue;
        /* drawn on a copy: the sampler advances when they are taken */
        cdl_sampler c = smp[i];
        for (int j = 0; j < nv; j++) {
            cdl_vertex_numbers w = cdl_vertex_numbers_draw(&c);
            ahead->x0[j][i] = w.x0;
            ahead->s2[j][i] = w.s2;
            ahead->u0[j][i] = w.u[0];
            ahead->u2[j][i] = w.u[2];
            ahead->u3[j][i] = w.u[3];
            ahead->u5[j][i] = w.u[5];
            ahead->u6[j][i] = w.u[6];
        }
    }
}
