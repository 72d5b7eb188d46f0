/* Tests of pixel filters (film/filter.c), the orthographic camera and
 * Mitsuba's spot and projector lights (scene/light.c), issue 27.
 *
 * Filters (Mitsuba's box, tent, gaussian, mitchell, catmullrom, lanczos;
 * pbrt-v3's gaussian, pbrt-v4's gaussian):
 *  - the profile matches the closed form at a few offsets;
 *  - the camera sample weights f / pdf / int f average to 1 over the
 *    filter (the weights integrate to 1) and reproduce the filtered value
 *    int f(x) g(x) dx / int f of a test function g (midpoint quadrature
 *    of the same integral as the reference), also for a pixel at the image
 *    corner where Mitsuba's samples stay inside the image;
 *  - the one-pixel box passes the jitter through unchanged with weight 1;
 *  - a light-tracing contribution spreads over weights summing to 1.
 * Orthographic camera: ray origins span the to_world scale and share the
 * axis direction.
 * Spot (Mitsuba): intensity I at the centre, I inside beam_width, linear
 * in the angle to 0 at cutoff_angle, 0 beyond; Li = I / d^2.
 * Projector: a constant irradiance E at distance 1 on the axis gives
 * Li = pi E scale / (z^2 cos); nothing outside its image.
 *
 * Deterministic: the outcome never changes between runs. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rng.h"
#include "film/filter.h"
#include "scene/camera.h"
#include "scene/light.h"

static int checks, failures;

#define check(cond, ...)                                                                                           \
    do {                                                                                                           \
        checks++;                                                                                                  \
        if (!(cond)) {                                                                                             \
            failures++;                                                                                            \
            printf("FAIL: ");                                                                                      \
            printf(__VA_ARGS__);                                                                                   \
            printf("\n");                                                                                          \
        }                                                                                                          \
    } while (0)

static double g_test(double x, double y) { return 1.0 + 0.5 * sin(1.3 * x + 0.4) + 0.3 * x * y + 0.2 * y * y; }

/* int f(x - cx) f(y - cy) g over [x0, x1] x [y0, y1] / int f f, by the
 * midpoint rule on a fine grid. */
static double filtered(const cdl_filter *f, double cx, double cy, double x0, double x1, double y0, double y1)
{
    int n = 400;
    double num = 0.0, den = 0.0, hx = (x1 - x0) / n, hy = (y1 - y0) / n;
    for (int j = 0; j < n; j++) {
        double y = y0 + (j + 0.5) * hy, fy = cdl_filter_eval(f, 1, (float)(y - cy));
        for (int i = 0; i < n; i++) {
            double x = x0 + (i + 0.5) * hx, w = cdl_filter_eval(f, 0, (float)(x - cx)) * fy;
            num += w * g_test(x, y);
            den += w;
        }
    }
    return num / den;
}

static void test_filter(const char *name, cdl_filter_type t, float r, float p0, float p1, int clip)
{
    cdl_filter f;
    check(cdl_filter_init(&f, t, r, r, p0, p1, clip) == 0, "%s: init", name);
    int W = 16, H = 12;
    /* a pixel in the middle, and the top-left corner one */
    int px[2] = {7, 0}, py[2] = {5, 0};
    for (int k = 0; k < 2; k++) {
        double cx = px[k] + 0.5, cy = py[k] + 0.5;
        double x0 = cx - r, x1 = cx + r, y0 = cy - r, y1 = cy + r;
        if (clip) {
            x0 = fmax(x0, 0.0);
            y0 = fmax(y0, 0.0);
            x1 = fmin(x1, W);
            y1 = fmin(y1, H);
        }
        double ref = filtered(&f, cx, cy, x0, x1, y0, y1);
        /* stratified uniform numbers: the estimates are near exact */
        int n = 1024;
        double sw = 0.0, swg = 0.0;
        int outside = 0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                float x, y, w;
                cdl_filter_sample(&f, px[k], py[k], W, H, (i + 0.5f) / n, (j + 0.5f) / n, &x, &y, &w);
                sw += w;
                swg += w * g_test(x, y);
                outside += clip && (x < 0.0f || y < 0.0f || x >= W || y >= H);
            }
        sw /= (double)n * n;
        swg /= (double)n * n;
        /* signed weights of negative lobes converge more slowly on the grid */
        double tol = (t == CDL_FILTER_MITCHELL || t == CDL_FILTER_LANCZOS) ? 1e-2 : 3e-3;
        check(fabs(sw - 1.0) < tol, "%s pixel (%d,%d): weights average %.5f, not 1", name, px[k], py[k], sw);
        check(fabs(swg - ref) < tol * fabs(ref), "%s pixel (%d,%d): filtered g %.5f, quadrature %.5f", name, px[k],
              py[k], swg, ref);
        check(!outside, "%s: %d samples left the image", name, outside);
    }
    /* light tracing: weights sum to one where the footprint lies inside */
    int pix[CDL_FILTER_MAX_TAPS];
    float wt[CDL_FILTER_MAX_TAPS];
    int m = cdl_filter_spread(&f, 8.3f, 6.7f, W, H, pix, wt);
    double s = 0.0;
    for (int i = 0; i < m; i++)
        s += wt[i];
    check(m >= 1 && fabs(s - 1.0) < 1e-5, "%s: spread over %d pixels sums to %.6f", name, m, s);
}

static void test_profiles(void)
{
    cdl_filter f;
    /* Mitsuba's gaussian: exp(-x^2 / (2 sd^2)) - exp(-(4 sd)^2 / (2 sd^2)), sd = 0.5 */
    cdl_filter_init(&f, CDL_FILTER_GAUSSIAN, 2.0f, 2.0f, 2.0f, 0.0f, 1);
    for (float x = 0.0f; x < 2.2f; x += 0.25f) {
        double want = fmax(0.0, exp(-2.0 * x * x) - exp(-8.0));
        check(fabs(cdl_filter_eval(&f, 0, x) - want) < 1e-6, "gaussian(%g) = %g, want %g", (double)x,
              (double)cdl_filter_eval(&f, 0, x), want);
    }
    /* Mitchell-Netravali B = C = 1/3: 16/18 at 0, 1/18 at 1, 0 at 2 */
    cdl_filter_init(&f, CDL_FILTER_MITCHELL, 2.0f, 2.0f, 1.0f / 3.0f, 1.0f / 3.0f, 1);
    check(fabsf(cdl_filter_eval(&f, 0, 0.0f) - 16.0f / 18.0f) < 1e-6f, "mitchell(0)");
    check(fabsf(cdl_filter_eval(&f, 0, 1.0f) - 1.0f / 18.0f) < 1e-6f, "mitchell(1)");
    check(fabsf(cdl_filter_eval(&f, 0, 2.0f)) < 1e-6f, "mitchell(2)");
    /* Catmull-Rom interpolates: 1 at 0, 0 at 1 */
    cdl_filter_init(&f, CDL_FILTER_MITCHELL, 2.0f, 2.0f, 0.0f, 0.5f, 1);
    check(fabsf(cdl_filter_eval(&f, 0, 0.0f) - 1.0f) < 1e-6f && fabsf(cdl_filter_eval(&f, 0, 1.0f)) < 1e-6f,
          "catmullrom(0) = 1, (1) = 0");
    /* Lanczos, 3 lobes: sinc(x) sinc(x / 3) */
    cdl_filter_init(&f, CDL_FILTER_LANCZOS, 3.0f, 3.0f, 3.0f, 0.0f, 1);
    double x = 0.7, want = sin(CDL_PI * x) / (CDL_PI * x) * sin(CDL_PI * x / 3.0) / (CDL_PI * x / 3.0);
    check(fabs(cdl_filter_eval(&f, 0, (float)x) - want) < 1e-6, "lanczos(0.7)");
    check(cdl_filter_eval(&f, 0, 3.5f) == 0.0f, "lanczos beyond its lobes");
    /* tent of radius 1 */
    cdl_filter_init(&f, CDL_FILTER_TENT, 1.0f, 1.0f, 0.0f, 0.0f, 1);
    check(fabsf(cdl_filter_eval(&f, 0, 0.25f) - 0.75f) < 1e-6f, "tent(0.25)");
    /* the box passes the jitter through */
    cdl_filter_box(&f);
    float sx, sy, w;
    cdl_filter_sample(&f, 3, 4, 8, 8, 0.25f, 0.75f, &sx, &sy, &w);
    check(sx == 3.25f && sy == 4.75f && w == 1.0f, "box sample (%g, %g) weight %g", (double)sx, (double)sy,
          (double)w);
    int pix[4];
    float wt[4];
    check(cdl_filter_spread(&f, 3.9f, 4.1f, 8, 8, pix, wt) == 1 && pix[0] == 4 * 8 + 3 && wt[0] == 1.0f,
          "box spread: one pixel");
    check(cdl_filter_init(&f, CDL_FILTER_GAUSSIAN, 0.0f, 1.0f, 1.0f, 0.0f, 0) != 0, "zero radius refused");
}

static void test_ortho(void)
{
    cdl_camera c;
    cdl_error err;
    /* Mitsuba's x axis is the image's left: right = -1.5 x, up = 1.5 y */
    cdl_vec3 eye = cdl_v3(1, 2, 3), right = cdl_v3(-1.5f, 0, 0), up = cdl_v3(0, 1.5f, 0), fwd = cdl_v3(0, 0, 1);
    int W = 200, H = 120;
    check(cdl_camera_init_ortho(&c, eye, right, up, fwd, 1.0f, (float)H / W, 1.0f, W, H, &err) == 0, "ortho init");
    cdl_vec3 o0, o1, d0, d1;
    cdl_camera_gen(&c, 0.0f, 0.0f, &o0, &d0);
    cdl_camera_gen(&c, (float)W, (float)H, &o1, &d1);
    /* origins from x = 1 + 1.5 to 1 - 1.5, y = 2 + 1.5 H/W to 2 - 1.5 H/W, z = 3 + near */
    check(fabsf(o0.x - 2.5f) < 1e-5f && fabsf(o1.x + 0.5f) < 1e-5f, "ortho x span %g..%g", (double)o0.x,
          (double)o1.x);
    check(fabsf(o0.y - (2.0f + 0.9f)) < 1e-5f && fabsf(o1.y - (2.0f - 0.9f)) < 1e-5f, "ortho y span %g..%g",
          (double)o0.y, (double)o1.y);
    check(fabsf(o0.z - 4.0f) < 1e-6f && fabsf(o1.z - 4.0f) < 1e-6f, "ortho origins on the near plane");
    check(d0.z == 1.0f && d1.z == 1.0f && d0.x == 0.0f && d1.y == 0.0f, "ortho rays parallel to the axis");
    float x, y;
    check(!cdl_camera_raster(&c, cdl_v3(0, 0, 1), &x, &y), "nothing connects to an orthographic camera");
}

static void test_spot(void)
{
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_SPOT;
    l.spot_linear = 1;
    l.p = cdl_v3(0, 0, 0);
    l.n = cdl_v3(0, 0, 1);
    l.ax = cdl_v3(1, 0, 0);
    l.ay = cdl_v3(0, 1, 0);
    l.L = cdl_v3(5, 5, 5);
    l.cutoff = 20.0f * CDL_PI / 180.0f;
    l.beam = 15.0f * CDL_PI / 180.0f;
    l.cos_total = cosf(l.cutoff);
    l.cos_falloff = cosf(l.beam);
    l.tan_x = l.tan_y = tanf(l.cutoff);
    l.tex_id = -1;
    cdl_light_sample s;
    /* on the axis at distance 2: I / 4 */
    check(cdl_light_sample_li(&l, cdl_v3(0, 0, 2), 0.5f, 0.5f, &s) && fabsf(s.Li.x - 1.25f) < 1e-5f && s.delta,
          "spot centre: Li %g, want 1.25", (double)s.Li.x);
    float angles[4] = {10.0f, 17.5f, 19.0f, 21.0f}, want[4] = {5.0f, 2.5f, 1.0f, 0.0f};
    for (int i = 0; i < 4; i++) {
        float a = angles[i] * CDL_PI / 180.0f;
        cdl_vec3 w = cdl_v3(sinf(a), 0.0f, cosf(a));
        cdl_vec3 I = cdl_mul(l.L, cdl_light_I_factor(&l, w));
        check(fabsf(I.x - want[i]) < 1e-3f, "spot at %g degrees: I %g, want %g", (double)angles[i], (double)I.x,
              (double)want[i]);
    }
    check(!cdl_light_sample_li(&l, cdl_v3(0, 2, 1), 0.5f, 0.5f, &s), "nothing beyond the cutoff");
    /* emitted rays stay in the cone and carry I(d) */
    cdl_light_emit e;
    check(cdl_light_sample_le(&l, 0.1f, 0.2f, 0.7f, 0.3f, &e) && cdl_dot(e.d, l.n) >= l.cos_total - 1e-6f,
          "spot emission inside its cone");
}

static void test_projector(void)
{
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_PROJECTOR;
    l.p = cdl_v3(0, 0, 1);
    l.n = cdl_v3(0, 0, -1);
    l.ax = cdl_v3(-1, 0, 0);
    l.ay = cdl_v3(0, 1, 0);
    l.tan_x = l.tan_y = tanf(0.5f * 165.0f * CDL_PI / 180.0f);
    l.L = cdl_v3(CDL_PI, CDL_PI, CDL_PI); /* pi * scale 1 * irradiance 1 */
    l.tex_id = -1;
    cdl_light_sample s;
    /* a receiver at the plane z = 0 (distance 1 along the axis), off axis:
     * Li cos_receiver = pi (the irradiance times pi, Mitsuba's scale) */
    cdl_vec3 ref = cdl_v3(0.7f, -0.4f, 0.0f);
    check(cdl_light_sample_li(&l, ref, 0.5f, 0.5f, &s), "projector lights the plane");
    float cos_r = s.wi.z;
    check(fabsf(s.Li.x * cos_r - CDL_PI) < 1e-4f, "projector: Li cos %g, want pi", (double)(s.Li.x * cos_r));
    check(!cdl_light_sample_li(&l, cdl_v3(0, 0, 2), 0.5f, 0.5f, &s), "nothing behind a projector");
    /* emission: the pdf of sampled directions matches cdl_light_pdf_emit_dir
     * and integrates to one (Monte Carlo over the sphere) */
    cdl_light_emit e;
    check(cdl_light_sample_le(&l, 0.0f, 0.0f, 0.3f, 0.8f, &e) &&
              fabsf(e.pdf_dir - cdl_light_pdf_emit_dir(&l, e.d)) < 1e-4f * e.pdf_dir,
          "projector emission pdf");
    l.tan_x = l.tan_y = 0.5f;
    cdl_rng r;
    cdl_rng_seed(&r, 7, 1);
    double sum = 0.0;
    int n = 400000;
    for (int i = 0; i < n; i++) {
        float z = 1.0f - 2.0f * cdl_rng_float(&r), ph = 2.0f * CDL_PI * cdl_rng_float(&r);
        float sr = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        sum += cdl_light_pdf_emit_dir(&l, cdl_v3(sr * cosf(ph), sr * sinf(ph), z));
    }
    sum *= 4.0 * CDL_PI / n;
    check(fabs(sum - 1.0) < 0.02, "projector emission pdf integrates to %g", sum);
}

int main(void)
{
    test_profiles();
    test_filter("mitsuba box", CDL_FILTER_BOX, 0.5f, 0.0f, 0.0f, 1);
    test_filter("mitsuba tent", CDL_FILTER_TENT, 1.0f, 0.0f, 0.0f, 1);
    test_filter("mitsuba gaussian", CDL_FILTER_GAUSSIAN, 2.0f, 2.0f, 0.0f, 1);
    test_filter("mitsuba mitchell", CDL_FILTER_MITCHELL, 2.0f, 1.0f / 3.0f, 1.0f / 3.0f, 1);
    test_filter("mitsuba catmullrom", CDL_FILTER_MITCHELL, 2.0f, 0.0f, 0.5f, 1);
    test_filter("mitsuba lanczos", CDL_FILTER_LANCZOS, 3.0f, 3.0f, 0.0f, 1);
    test_filter("pbrt-v3 gaussian", CDL_FILTER_GAUSSIAN, 2.0f, 2.0f, 0.0f, 0);
    test_filter("pbrt-v4 gaussian", CDL_FILTER_GAUSSIAN, 1.5f, 2.0f, 0.0f, 0);
    test_filter("pbrt box 1", CDL_FILTER_BOX, 1.0f, 0.0f, 0.0f, 0);
    test_ortho();
    test_spot();
    test_projector();
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
