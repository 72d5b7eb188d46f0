/* Discontinuity segmentation and the segment-restricted box filter
 * (film/segments.c; Herzog et al. 2007, §6.2): a depth step, a crease
 * and a slanted plane seen in perspective; the filter never mixes two
 * segments, keeps constants and linear ramps inside a segment, and the
 * support grows until the box holds the target count. */
#include <math.h>
#include <string.h>

#include "core/rng.h"
#include "film/segments.h"
#include "test_util.h"

#define W 64
#define H 48

/* View depth (along -z) of the plane n . x = c seen through pixel (x, y)
 * (camera at the origin looking down -z, 60 degree vertical field of view). */
static float plane_depth(int x, int y, cdl_vec3 n, float c)
{
    float t = tanf(0.5236f);
    cdl_vec3 d = cdl_normalize(cdl_v3((2.0f * (x + 0.5f) / W - 1.0f) * t * W / H, (1.0f - 2.0f * (y + 0.5f) / H) * t, -1.0f));
    return c / cdl_dot(n, d) * -d.z;
}

int main(void)
{
    static float depth[W * H], img[W * H * 2], count[W * H];
    static cdl_vec3 nrm[W * H];
    static uint8_t rad[W * H];
    cdl_error err;
    cdl_segments sg;
    cdl_rng r;
    cdl_rng_seed(&r, 3, 0);

    /* 1. a wall at distance 4 with a box face at distance 2 in front of
     * its left half (same normal): a depth step at x = 30 */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int p = y * W + x;
            nrm[p] = cdl_v3(0, 0, 1);
            depth[p] = plane_depth(x, y, cdl_v3(0, 0, -1), x < 30 ? 2.0f : 4.0f);
        }
    die_on(cdl_segment(&sg, W, H, depth, nrm, cosf(20.0f * 3.14159265f / 180.0f), 0.05f, &err), &err);
    int split_ok = sg.n == 2;
    for (int p = 0; p < W * H && split_ok; p++)
        split_ok = sg.id[p] == (p % W < 30 ? sg.id[0] : sg.id[W - 1]) && sg.id[0] != sg.id[W - 1];
    CHECK(split_ok, "a depth step splits the image into 2 segments along the step (%u segments)", sg.n);
    /* noisy values 1 left, 5 right: the filter averages each side alone */
    double left = 0.0, right = 0.0;
    for (int p = 0; p < W * H; p++) {
        float v = (p % W < 30 ? 1.0f : 5.0f) + 0.5f * (cdl_rng_float(&r) - 0.5f);
        img[2 * p] = v;
        img[2 * p + 1] = 7.0f; /* a constant channel */
        if (p % W < 30)
            left += v;
        else
            right += v;
        rad[p] = 200; /* the whole segment */
    }
    left /= 30.0 * H;
    right /= (W - 30.0) * H;
    die_on(cdl_segment_filter(&sg, img, 2, NULL, rad, &err), &err);
    double worst = 0.0, worst_c = 0.0;
    for (int p = 0; p < W * H; p++) {
        double want = p % W < 30 ? left : right;
        worst = fmax(worst, fabs(img[2 * p] - want));
        worst_c = fmax(worst_c, fabs(img[2 * p + 1] - 7.0));
    }
    CHECK(worst < 1e-4 && worst_c < 1e-5,
          "a box over the whole image gives each side its own mean (worst %.2g), a constant stays (%.2g)", worst,
          worst_c);
    /* a small box: pixels next to the step see their own side only */
    for (int p = 0; p < W * H; p++) {
        img[2 * p] = p % W < 30 ? 1.0f : 5.0f;
        rad[p] = 3;
    }
    die_on(cdl_segment_filter(&sg, img, 2, NULL, rad, &err), &err);
    int mixed = 0;
    for (int p = 0; p < W * H; p++)
        mixed += img[2 * p] != (p % W < 30 ? 1.0f : 5.0f);
    CHECK(mixed == 0, "a 7x7 box at the step never mixes the two segments (%d pixels changed)", mixed);
    /* a ramp inside one segment stays: the box mean of a linear function */
    for (int p = 0; p < W * H; p++) {
        img[2 * p] = 0.25f * (float)(p % W) + 0.5f * (float)(p / W);
        rad[p] = 2;
    }
    die_on(cdl_segment_filter(&sg, img, 2, NULL, rad, &err), &err);
    double ramp = 0.0;
    for (int y = 2; y < H - 2; y++)
        for (int x = 2; x < 28; x++)
            ramp = fmax(ramp, fabs(img[2 * (y * W + x)] - (0.25 * x + 0.5 * y)));
    CHECK(ramp < 1e-4, "a linear ramp away from the segment's borders is kept (worst %.2g)", ramp);
    /* support: 3 per pixel, target 75 -> a 5x5 box (r = 2) inside, larger at borders */
    for (int p = 0; p < W * H; p++)
        count[p] = 3.0f;
    die_on(cdl_segment_support(&sg, count, 75.0, 25, rad, &err), &err);
    CHECK(rad[20 * W + 15] == 2 && rad[20 * W + 29] > 2 && rad[0] > 2,
          "support: r = 2 for 25 pixels of 3 inside (got %d), wider at the step (%d) and the corner (%d)",
          rad[20 * W + 15], rad[20 * W + 29], rad[0]);
    die_on(cdl_segment_support(&sg, count, 1e9, 25, rad, &err), &err);
    CHECK(rad[100] == 25, "an unreachable target takes the largest support (%d)", rad[100]);
    cdl_segments_free(&sg);

    /* 2. a crease: floor and wall meet at the same depth, normals 90 degrees apart */
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int p = y * W + x;
            int floor = y >= 30;
            nrm[p] = floor ? cdl_v3(0, 1, 0) : cdl_v3(0, 0, 1);
            depth[p] = 3.0f;
        }
    die_on(cdl_segment(&sg, W, H, depth, nrm, cosf(20.0f * 3.14159265f / 180.0f), 0.05f, &err), &err);
    CHECK(sg.n == 2 && sg.id[29 * W] != sg.id[30 * W], "a crease (normals 90 degrees apart) is a border (%u segments)",
          sg.n);
    cdl_segments_free(&sg);

    /* 3. a floor slanted away in perspective, and pixels with no surface */
    int holes = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int p = y * W + x;
            nrm[p] = cdl_v3(0, 1, 0);
            depth[p] = y >= H / 2 + 2 ? plane_depth(x, y, cdl_v3(0, 1, 0), -1.0f) : 0.0f;
            holes += depth[p] == 0.0f;
        }
    die_on(cdl_segment(&sg, W, H, depth, nrm, cosf(20.0f * 3.14159265f / 180.0f), 0.05f, &err), &err);
    int none = 0;
    for (int p = 0; p < W * H; p++)
        none += sg.id[p] < 0;
    CHECK(sg.n == 1 && none == holes, "a slanted floor in perspective is one segment (%u), empty pixels none (%d of %d)",
          sg.n, none, holes);
    cdl_segments_free(&sg);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
