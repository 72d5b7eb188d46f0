/* The visibility mask's work on one photon ray (integrators/splat/
 * mask_ray.c): rasterizing a batch whose boxes fit a small window (the
 * rows z-min in registers) fills the buffer exactly as one cell at a time
 * does, bit for bit, on clustered batches (windows of 1 x 1 to 8 x 8
 * cells), spread ones (the cell by cell path), several grid sizes, and
 * with the reach cutting some lanes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "integrators/splat/mask_ray.h"
#include "test_util.h"

#define NB 512 /* batches */
#define NS (16 * NB)

static float pos[3][NS + 16], nrm[3][NS + 16], pw[NS + 16], ax[6][NS + 16];

static uint32_t bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

int main(void)
{
    cdl_rng rng;
    cdl_rng_seed(&rng, 29, 0);
    /* the ray along +z from the origin, its kernel 0.2 + 0.1 z wide */
    cdl_photon_ray r;
    memset(&r, 0, sizeof r);
    r.o = cdl_v3(0.0f, 0.0f, 0.0f), r.d = cdl_v3(0.0f, 0.0f, 1.0f), r.on = cdl_v3(0.0f, 0.0f, 1.0f);
    r.len = 4.0f, r.h0 = 0.2f, r.dh = 0.1f;
    mask_held *held = calloc(NB, sizeof *held);
    /* batch b: 16 samples about a centre, spread 0.002 to 0.5 (a batch
     * in 8 is spread across the kernel) */
    for (uint32_t b = 0; b < NB; b++) {
        float z0 = 0.5f + 3.0f * cdl_rng_float(&rng), h = r.h0 + r.dh * z0;
        float cx = h * (2.0f * cdl_rng_float(&rng) - 1.0f), cy = h * (2.0f * cdl_rng_float(&rng) - 1.0f);
        float spread = b % 8 == 7 ? h : 0.002f + 0.05f * (float)(b % 8);
        float foot = b % 3 == 0 ? 0.002f : 0.02f * cdl_rng_float(&rng);
        held[b].first = 16 * b;
        held[b].mask = (uint32_t)(cdl_rng_u32(&rng) & 0xffffu) | 1u;
        for (uint32_t i = 0; i < 16; i++) {
            uint32_t q = 16 * b + i;
            pos[0][q] = cx + spread * (cdl_rng_float(&rng) - 0.5f);
            pos[1][q] = cy + spread * (cdl_rng_float(&rng) - 0.5f);
            pos[2][q] = z0 + 0.1f * (cdl_rng_float(&rng) - 0.5f);
            /* facing the ray mostly; some tilted, a few edge-on (the
             * origin's plane: not rasterized) */
            float tx = 0.6f * (cdl_rng_float(&rng) - 0.5f), ty = 0.6f * (cdl_rng_float(&rng) - 0.5f);
            float l = sqrtf(tx * tx + ty * ty + 1.0f);
            nrm[0][q] = tx / l, nrm[1][q] = ty / l, nrm[2][q] = -1.0f / l;
            if (i == 5) /* its plane through the origin */
                nrm[0][q] = pos[2][q] / sqrtf(pos[0][q] * pos[0][q] + pos[2][q] * pos[2][q]),
                nrm[1][q] = 0.0f, nrm[2][q] = -pos[0][q] / sqrtf(pos[0][q] * pos[0][q] + pos[2][q] * pos[2][q]);
            pw[q] = foot * (0.5f + cdl_rng_float(&rng));
            float s = 0.6f * pw[q], s2 = s * (1.0f + 4.0f * cdl_rng_float(&rng));
            ax[0][q] = s2 * nrm[2][q], ax[1][q] = 0.0f, ax[2][q] = -s2 * nrm[0][q];
            ax[3][q] = 0.0f, ax[4][q] = s * 1.0f, ax[5][q] = 0.0f;
            held[b].z[i] = pos[2][q];
        }
    }
    cdl_skd t;
    memset(&t, 0, sizeof t);
    for (int c = 0; c < 3; c++)
        t.p[c] = pos[c], t.nrm[c] = nrm[c];
    t.n = NS;
    const float *axp[6] = {ax[0], ax[1], ax[2], ax[3], ax[4], ax[5]};
    uint64_t *g0 = malloc(sizeof *g0 * MASK_G * MASK_G), *g1 = malloc(sizeof *g1 * MASK_G * MASK_G);
    const int sizes[4] = {32, 24, 13, 5};
    for (int gi = 0; gi < 4; gi++)
        for (int cut = 0; cut < 2; cut++) {
            int g = sizes[gi];
            mask_ray x0 = {.t = &t, .r = &r, .pw = pw, .ax = axp, .U = {1.0f, 0.0f, 0.0f}, .V = {0.0f, 1.0f, 0.0f},
                           .eps = 1e-5f, .g = g, .reach = cut ? (int32_t)bits(2.0f) : INT32_MAX, .grid = g0, .plain = 1};
            mask_ray x1 = x0;
            x1.grid = g1, x1.plain = 0;
            for (int c = 0; c < MASK_G * MASK_G; c++)
                g0[c] = g1[c] = UINT64_MAX;
            uint64_t n0 = 0, n1 = 0;
            for (uint32_t b = 0; b < NB; b++) {
                n0 += splat_mask_rasterize(&x0, &held[b]);
                n1 += splat_mask_rasterize(&x1, &held[b]);
            }
            int diff = 0, filled = 0;
            for (int c = 0; c < g * g; c++) {
                diff += g0[c] != g1[c];
                filled += g0[c] != UINT64_MAX;
            }
            CHECK(n0 == n1 && n0 > 1000, "g %d, reach %s: both rasterize the same lanes (%llu, %llu)", g,
                  cut ? "cut" : "open", (unsigned long long)n0, (unsigned long long)n1);
            CHECK(diff == 0 && filled > g * g / 2, "g %d, reach %s: the same buffer (%d of %d cells differ, %d filled)",
                  g, cut ? "cut" : "open", diff, g * g, filled);
        }

    free(g0);
    free(g1);
    free(held);
    return test_failures ? 1 : 0;
}
