/* Error metrics between a rendered image and a reference. */
#include "film/metrics.h"

#include <math.h>
#include <stdlib.h>

static int same_size(const cdl_image *a, const cdl_image *b, cdl_error *err)
{
    if (a->width == b->width && a->height == b->height && a->rgb && b->rgb)
        return 0;
    return cdl_error_set(err, CDL_ERR_INPUT, NULL, 0,
                         "image sizes differ: test %dx%d, reference %dx%d",
                         a->width, a->height, b->width, b->height);
}

/* The relmse term; the 0.01 keeps near-black reference pixels from
 * dominating. */
static double rel_term(double t, double r)
{
    return (t - r) * (t - r) / (r * r + 0.01);
}

static double pixel_rel(const float *t, const float *r)
{
    return (rel_term(t[0], r[0]) + rel_term(t[1], r[1]) +
            rel_term(t[2], r[2])) / 3.0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int cdl_image_compare(const cdl_image *test, const cdl_image *ref,
                      cdl_metrics *out, cdl_error *err)
{
    if (same_size(test, ref, err))
        return CDL_ERR_INPUT;
    size_t npix = (size_t)test->width * test->height, n = 3 * npix;
    for (int which = 0; which < 2; which++) {
        const float *p = which ? ref->rgb : test->rgb;
        for (size_t i = 0; i < n; i++)
            if (!isfinite(p[i]))
                return cdl_error_set(
                    err, CDL_ERR_INPUT, NULL, 0,
                    "%s image has a non-finite value at pixel (%zu, %zu)",
                    which ? "reference" : "test", i / 3 % test->width,
                    i / 3 / test->width);
    }
    double *terms = malloc(npix * sizeof *terms);
    if (!terms)
        return cdl_error_set(err, CDL_ERR_SYSTEM, NULL, 0, "out of memory");

    double se = 0, rel = 0, ae = 0, st = 0, sr = 0;
    for (size_t i = 0; i < n; i++) {
        double t = test->rgb[i], r = ref->rgb[i], d = t - r;
        se += d * d;
        rel += rel_term(t, r);
        ae += fabs(d);
        st += t;
        sr += r;
    }
    out->rmse = sqrt(se / n);
    out->relmse = rel / n;
    out->mae = ae / n;
    out->mean_test = st / n;
    out->mean_ref = sr / n;
    out->mean_ratio = sr != 0 ? st / sr : NAN;

    /* A handful of fireflies can dominate relmse; the trimmed value shows
     * whether the rest of the image converged. */
    for (size_t p = 0; p < npix; p++)
        terms[p] = pixel_rel(test->rgb + 3 * p, ref->rgb + 3 * p);
    qsort(terms, npix, sizeof *terms, cmp_double);
    size_t keep = npix - npix / 1000;
    double sum = 0;
    for (size_t p = 0; p < keep; p++)
        sum += terms[p];
    out->relmse_trimmed = sum / keep;
    free(terms);
    return 0;
}

/* Blue -> light blue -> green -> yellow -> red, in sRGB, roughly even in
 * perceived lightness steps so equal log-error steps look equal. */
static void ramp(double u, float rgb[3])
{
    static const float stops[5][3] = {{0.16f, 0.20f, 0.65f},
                                      {0.15f, 0.55f, 0.90f},
                                      {0.20f, 0.78f, 0.40f},
                                      {0.98f, 0.85f, 0.15f},
                                      {0.85f, 0.10f, 0.10f}};
    double s = u * 4.0;
    int i = s >= 4.0 ? 3 : (int)s;
    float f = (float)(s - i);
    for (int c = 0; c < 3; c++)
        rgb[c] = cdl_srgb_decode(stops[i][c] + f * (stops[i + 1][c] - stops[i][c]));
}

int cdl_image_heatmap(const cdl_image *test, const cdl_image *ref,
                      cdl_image *out, cdl_error *err)
{
    if (same_size(test, ref, err))
        return CDL_ERR_INPUT;
    int status = cdl_image_alloc(out, test->width, test->height, err);
    if (status)
        return status;
    size_t npix = (size_t)test->width * test->height;
    for (size_t p = 0; p < npix; p++) {
        double e = pixel_rel(test->rgb + 3 * p, ref->rgb + 3 * p);
        float *o = out->rgb + 3 * p;
        if (!isfinite(e)) {
            o[0] = o[1] = o[2] = 1.0f;
            continue;
        }
        double u = e > 0 ? (log10(e) + 4.0) / 4.0 : 0.0; /* 1e-4..1 -> 0..1 */
        ramp(u < 0 ? 0 : u > 1 ? 1 : u, o);
    }
    return 0;
}

/* Ratios of block means (blocks with a dark or non-finite ratio left
 * out) into a new array; *n their count. NULL on bad input. */
static double *block_ratios(const cdl_image *test, const cdl_image *ref, int bs, size_t *count)
{
    if (bs < 1 || same_size(test, ref, NULL))
        return NULL;
    int w = test->width, h = test->height;
    size_t nbx = (w + bs - 1) / bs, nby = (h + bs - 1) / bs, n = 0;
    double *ratios = malloc(nbx * nby * sizeof *ratios);
    if (!ratios)
        return NULL;
    for (int by = 0; by < h; by += bs)
        for (int bx = 0; bx < w; bx += bs) {
            double st = 0, sr = 0;
            int cnt = 0;
            for (int y = by; y < by + bs && y < h; y++)
                for (int x = bx; x < bx + bs && x < w; x++)
                    for (int c = 0; c < 3; c++, cnt++) {
                        size_t i = 3 * ((size_t)y * w + x) + c;
                        st += test->rgb[i];
                        sr += ref->rgb[i];
                    }
            double ratio = st / sr;
            if (sr / cnt >= 1e-6 && isfinite(ratio))
                ratios[n++] = ratio;
        }
    *count = n;
    return ratios;
}

double cdl_image_block_median_ratio(const cdl_image *test,
                                    const cdl_image *ref, int bs)
{
    size_t n;
    double *ratios = block_ratios(test, ref, bs, &n);
    if (!ratios)
        return NAN;
    double med = NAN;
    if (n > 0) {
        qsort(ratios, n, sizeof *ratios, cmp_double);
        med = n % 2 ? ratios[n / 2] : 0.5 * (ratios[n / 2 - 1] + ratios[n / 2]);
    }
    free(ratios);
    return med;
}

double cdl_image_block_rms_dev(const cdl_image *test, const cdl_image *ref, int bs)
{
    size_t n;
    double *ratios = block_ratios(test, ref, bs, &n), s = 0.0;
    if (!ratios)
        return NAN;
    for (size_t i = 0; i < n; i++)
        s += (ratios[i] - 1.0) * (ratios[i] - 1.0);
    free(ratios);
    return n ? sqrt(s / (double)n) : NAN;
}
