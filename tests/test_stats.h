/* Shared helpers of the statistical tests: the BSDF tests (test_bsdf.c) and
 * the light tests (test_light.c) both include this header.
 *
 *  - check(): prints "<message> ok" / "<message> FAIL", counts checks and
 *    failures;
 *  - double precision vectors (dvec) and orthonormal frames (dframe), to
 *    compute references independently of the renderer's float cdl_vec3;
 *  - rel_err();
 *  - the chi-square test: regularized incomplete gamma gamma_q, Pearson's
 *    test chi2_test with pooling of low-expected bins, the Sidak-corrected
 *    threshold P_MIN, and test_gamma, the self-test of gamma_q.
 *
 * Everything is static (one copy per test program) and marked unused, so
 * -Wall -Wextra stays quiet in a file that uses only some of it. An
 * including file that runs chi-square tests defines N_CHI2, the number of
 * chi2_test calls it makes (P_MIN uses it; main checks chi2_count against
 * it). */
#ifndef CDL_TEST_STATS_H
#define CDL_TEST_STATS_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/vec.h"

#define TS_UNUSED __attribute__((unused))

#define PI_D 3.14159265358979323846

static TS_UNUSED int failures, checks;

/* Prints "<message> ok" or "<message> FAIL" and counts failures. */
static TS_UNUSED void check(int ok, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    printf(ok ? " ok\n" : " FAIL\n");
    checks++;
    if (!ok)
        failures++;
}

/* ---- double precision vectors ------------------------------------------ */

typedef struct dvec {
    double x, y, z;
} dvec;

static TS_UNUSED dvec dv(double x, double y, double z) { return (dvec){x, y, z}; }
static TS_UNUSED dvec dadd(dvec a, dvec b) { return dv(a.x + b.x, a.y + b.y, a.z + b.z); }
static TS_UNUSED dvec dsub(dvec a, dvec b) { return dv(a.x - b.x, a.y - b.y, a.z - b.z); }
static TS_UNUSED dvec dscale(dvec a, double s) { return dv(a.x * s, a.y * s, a.z * s); }
static TS_UNUSED double ddot(dvec a, dvec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static TS_UNUSED dvec dcross(dvec a, dvec b)
{
    return dv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static TS_UNUSED double dlen(dvec a) { return sqrt(ddot(a, a)); }
static TS_UNUSED dvec dnorm(dvec a) { return dscale(a, 1.0 / dlen(a)); }
static TS_UNUSED dvec from_f(cdl_vec3 a) { return dv(a.x, a.y, a.z); }
static TS_UNUSED cdl_vec3 to_f(dvec a) { return cdl_v3((float)a.x, (float)a.y, (float)a.z); }
/* Angle between two directions, accurate near 0 and pi. */
static TS_UNUSED double dangle(dvec a, dvec b)
{
    return atan2(sqrt(ddot(dcross(a, b), dcross(a, b))), ddot(a, b));
}

typedef struct dframe {
    dvec t, b, n;
} dframe;

/* Orthonormal frame (t, b, n) around the unit vector n. */
static TS_UNUSED dframe dframe_from(dvec n)
{
    dframe f;
    f.n = n;
    dvec a = fabs(n.x) < 0.7 ? dv(1, 0, 0) : dv(0, 1, 0);
    f.t = dnorm(dsub(a, dscale(n, ddot(a, n))));
    f.b = dcross(n, f.t);
    return f;
}
/* Direction of cos theta c and azimuth phi in a frame. */
static TS_UNUSED dvec dframe_dir(const dframe *f, double c, double phi)
{
    double s = sqrt(fmax(0.0, 1.0 - c * c));
    return dadd(dadd(dscale(f->t, s * cos(phi)), dscale(f->b, s * sin(phi))), dscale(f->n, c));
}
/* (cos theta, phi in [0, 2 pi)) of a direction in a frame. */
static TS_UNUSED void dframe_coords(const dframe *f, dvec w, double *c, double *phi)
{
    *c = ddot(w, f->n);
    double p = atan2(ddot(w, f->b), ddot(w, f->t));
    *phi = p < 0.0 ? p + 2.0 * PI_D : p;
}

static TS_UNUSED double rel_err(double a, double b)
{
    double d = fabs(a - b), m = fmax(fabs(a), fabs(b));
    return m > 0.0 ? d / m : 0.0;
}

/* ---- chi-square --------------------------------------------------------- */

/* Significance of the chi-square tests: 1% for the whole program,
 * Sidak-corrected over its N_CHI2 tests (N_CHI2 defined by the including
 * file). Seeds are fixed, so a run never flakes; the correction keeps a
 * correct implementation passing with probability 0.99 even when another
 * compiler or -march changes the float bits and so the samples. Real
 * defects give p-values of ~0. */
#define FAMILY_ALPHA 0.01
#define P_MIN (1.0 - pow(1.0 - FAMILY_ALPHA, 1.0 / N_CHI2))
static TS_UNUSED int chi2_count; /* chi2_test calls so far */

/* Regularized upper incomplete gamma Q(a, x) (Numerical Recipes 6.2). */
static TS_UNUSED double gamma_q(double a, double x)
{
    if (!(a > 0.0) || x < 0.0)
        return NAN;
    if (x == 0.0)
        return 1.0;
    double lpre = -x + a * log(x) - lgamma(a);
    if (x < a + 1.0) {
        double ap = a, del = 1.0 / a, sum = del;
        for (int n = 0; n < 100000; n++) {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if (fabs(del) < fabs(sum) * 1e-16)
                break;
        }
        return fmax(0.0, 1.0 - sum * exp(lpre));
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - a, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < tiny)
            d = tiny;
        c = b + an / c;
        if (fabs(c) < tiny)
            c = tiny;
        d = 1.0 / d;
        double del = d * c;
        h *= del;
        if (fabs(del - 1.0) < 1e-16)
            break;
    }
    return exp(lpre) * h;
}

typedef struct chi2_result {
    double stat, p;
    int dof;
    double zero_hits; /* samples in bins of expected count 0 */
} chi2_result;

static TS_UNUSED const double *sort_key;
static TS_UNUSED int by_key(const void *a, const void *b)
{
    double x = sort_key[*(const int *)a], y = sort_key[*(const int *)b];
    return x < y ? -1 : x > y;
}

/* Pearson's test; bins expecting fewer than min_exp are pooled into one
 * bin, itself merged into the smallest regular bin if still too small.
 * Bins where the expected count is 0 (for the BSDFs: the quadrature found
 * no mass at all; a sliver of the support may escape every quadrature
 * node) are pooled too; zero_hits counts their samples, and a caller for
 * which those bins must stay empty checks zero_hits == 0. The p-value is 0
 * only when samples fell in bins and no bin expected any. Samples where a
 * BSDF's pdf really is 0 are caught one by one by the consistency checks
 * (sample pdf > 0 and equal to cdl_bsdf_pdf). Counts the call in
 * chi2_count. */
static TS_UNUSED chi2_result chi2_test(const double *obs, const double *expd, int n, double min_exp)
{
    chi2_result r = {0.0, 1.0, 0, 0.0};
    int *idx = malloc(sizeof(int) * (size_t)n);
    for (int i = 0; i < n; i++)
        idx[i] = i;
    sort_key = expd;
    qsort(idx, (size_t)n, sizeof(int), by_key);
    double po = 0.0, pe = 0.0;
    int nb = 0;
    for (int k = 0; k < n; k++) {
        double o = obs[idx[k]], e = expd[idx[k]];
        if (e <= 0.0)
            r.zero_hits += o;
        if (e < min_exp) {
            po += o;
            pe += e;
            continue;
        }
        if ((pe > 0.0 || po > 0.0) && pe < min_exp) {
            o += po;
            e += pe;
            po = pe = 0.0;
        }
        r.stat += (o - e) * (o - e) / e;
        nb++;
    }
    if (pe > 0.0) {
        r.stat += (po - pe) * (po - pe) / pe;
        nb++;
    } else if (po > 0.0) {
        r.p = 0.0; /* samples and nowhere any expected mass */
    }
    free(idx);
    r.dof = nb - 1;
    chi2_count++;
    if (r.p > 0.0)
        r.p = r.dof >= 1 ? gamma_q(0.5 * r.dof, 0.5 * r.stat) : 1.0;
    return r;
}

/* Self-test of gamma_q against closed forms: Q(1/2, x) = erfc(sqrt x) and
 * Q(1, x) = exp(-x); with full also Q(5, x) = exp(-x) sum_{k<5} x^k/k! and
 * the p-value of the 5% quantile of chi2 with 1 dof (an extra check). The
 * BSDF test runs the full form, the light test the short one; each prints
 * its own message. */
static TS_UNUSED void test_gamma(int full)
{
    double worst = 0.0;
    int na = full ? 3 : 2;
    for (double x = 0.01; x < 60.0; x *= 1.37) {
        double e5 = 0.0, term = 1.0;
        for (int k = 0; k < 5; k++) {
            e5 += term;
            term *= x / (k + 1);
        }
        e5 *= exp(-x);
        double refs[3] = {erfc(sqrt(x)), exp(-x), e5}, as[3] = {0.5, 1.0, 5.0};
        for (int i = 0; i < na; i++) {
            double q = gamma_q(as[i], x);
            double err = fabs(q - refs[i]) / fmax(refs[i], 1e-300);
            if (refs[i] > 1e-250 && err > worst)
                worst = err;
        }
    }
    if (!full) {
        check(worst < 1e-9,
              "gamma_q against erfc(sqrt x) and exp(-x): max relative error %.2e (< 1e-9)", worst);
        return;
    }
    check(worst < 1e-9, "gamma_q against closed forms: max relative error %.2e (< 1e-9)", worst);
    double p = gamma_q(0.5, 3.841458820694124 / 2.0);
    check(fabs(p - 0.05) < 1e-9, "chi2 p-value of 3.8415 with 1 dof: %.9f (0.05)", p);
}

#endif
