#include "film/filter.h"

#include <math.h>
#include <string.h>

#define NB CDL_FILTER_BINS

void cdl_filter_box(cdl_filter *f)
{
    memset(f, 0, sizeof *f);
    f->type = CDL_FILTER_BOX;
    f->radius[0] = f->radius[1] = 0.5f;
}

static double sinc(double x)
{
    double t = CDL_PI * x;
    return fabs(t) < 1e-6 ? 1.0 - t * t / 6.0 : sin(t) / t;
}

static double profile(const cdl_filter *f, int axis, double x)
{
    double r = f->radius[axis], ax = fabs(x);
    if (ax > r)
        return 0.0;
    switch (f->type) {
    case CDL_FILTER_BOX:
        return 1.0;
    case CDL_FILTER_TENT:
        return 1.0 - ax / r;
    case CDL_FILTER_GAUSSIAN: /* the tail beyond the radius subtracted, as Mitsuba 3 and pbrt */
        return fmax(0.0, exp(-f->p0 * ax * ax) - exp(-f->p0 * r * r));
    case CDL_FILTER_MITCHELL: { /* Mitchell & Netravali 1988 on [0, 2], stretched to the radius */
        double t = 2.0 * ax / r, t2 = t * t, t3 = t2 * t, B = f->p0, C = f->p1;
        if (t < 1.0)
            return ((12.0 - 9.0 * B - 6.0 * C) * t3 + (-18.0 + 12.0 * B + 6.0 * C) * t2 + (6.0 - 2.0 * B)) / 6.0;
        return ((-B - 6.0 * C) * t3 + (6.0 * B + 30.0 * C) * t2 + (-12.0 * B - 48.0 * C) * t + (8.0 * B + 24.0 * C)) /
               6.0;
    }
    case CDL_FILTER_LANCZOS:
        return sinc(x) * sinc(x / f->p0);
    }
    return 0.0;
}

float cdl_filter_eval(const cdl_filter *f, int axis, float x)
{
    return (float)profile(f, axis, (double)x);
}

int cdl_filter_init(cdl_filter *f, cdl_filter_type type, float rx, float ry, float p0, float p1, int clip)
{
    cdl_filter_box(f);
    if (!(rx > 0.0f && rx <= 16.0f && ry > 0.0f && ry <= 16.0f) || !isfinite(p0) || !isfinite(p1) ||
        (type == CDL_FILTER_GAUSSIAN && !(p0 > 0.0f)) || (type == CDL_FILTER_LANCZOS && !(p0 > 0.0f)))
        return -1;
    f->type = type;
    f->radius[0] = rx;
    f->radius[1] = ry;
    f->p0 = p0;
    f->p1 = p1;
    f->clip = clip;
    f->wide = !(type == CDL_FILTER_BOX && rx == 0.5f && ry == 0.5f);
    if (!f->wide)
        return 0;
    for (int a = 0; a < 2; a++) {
        double r = f->radius[a], h = 2.0 * r / NB, sa = 0.0, ss = 0.0, peak = 0.0;
        for (int k = 0; k < NB; k++)
            peak = fmax(peak, fabs(profile(f, a, -r + (k + 0.5) * h)));
        f->cabs[a][0] = f->csgn[a][0] = 0.0f;
        for (int k = 0; k < NB; k++) {
            /* Simpson's rule on 16 steps per bin; every bin keeps a little
             * probability so that no point where f != 0 is unreachable */
            double x0 = -r + k * h, ia = 0.0, is = 0.0, hs = h / 16.0;
            for (int j = 0; j <= 16; j++) {
                double v = profile(f, a, x0 + j * hs), c = (j == 0 || j == 16) ? 1.0 : (j % 2 ? 4.0 : 2.0);
                ia += c * fabs(v);
                is += c * v;
            }
            sa += ia * hs / 3.0 + 1e-6 * peak * h;
            ss += is * hs / 3.0;
            f->cabs[a][k + 1] = (float)sa;
            f->csgn[a][k + 1] = (float)ss;
        }
        if (!(ss > 0.0) || !(peak > 0.0)) {
            cdl_filter_box(f);
            return -1;
        }
    }
    return 0;
}

/* A cumulative table at offset x, linear within a bin. */
static double cum(const float *c, double r, double x)
{
    double t = (x + r) / (2.0 * r) * NB;
    if (t <= 0.0)
        return c[0];
    if (t >= NB)
        return c[NB];
    int k = (int)t;
    return c[k] + (t - k) * (c[k + 1] - c[k]);
}

/* One axis: an offset in [lo, hi] from the tabulated |f| and its weight
 * f / pdf / (integral of f over [lo, hi]). */
static float sample_axis(const cdl_filter *f, int a, double lo, double hi, float u, float *weight)
{
    double r = f->radius[a], h = 2.0 * r / NB;
    lo = fmax(lo, -r);
    hi = fmin(hi, r);
    const float *ca = f->cabs[a];
    double c0 = cum(ca, r, lo), c1 = cum(ca, r, hi), norm = cum(f->csgn[a], r, hi) - cum(f->csgn[a], r, lo);
    if (!(c1 > c0) || !(norm > 0.0)) {
        *weight = 0.0f;
        return 0.0f;
    }
    double t = c0 + (double)u * (c1 - c0);
    int k0 = 0, k1 = NB; /* ca[k0] <= t < ca[k1] */
    while (k1 - k0 > 1) {
        int m = (k0 + k1) / 2;
        if ((double)ca[m] <= t)
            k0 = m;
        else
            k1 = m;
    }
    double bin = (double)ca[k0 + 1] - (double)ca[k0];
    double x = -r + (k0 + (bin > 0.0 ? (t - ca[k0]) / bin : 0.5)) * h;
    x = fmin(fmax(x, lo), hi);
    double pdf = bin / h / (c1 - c0);
    *weight = pdf > 0.0 ? (float)(profile(f, a, x) / pdf / norm) : 0.0f;
    return (float)x;
}

void cdl_filter_sample_wide(const cdl_filter *f, int px, int py, int w, int h, float u1, float u2, float *x,
                            float *y, float *weight)
{
    double cx = px + 0.5, cy = py + 0.5, big = 1e30;
    float wx, wy;
    float ox = sample_axis(f, 0, f->clip ? -cx : -big, f->clip ? (double)w - cx : big, u1, &wx);
    float oy = sample_axis(f, 1, f->clip ? -cy : -big, f->clip ? (double)h - cy : big, u2, &wy);
    *x = (float)(cx + ox);
    *y = (float)(cy + oy);
    if (f->clip) { /* rounding must not carry a sample off the image */
        *x = fminf(fmaxf(*x, 0.0f), nextafterf((float)w, 0.0f));
        *y = fminf(fmaxf(*y, 0.0f), nextafterf((float)h, 0.0f));
    }
    *weight = wx * wy;
}

int cdl_filter_spread(const cdl_filter *f, float x, float y, int w, int h, int *pix, float *wt)
{
    if (!f || !f->wide) {
        int ix = (int)floorf(x), iy = (int)floorf(y);
        if (ix < 0 || iy < 0 || ix >= w || iy >= h)
            return 0;
        pix[0] = iy * w + ix;
        wt[0] = 1.0f;
        return 1;
    }
    float wx[33], wy[33];
    int q0[2], n[2];
    double sum[2];
    for (int a = 0; a < 2; a++) {
        double c = a ? y : x, r = f->radius[a];
        int lo = (int)ceil(c - r - 0.5), hi = (int)floor(c + r - 0.5);
        if (hi - lo + 1 > 33)
            hi = lo + 32;
        q0[a] = lo;
        n[a] = hi >= lo ? hi - lo + 1 : 0;
        sum[a] = 0.0;
        for (int i = 0; i < n[a]; i++) {
            float v = (float)profile(f, a, lo + i + 0.5 - c);
            (a ? wy : wx)[i] = v;
            sum[a] += v;
        }
    }
    if (!(sum[0] != 0.0) || !(sum[1] != 0.0))
        return 0;
    float norm = (float)(1.0 / (sum[0] * sum[1]));
    int m = 0;
    for (int j = 0; j < n[1]; j++) {
        int qy = q0[1] + j;
        if (qy < 0 || qy >= h || wy[j] == 0.0f)
            continue;
        for (int i = 0; i < n[0]; i++) {
            int qx = q0[0] + i;
            if (qx < 0 || qx >= w || wx[i] == 0.0f)
                continue;
            pix[m] = qy * w + qx;
            wt[m] = wx[i] * wy[j] * norm;
            m++;
        }
    }
    return m;
}
