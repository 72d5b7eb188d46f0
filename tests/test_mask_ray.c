/* The visibility mask's work on one photon ray (integrators/splat/
 * mask_ray.c): rasterizing a batch whose boxes fit a small window (the
 * rows z-min in registers) fills the buffer exactly as one cell at a time
 * does, bit for bit, on clustered batches (windows of 1 x 1 to 8 x 8
 * cells), spread ones (the cell by cell path), several grid sizes, and
 * with the reach cutting some lanes; and a buffer that keeps a plane per
 * cell hides exactly the samples one that keeps the occluder does, for
 * occluders on three planes (facing the ray, tilted, and with the origin
 * behind it). */
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

/* Occluders on three planes, rasterized once by index and once by plane;
 * feasible samples throughout the frustum filtered through both. */
#define NF (16 * 256)
#define NH 48
/* the feasible samples, then the occluders (the index filter reads their
 * planes from the feasible samples' tree, as in the renderer) */
static float fpos[3][NF + 16 * NH + 16], fnrm[3][NF + 16 * NH + 16], fpw[NF + 16];
static uint32_t fid[16 * NH + 16];

static void planes_match(const cdl_photon_ray *r, const float *const *axp)
{
    cdl_rng rng;
    cdl_rng_seed(&rng, 29, 1);
    const float pn[3][3] = {{0.0f, 0.0f, -1.0f}, {0.6f, 0.0f, -0.8f}, {0.0f, 0.0f, 1.0f}};
    const float pc[3] = {-1.0f, -1.2f, 2.5f}; /* p . n on each plane */
    static mask_held h[NH];
    for (uint32_t b = 0; b < NH; b++) {
        const int k = (int)(b % 3);
        h[b].first = 16 * b, h[b].mask = 0xffffu;
        for (uint32_t i = 0; i < 16; i++) {
            uint32_t q = 16 * b + i;
            float x = 1.2f * (cdl_rng_float(&rng) - 0.5f), y = 1.2f * (cdl_rng_float(&rng) - 0.5f);
            /* on plane k: solve n . p = c for z */
            float z = (pc[k] - pn[k][0] * x - pn[k][1] * y) / pn[k][2];
            pos[0][q] = x, pos[1][q] = y, pos[2][q] = z;
            for (int c = 0; c < 3; c++)
                nrm[c][q] = pn[k][c];
            pw[q] = 0.01f;
            h[b].z[i] = z;
            h[b].pid[i] = (uint8_t)k;
            fid[q] = NF + q;
            for (int c = 0; c < 3; c++)
                fpos[c][NF + q] = pos[c][q], fnrm[c][NF + q] = pn[k][c];
        }
    }
    /* the planes turned away from the origin (the side they hide), offsets
     * p . n */
    float tab[4 * MASK_PLANES];
    memset(tab, 0, sizeof tab);
    for (int k = 0; k < 3; k++) {
        float s = -pc[k] > 0.0f ? -1.0f : 1.0f; /* (o - q) . n > 0: turned */
        for (int c = 0; c < 3; c++)
            tab[c * MASK_PLANES + k] = s * pn[k][c];
        tab[3 * MASK_PLANES + k] = s * pc[k];
    }
    for (uint32_t q = 0; q < NF; q++) {
        float z = 0.5f + 3.5f * cdl_rng_float(&rng), hz = r->h0 + r->dh * (z < r->len ? z : r->len);
        fpos[0][q] = 1.8f * hz * (cdl_rng_float(&rng) - 0.5f);
        fpos[1][q] = 1.8f * hz * (cdl_rng_float(&rng) - 0.5f);
        fpos[2][q] = z;
        fpw[q] = 0.002f + 0.03f * cdl_rng_float(&rng);
    }
    cdl_skd t, ft;
    memset(&t, 0, sizeof t);
    memset(&ft, 0, sizeof ft);
    for (int c = 0; c < 3; c++)
        t.p[c] = pos[c], t.nrm[c] = nrm[c], ft.p[c] = fpos[c], ft.nrm[c] = fnrm[c];
    t.n = 16 * NH, ft.n = NF;
    const int g = 32, gg = g * g;
    uint64_t *gi = malloc(sizeof *gi * gg);
    uint32_t *zg = malloc(sizeof *zg * gg), *ig = malloc(sizeof *ig * gg), *cz = malloc(sizeof *cz * gg);
    uint32_t occ[MASK_G * MASK_G / 32];
    memset(occ, 0, sizeof occ);
    mask_ray xi = {.t = &t, .r = r, .pw = pw, .ax = axp, .U = {1.0f, 0.0f, 0.0f}, .V = {0.0f, 1.0f, 0.0f},
                   .eps = 1e-5f, .g = g, .reach = INT32_MAX, .grid = gi, .id = fid, .ft = &ft, .fpw = fpw};
    mask_ray xp = xi;
    xp.grid = NULL;
    for (int c = 0; c < gg; c++)
        gi[c] = UINT64_MAX, cz[c] = (uint32_t)INT32_MAX;
    xp.grid32 = cz;
    for (uint32_t b = 0; b < NH; b++) {
        splat_mask_rasterize_z(&xi, h[b].first, h[b].mask, h[b].z);
        splat_mask_rasterize_planes(&xp, h[b].first, h[b].mask, h[b].z, h[b].pid);
    }
    int cover = 0;
    for (int c = 0; c < gg; c++) {
        int full = gi[c] != UINT64_MAX, full32 = cz[c] != (uint32_t)INT32_MAX;
        zg[c] = full ? (uint32_t)(gi[c] >> 32) : (uint32_t)INT32_MAX, ig[c] = (uint32_t)gi[c];
        occ[c >> 5] |= (uint32_t)full32 << (c & 31);
        cover += full != full32;
    }
    CHECK(cover == 0, "planes and occluders fill the same cells (%d differ)", cover);
    xi.zg = zg, xi.ig = ig;
    xp.cz = cz, xp.occ = occ, xp.tab = tab;
    uint32_t hidden = 0, differ = 0;
    for (uint32_t q = 0; q < NF; q += 16) {
        uint32_t a = splat_mask_filter(&xi, q, 0xffffu), b = splat_mask_filter(&xp, q, 0xffffu);
        hidden += (uint32_t)__builtin_popcount(~a & 0xffffu);
        differ += (uint32_t)__builtin_popcount(a ^ b);
    }
    CHECK(differ == 0 && hidden > NF / 20 && hidden < NF - NF / 20,
          "planes per cell hide what occluders per cell do (%u of %u differ, %u hidden)", differ, NF, hidden);
    free(gi), free(zg), free(ig), free(cz);
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
            held[b].pid[i] = (uint8_t)((b + i) % 5);
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
            /* the same with a plane per cell (32-bit keys, two rows a
             * register) */
            uint32_t *h0 = (uint32_t *)g0, *h1 = (uint32_t *)g1;
            for (int c = 0; c < MASK_G * MASK_G; c++)
                h0[c] = h1[c] = (uint32_t)INT32_MAX;
            x0.grid32 = h0, x1.grid32 = h1;
            n0 = n1 = 0;
            for (uint32_t b = 0; b < NB; b++) {
                n0 += (uint64_t)__builtin_popcount(splat_mask_rasterize_planes(&x0, held[b].first, held[b].mask, held[b].z, held[b].pid));
                n1 += (uint64_t)__builtin_popcount(splat_mask_rasterize_planes(&x1, held[b].first, held[b].mask, held[b].z, held[b].pid));
            }
            diff = filled = 0;
            for (int c = 0; c < g * g; c++) {
                diff += h0[c] != h1[c];
                filled += h0[c] != (uint32_t)INT32_MAX;
            }
            CHECK(n0 == n1 && diff == 0 && filled > g * g / 2,
                  "g %d, reach %s, planes: the same lanes and buffer (%llu, %llu; %d cells differ, %d filled)", g,
                  cut ? "cut" : "open", (unsigned long long)n0, (unsigned long long)n1, diff, filled);
        }

    free(g0);
    free(g1);
    free(held);
    planes_match(&r, axp);
    return test_failures ? 1 : 0;
}
