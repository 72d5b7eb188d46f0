/* The Owen-scrambled Sobol sampler (core/sampler.h): what progressive
 * rendering relies on.
 *  - every 2D request over passes 0 .. 2^m - 1 of a pixel is a (0, m, 2)-net:
 *    each of the 2^m elementary boxes of every shape 2^-a x 2^-(m-a) holds
 *    exactly one point, and so does every aligned block of passes after it;
 *  - a 1D request is stratified the same way (one point per 1 / 2^m);
 *  - requests of one pixel, and the same request of neighbouring pixels,
 *    are uncorrelated (the scrambles are independent hashes);
 *  - a fixed seed gives the same numbers; another seed other ones;
 *  - the independent sampler is uniform (mean, variance);
 *  - a block's samplers started together (core/sampler_block.h, vector
 *    lanes) give the bits of the one-at-a-time calls. */
#include <math.h>
#include <string.h>

#include "core/sampler.h"
#include "core/sampler_block.h"
#include "test_util.h"

/* Draws request `dim` (all earlier requests 2D) of pixel `px` at `pass`. */
static void draw(uint64_t seed, uint64_t px, uint32_t pass, uint32_t dim, float *u, float *v)
{
    cdl_sampler s;
    cdl_sampler_start(&s, CDL_SAMPLER_SOBOL, seed, px, pass);
    float a, b;
    for (uint32_t d = 0; d < dim; d++)
        cdl_sampler_2d(&s, &a, &b);
    cdl_sampler_2d(&s, u, v);
}

/* Whether passes [first, first + 2^m) of a request form a (0, m, 2)-net. */
static int is_net(uint64_t seed, uint64_t px, uint32_t dim, uint32_t first, int m, int *worst)
{
    uint32_t n = 1u << m;
    float *u = malloc(sizeof *u * n), *v = malloc(sizeof *v * n);
    uint8_t *hit = malloc(n);
    for (uint32_t k = 0; k < n; k++)
        draw(seed, px, first + k, dim, &u[k], &v[k]);
    int ok = 1;
    for (int a = 0; a <= m; a++) {
        memset(hit, 0, n);
        for (uint32_t k = 0; k < n; k++) {
            if (!(u[k] >= 0.0f && u[k] < 1.0f && v[k] >= 0.0f && v[k] < 1.0f)) {
                ok = 0;
                continue;
            }
            uint32_t x = (uint32_t)(u[k] * (float)(1u << a)), y = (uint32_t)(v[k] * (float)(1u << (m - a)));
            uint32_t c = (x << (m - a)) | y;
            if (hit[c]++ && hit[c] > *worst)
                *worst = hit[c];
        }
        for (uint32_t c = 0; c < n; c++)
            ok &= hit[c] == 1;
    }
    free(u);
    free(v);
    free(hit);
    return ok;
}

static double correlation(const float *a, const float *b, int n)
{
    double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
    for (int i = 0; i < n; i++)
        ma += a[i], mb += b[i];
    ma /= n, mb /= n;
    for (int i = 0; i < n; i++) {
        sab += (a[i] - ma) * (b[i] - mb);
        saa += (a[i] - ma) * (a[i] - ma);
        sbb += (b[i] - mb) * (b[i] - mb);
    }
    return sab / sqrt(saa * sbb);
}

/* The seven numbers of two draws, the late ones included. */
static int same_numbers(const cdl_vertex_numbers *a, const cdl_vertex_numbers *b)
{
    int k[5] = {0, 2, 3, 5, 6}, ok = 1;
    for (int i = 0; i < 5; i++)
        ok &= a->u[k[i]] == b->u[k[i]];
    return ok && cdl_vertex_number_late(a, 1) == cdl_vertex_number_late(b, 1) &&
           cdl_vertex_number_late(a, 4) == cdl_vertex_number_late(b, 4);
}

int main(void)
{
    /* nets: pixels, requests and sizes, the first blocks and a later one */
    int nets = 0, good = 0, worst = 1;
    for (uint64_t px = 0; px < 6; px++)
        for (uint32_t dim = 0; dim < 12; dim += 3)
            for (int m = 2; m <= 10; m += 4) {
                nets += 2;
                good += is_net(7, px * 7919, dim, 0, m, &worst);
                good += is_net(7, px * 7919, dim, 5u << m, m, &worst);
            }
    CHECK(good == nets, "2D requests over 2^m passes are (0, m, 2)-nets: %d of %d (most points in one box: %d)",
          good, nets, worst);

    /* 1D: one point per stratum over 256 passes */
    int strat = 1;
    for (uint64_t px = 0; px < 4; px++) {
        uint8_t seen[256] = {0};
        for (uint32_t pass = 0; pass < 256; pass++) {
            cdl_sampler s;
            cdl_sampler_start(&s, CDL_SAMPLER_SOBOL, 3, px, pass);
            float a, b;
            cdl_sampler_2d(&s, &a, &b);
            float u = cdl_sampler_1d(&s);
            int k = (int)(u * 256.0f);
            strat &= k >= 0 && k < 256 && !seen[k]++;
        }
    }
    CHECK(strat, "1D requests over 256 passes: one point per 1/256");

    /* decorrelation across requests of a pixel and across pixels: the
     * sample correlation of 4096 pairs has sigma 1 / 64 */
    enum { N = 4096 };
    static float a[N], b[N], c[N], d[N];
    for (int k = 0; k < N; k++) {
        float v;
        draw(11, 1234, (uint32_t)k, 0, &a[k], &v);
        draw(11, 1234, (uint32_t)k, 1, &b[k], &v);
        draw(11, 1235, (uint32_t)k, 0, &c[k], &v);
        draw(11, (uint64_t)k, 0, 0, &d[k], &v); /* one pass, many pixels */
    }
    double r_dims = correlation(a, b, N), r_px = correlation(a, c, N);
    CHECK(fabs(r_dims) < 5.0 / 64.0 && fabs(r_px) < 5.0 / 64.0,
          "correlation between requests %.4f, between neighbouring pixels %.4f (limit 5 sigma = %.4f)", r_dims, r_px,
          5.0 / 64.0);
    double mean = 0;
    for (int k = 0; k < N; k++)
        mean += d[k];
    mean /= N;
    CHECK(fabs(mean - 0.5) < 5.0 * sqrt(1.0 / 12.0 / N), "pass 0 over 4096 pixels: mean %.4f (limit 0.5 +- %.4f)",
          mean, 5.0 * sqrt(1.0 / 12.0 / N));

    /* seeds */
    float u1, v1, u2, v2, u3, v3;
    draw(5, 99, 17, 4, &u1, &v1);
    draw(5, 99, 17, 4, &u2, &v2);
    draw(6, 99, 17, 4, &u3, &v3);
    CHECK(u1 == u2 && v1 == v2 && (u1 != u3 || v1 != v3), "a seed repeats its numbers (%.6f %.6f), another seed "
          "does not (%.6f %.6f)", u1, v1, u3, v3);

    /* the independent sampler */
    double s1 = 0, s2 = 0;
    for (int k = 0; k < N; k++) {
        cdl_sampler s;
        cdl_sampler_start(&s, CDL_SAMPLER_INDEPENDENT, 1, (uint64_t)k, 3);
        float x = cdl_sampler_1d(&s);
        s1 += x;
        s2 += x * x;
    }
    double im = s1 / N, iv = s2 / N - im * im;
    CHECK(fabs(im - 0.5) < 5.0 * sqrt(1.0 / 12.0 / N) && fabs(iv - 1.0 / 12.0) < 0.01,
          "independent sampler: mean %.4f, variance %.4f (1/12 = %.4f)", im, iv, 1.0 / 12.0);

    /* block start against one sampler at a time: every lane count, seeds,
     * passes (high bits too) and streams, three vertices drawn ahead, then
     * the draws after them */
    enum { NV = 3 };
    int blocks = 0, same = 0;
    for (int n = 1; n <= CDL_SAMPLER_BLOCK; n++)
        for (uint32_t pass = 0; pass < 40; pass++) {
            uint64_t seed = (uint64_t)n * 0x1234567ULL + pass, stream[CDL_SAMPLER_BLOCK];
            uint32_t index = pass < 20 ? pass : pass * 0x9e3779b9u;
            for (int i = 0; i < n; i++)
                stream[i] = (uint64_t)(pass * 977 + i) * 1000003ULL + ((uint64_t)i << 40);
            cdl_sampler blk[CDL_SAMPLER_BLOCK];
            cdl_numbers_ahead ahead;
            float jx[CDL_SAMPLER_BLOCK], jy[CDL_SAMPLER_BLOCK];
            cdl_sampler_block_start(blk, n, CDL_SAMPLER_SOBOL, seed, stream, index, jx, jy, &ahead, NV);
            for (int i = 0; i < n; i++) {
                cdl_sampler s;
                float x, y;
                cdl_sampler_start(&s, CDL_SAMPLER_SOBOL, seed, stream[i], index);
                cdl_sampler_2d(&s, &x, &y);
                int ok = ahead.nv == NV && x == jx[i] && y == jy[i] && s.key == blk[i].key && s.dim == blk[i].dim;
                for (int j = 0; j < NV; j++) {
                    cdl_vertex_numbers p, vn = cdl_vertex_numbers_draw(&s);
                    ok &= cdl_numbers_ahead_take(&ahead, i, &blk[i], &p) && same_numbers(&vn, &p);
                }
                cdl_vertex_numbers none;
                ok &= !cdl_numbers_ahead_take(&ahead, i, &blk[i], &none);
                float a1, b1, a2, b2;
                cdl_sampler_2d(&s, &a1, &b1);
                cdl_sampler_2d(&blk[i], &a2, &b2);
                ok &= s.dim == blk[i].dim && a1 == a2 && b1 == b2;
                blocks++;
                same += ok;
            }
        }
    CHECK(same == blocks, "block start gives the one-at-a-time numbers in %d of %d lanes", same, blocks);
    cdl_sampler ib[2];
    cdl_numbers_ahead iahead;
    float ix[2], iy[2];
    uint64_t ist[2] = {5, 6};
    cdl_sampler_block_start(ib, 2, CDL_SAMPLER_INDEPENDENT, 1, ist, 3, ix, iy, &iahead, 2);
    cdl_sampler is;
    cdl_sampler_start(&is, CDL_SAMPLER_INDEPENDENT, 1, 6, 3);
    float ia, ibv;
    cdl_sampler_2d(&is, &ia, &ibv);
    CHECK(iahead.nv == 0 && ix[1] == ia && iy[1] == ibv,
          "independent sampler: block start draws only the first request");
    return test_failures ? 1 : 0;
}
