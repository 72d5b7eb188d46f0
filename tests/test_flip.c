/* FLIP and HDR-FLIP (src/film/flip.c): zero for identical images, uniform
 * colours against the paper's formulas evaluated here independently,
 * symmetry and monotonicity, the filters' sizes at the default viewing
 * distance, HDR-FLIP's automatic exposures on images whose luminances are
 * chosen, and the public API's argument checks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "candela/candela.h"
#include "film/flip.h"
#include "test_util.h"


static cdl_image make(int w, int h)
{
    cdl_image img = {0};
    if (cdl_image_alloc(&img, w, h, NULL))
        exit(2);
    return img;
}

static void fill(cdl_image *img, float r, float g, float b)
{
    for (size_t p = 0; p < (size_t)img->width * img->height; p++) {
        img->rgb[3 * p] = r;
        img->rgb[3 * p + 1] = g;
        img->rgb[3 * p + 2] = b;
    }
}

static unsigned rng = 12345u;
static float urand(void)
{
    rng = rng * 1664525u + 1013904223u;
    return (rng >> 8) * (1.0f / 16777216.0f);
}

static double flip_mean(const cdl_image *t, const cdl_image *r, int hdr, double ppd)
{
    double m = -1.0;
    cdl_error err;
    if (cdl_flip(t, r, hdr, ppd, NULL, &m, NULL, &err))
        printf("cdl_flip: %s\n", err.msg);
    return m;
}

/* ---- the paper's colour pipeline, written out again for uniform images ---- */

/* sRGB primaries, D65 (IEC 61966-2-1), and CIELAB with Hunt's adjustment. */
static void lab_hunt_ref(const double c[3], double lab[3])
{
    double X = 0.4123908 * c[0] + 0.3575843 * c[1] + 0.1804808 * c[2];
    double Y = 0.2126390 * c[0] + 0.7151687 * c[1] + 0.0721923 * c[2];
    double Z = 0.0193308 * c[0] + 0.1191948 * c[1] + 0.9505322 * c[2];
    double t[3] = {X / 0.950428545, Y, Z / 1.088900371}, f[3];
    for (int i = 0; i < 3; i++)
        f[i] = t[i] > 216.0 / 24389.0 ? cbrt(t[i]) : t[i] * 24389.0 / 3132.0 + 4.0 / 29.0;
    double L = 116.0 * f[1] - 16.0;
    lab[0] = L;
    lab[1] = L / 100.0 * 500.0 * (f[0] - f[1]);
    lab[2] = L / 100.0 * 200.0 * (f[1] - f[2]);
}

static double hyab_ref(const double *p, const double *q)
{
    return fabs(p[0] - q[0]) + sqrt((p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
}

/* FLIP of two uniform images: the filters keep a constant, the edge and
 * point detectors give 0, so FLIP = the remapped HyAB distance. */
static double uniform_flip_ref(const double a[3], const double b[3])
{
    const double green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
    double la[3], lb[3], lg[3], lbl[3];
    lab_hunt_ref(a, la);
    lab_hunt_ref(b, lb);
    lab_hunt_ref(green, lg);
    lab_hunt_ref(blue, lbl);
    double cmax = pow(hyab_ref(lg, lbl), 0.7), d = pow(hyab_ref(la, lb), 0.7);
    return d < 0.4 * cmax ? 0.95 * d / (0.4 * cmax) : 0.95 + 0.05 * (d - 0.4 * cmax) / (0.6 * cmax);
}

static void test_identity(void)
{
    cdl_image a = make(37, 23);
    for (size_t i = 0; i < 3 * (size_t)37 * 23; i++)
        a.rgb[i] = 4.0f * urand() * urand();
    for (int hdr = 0; hdr < 2; hdr++) {
        float *map = malloc(37 * 23 * sizeof *map);
        double m = -1;
        int rc = cdl_flip(&a, &a, hdr, 0, map, &m, NULL, NULL);
        float mx = 0;
        for (int p = 0; p < 37 * 23; p++)
            mx = map[p] > mx ? map[p] : mx;
        CHECK(!rc && m == 0.0 && mx == 0.0f, "%s-FLIP of an image against itself: mean %g, largest %g (0)",
              hdr ? "HDR" : "LDR", m, mx);
        free(map);
    }
    cdl_image_free(&a);
}

static void test_uniform(void)
{
    const double pairs[][2][3] = {
        {{0, 0, 0}, {1, 1, 1}},          /* black and white: HyAB 100, above the cut-off */
        {{0.2, 0.2, 0.2}, {0.22, 0.2, 0.2}}, /* a small red shift: below the cut-off */
        {{0.5, 0.1, 0.05}, {0.1, 0.4, 0.6}},
        {{0.9, 0.9, 0.2}, {0.85, 0.9, 0.25}},
    };
    cdl_image a = make(24, 20), b = make(24, 20);
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
        const double *p = pairs[k][0], *q = pairs[k][1];
        fill(&a, (float)p[0], (float)p[1], (float)p[2]);
        fill(&b, (float)q[0], (float)q[1], (float)q[2]);
        double m = flip_mean(&a, &b, 0, 0), want = uniform_flip_ref(p, q);
        CHECK(fabs(m - want) < 2e-5, "uniform (%g,%g,%g) against (%g,%g,%g): FLIP %.6f, the formulas %.6f", p[0],
              p[1], p[2], q[0], q[1], q[2], m, want);
    }
    /* By hand: white and black differ by L = 100 only, 100^0.7 = 25.12;
     * cmax = HyAB(green, blue)^0.7 = 41.27, so 0.95 + 0.05 (25.12 - 16.51) /
     * (41.27 - 16.51) = 0.9674. */
    fill(&a, 1, 1, 1);
    fill(&b, 0, 0, 0);
    double m = flip_mean(&a, &b, 0, 0);
    CHECK(fabs(m - 0.9674) < 5e-4, "white against black: %.5f (0.9674 by hand)", m);
    CHECK(fabs(cdl_flip_cmax() - 41.27) < 0.01, "cmax %.4f (41.27 by hand)", cdl_flip_cmax());
    /* The remapping's knee: 0.4 cmax (as a HyAB distance, (0.4 cmax)^(1/0.7)) maps to 0.95. */
    double knee = pow(0.4 * cdl_flip_cmax(), 1.0 / 0.7);
    CHECK(fabs(cdl_flip_color_remap(knee) - 0.95) < 1e-12 && fabs(cdl_flip_color_remap(pow(cdl_flip_cmax(), 1 / 0.7)) - 1) < 1e-12,
          "remapping: 0.4 cmax -> %.12f (0.95), cmax -> 1", cdl_flip_color_remap(knee));
    /* LDR clamps: 2 and 1 are the same white. */
    fill(&a, 2, 2, 2);
    fill(&b, 1, 1, 1);
    CHECK(flip_mean(&a, &b, 0, 0) == 0.0, "LDR-FLIP clamps to [0, 1]: white 2 against 1 gives 0");
    cdl_image_free(&a);
    cdl_image_free(&b);
}

/* Every term is symmetric in the two images (|.| of differences, HyAB);
 * a larger uniform offset is a larger HyAB distance, and the remapping
 * and the power are increasing. */
static void test_symmetry_monotonicity(void)
{
    cdl_image a = make(40, 30), b = make(40, 30);
    for (size_t i = 0; i < 3 * (size_t)40 * 30; i++) {
        a.rgb[i] = urand();
        b.rgb[i] = urand();
    }
    double ab = flip_mean(&a, &b, 0, 0), ba = flip_mean(&b, &a, 0, 0);
    CHECK(ab == ba && ab > 0.1, "LDR-FLIP is symmetric: %.9f both ways", ab);
    double prev = 0;
    int mono = 1;
    for (int k = 1; k <= 8; k++) {
        fill(&a, 0.3f, 0.3f, 0.3f);
        fill(&b, 0.3f + 0.05f * k, 0.3f, 0.3f);
        double m = flip_mean(&b, &a, 0, 0);
        mono &= m > prev;
        prev = m;
    }
    CHECK(mono, "FLIP grows with a uniform red offset (0.05 to 0.4): up to %.4f", prev);
    /* Noise of growing amplitude on the same pattern: more error. */
    for (size_t i = 0; i < 3 * (size_t)40 * 30; i++)
        a.rgb[i] = 0.2f + 0.6f * ((i / 3 % 40) / 8 % 2);
    double e[3];
    for (int k = 0; k < 3; k++) {
        unsigned seed = rng;
        for (size_t i = 0; i < 3 * (size_t)40 * 30; i++)
            b.rgb[i] = a.rgb[i] + (0.05f * (1 << (2 * k))) * (urand() - 0.5f);
        rng = seed;
        e[k] = flip_mean(&b, &a, 0, 0);
    }
    CHECK(e[0] < e[1] && e[1] < e[2], "noise of amplitude 0.05, 0.2, 0.8 (same draws): %.4f < %.4f < %.4f", e[0], e[1],
          e[2]);
    cdl_image_free(&a);
    cdl_image_free(&b);
}

/* Sizes of the reference implementation at 67 ppd: spatial radius
 * ceil(3 sqrt(0.04 / (2 pi^2)) 67.02) = 10, feature radius
 * ceil(3 * 0.5 * 0.082 * 67.02) = 9. */
static void test_filters(void)
{
    CHECK(fabs(CDL_FLIP_PPD_DEFAULT - 67.0206) < 1e-4, "default ppd %.6f (0.7 m, 3840 px on 0.7 m)", CDL_FLIP_PPD_DEFAULT);
    CHECK(cdl_flip_spatial_radius(CDL_FLIP_PPD_DEFAULT) == 10 && cdl_flip_feature_radius(CDL_FLIP_PPD_DEFAULT) == 9,
          "radii at 67 ppd: spatial %d (10), feature %d (9)", cdl_flip_spatial_radius(CDL_FLIP_PPD_DEFAULT),
          cdl_flip_feature_radius(CDL_FLIP_PPD_DEFAULT));
    /* A step edge moved by 1 and by 2 pixels: the blurred images differ
     * over a band that widens with the shift, by more in each pixel. */
    cdl_image a = make(64, 16), b = make(64, 16);
    double e[2];
    for (int s = 1; s <= 2; s++) {
        for (int y = 0; y < 16; y++)
            for (int x = 0; x < 64; x++)
                for (int c = 0; c < 3; c++) {
                    a.rgb[3 * (y * 64 + x) + c] = x < 32 ? 0.1f : 0.8f;
                    b.rgb[3 * (y * 64 + x) + c] = x < 32 + s ? 0.1f : 0.8f;
                }
        e[s - 1] = flip_mean(&b, &a, 0, 0);
    }
    CHECK(0 < e[0] && e[0] < e[1], "edge moved by 1 px: FLIP %.4f < by 2 px: %.4f", e[0], e[1]);
    cdl_image_free(&a);
    cdl_image_free(&b);
}

static void test_exposures(void)
{
    double xm = cdl_flip_aces_inverse_085();
    /* (0.9036 - 0.85 * 0.8748) x^2 + (0.018 - 0.85 * 0.354) x - 0.85 * 0.14 = 0:
     * 0.16002 x^2 - 0.2829 x - 0.119 = 0, x = 2.11887. */
    CHECK(fabs(cdl_flip_aces(xm) - 0.85) < 1e-12 && fabs(xm - 2.11887) < 1e-4,
          "ACES reaches 0.85 at %.5f (2.11887 by hand)", xm);
    /* Greys 2^-6 .. 2: median (element n/2 = 4 of 8) 2^-2, max 2: start
     * log2(xm / 2), stop log2(xm / 0.25), ceil(3) = 3 exposures. */
    cdl_image g = make(8, 1);
    for (int i = 0; i < 8; i++)
        for (int c = 0; c < 3; c++)
            g.rgb[3 * i + c] = ldexpf(1.0f, i - 6);
    cdl_flip_exposures e;
    cdl_flip_exposure_range(&g, &e);
    CHECK(fabs(e.start - log2(xm / 2)) < 1e-6 && fabs(e.stop - log2(xm / 0.25)) < 1e-6 && e.count == 3,
          "greys 2^-6..2: exposures %.4f to %.4f, %d of them (%.4f, %.4f, 3)", e.start, e.stop, e.count,
          log2(xm / 2), log2(xm / 0.25));
    cdl_image_free(&g);
    /* NVlabs' HDR example is evaluated from -12.5423 to 0.9427 in 14
     * exposures (its test's file name): a reference with those median and
     * largest luminances gives the same range and count. */
    cdl_image h = make(3, 1);
    float ymed = (float)(xm / exp2(0.9427)), ymax = (float)(xm / exp2(-12.5423));
    float lum[3] = {0.0f, ymed, ymax};
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++)
            h.rgb[3 * i + c] = lum[i];
    cdl_flip_exposure_range(&h, &e);
    CHECK(fabs(e.start + 12.5423) < 1e-4 && fabs(e.stop - 0.9427) < 1e-4 && e.count == 14,
          "NVlabs' example range: %.4f to %.4f, %d exposures (-12.5423, 0.9427, 14)", e.start, e.stop, e.count);
    /* Mostly black: the median of the positive pixels instead of 0. */
    lum[0] = lum[1] = 0.0f;
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++)
            h.rgb[3 * i + c] = lum[i];
    cdl_flip_exposure_range(&h, &e);
    CHECK(isfinite(e.stop) && e.count == 2, "mostly black reference: finite range %.3f to %.3f", e.start, e.stop);
    fill(&h, 0, 0, 0);
    cdl_flip_exposure_range(&h, &e);
    CHECK(e.start == 0 && e.stop == 0 && e.count == 2, "black reference: exposure 0 twice");
    cdl_image_free(&h);

    /* HDR-FLIP of uniform greys is the largest LDR-FLIP over the exposures of
     * the tone-mapped greys; with ref = 1, test = 1.5 the range is one point
     * (start = stop = log2 xm), so the value is the LDR-FLIP there. */
    cdl_image a = make(16, 16), b = make(16, 16);
    fill(&a, 1, 1, 1);
    fill(&b, 1.5f, 1.5f, 1.5f);
    cdl_flip(&b, &a, 1, 0, NULL, NULL, &e, NULL);
    double tr = cdl_flip_aces(xm), tt = cdl_flip_aces(1.5 * xm);
    const double pr[3] = {tr, tr, tr}, pt[3] = {tt > 1 ? 1 : tt, tt > 1 ? 1 : tt, tt > 1 ? 1 : tt};
    double m = flip_mean(&b, &a, 1, 0), want = uniform_flip_ref(pt, pr);
    CHECK(e.count == 2 && fabs(e.start - log2(xm)) < 1e-9 && fabs(m - want) < 2e-5,
          "HDR-FLIP of greys 1.5 against 1: %.6f, the formulas at exposure log2 %.4f: %.6f", m, xm, want);
    cdl_image_free(&a);
    cdl_image_free(&b);
}

static void test_api(void)
{
    cdl_image *a = NULL, *b = NULL, *c = NULL, *map = NULL;
    cdl_error err;
    double m = -1;
    if (cdl_image_create(8, 6, &a, &err) || cdl_image_create(8, 6, &b, &err) || cdl_image_create(6, 8, &c, &err))
        exit(2);
    for (int i = 0; i < 3 * 48; i++)
        cdl_image_pixels(b)[i] = 0.5f;
    int rc = cdl_image_flip(a, b, 0, 0, &m, &map, &err);
    CHECK(!rc && map && m > 0.5, "API: black against grey %.4f, with a map", m);
    if (map) {
        float *p = cdl_image_pixels(map), want[3];
        cdl_flip_magma(0.0f, want);
        CHECK(p[0] > want[0] && fabs(want[2] - 0.001073) < 2e-5, "map: magma(0) = (%g, %g, %g) linear", want[0], want[1],
              want[2]);
    }
    cdl_image_release(map);
    CHECK(cdl_image_flip(a, c, 1, 0, &m, NULL, &err) == CDL_ERR_INPUT, "sizes differ: %s", err.msg);
    CHECK(cdl_image_flip(NULL, b, 1, 0, &m, NULL, &err) == CDL_ERR_USAGE, "no image: %s", err.msg);
    CHECK(cdl_image_flip(a, b, 1, 0, NULL, NULL, &err) == CDL_ERR_USAGE, "no mean: %s", err.msg);
    CHECK(cdl_image_flip(a, b, 1, 0.5, &m, NULL, &err) == CDL_ERR_USAGE, "ppd 0.5: %s", err.msg);
    CHECK(cdl_image_flip(a, b, 1, NAN, &m, NULL, &err) == CDL_ERR_USAGE, "ppd NaN: %s", err.msg);
    CHECK(cdl_image_flip(a, b, 2, 0, &m, NULL, &err) == CDL_ERR_USAGE, "hdr 2: %s", err.msg);
    cdl_image_pixels(a)[7] = INFINITY;
    map = (cdl_image *)&m; /* must be reset on failure */
    CHECK(cdl_image_flip(a, b, 0, 0, &m, &map, &err) == CDL_ERR_INPUT && !map, "infinite pixel: %s", err.msg);
    cdl_image_release(a);
    cdl_image_release(b);
    cdl_image_release(c);
}

int main(void)
{
    test_identity();
    test_uniform();
    test_symmetry_monotonicity();
    test_filters();
    test_exposures();
    test_api();
    printf("%d failed\n", test_failures);
    return test_failures != 0;
}
