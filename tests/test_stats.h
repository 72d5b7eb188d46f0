/* Shared helpers of the statistical tests: the BSDF tests (test_bsdf.c,
 * test_microfacet.c) and the light tests (test_light.c) include this header.
 *
 *  - check(): prints "<message> ok" / "<message> FAIL", counts checks and
 *    failures;
 *  - double precision vectors (dvec) and orthonormal frames (dframe), to
 *    compute references independently of the renderer's float cdl_vec3;
 *  - rel_err();
 *  - the chi-square test: regularized incomplete gamma gamma_q, Pearson's
 *    test chi2_test with pooling of low-expected bins, the Sidak-corrected
 *    threshold P_MIN, and test_gamma, the self-test of gamma_q;
 *  - for the BSDF tests: adaptive Gauss-Legendre quadrature of pdf and
 *    f |cos| over (cos theta, phi) rectangles (integrate_cell), the sphere
 *    binning NC x NP, the common geometric normal and the angle-form
 *    dielectric Fresnel reference.
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

#include "core/rng.h"
#include "core/vec.h"
#include "scene/bsdf.h"

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

/* ---- BSDF test machinery (test_bsdf.c, test_microfacet.c) ------------- */

#define DEG (PI_D / 180.0)

/* Binning of the sphere for the chi-square tests, and tolerances shared by
 * the opaque and microfacet tests. */
#define NC 10 /* cos theta bins over [-1, 1] */
#define NP 20 /* phi bins */
#define ZERO_HITS_MAX 20 /* slivers of support between quadrature nodes */
#define COS_ABS_ERR 1e-6 /* float rounding of cos(wi, n) after a change of frame */

/* ---- adaptive quadrature over (cos theta, phi) rectangles -------------- */

/* Integrand: [0] = pdf(wo, wi), [1] = f(wo, wi).x |cos(wi, shading n)|
 * (transport mode adj1), [2] the same for a second BSDF b2 (mode adj2),
 * [3] for a third b3 (mode adj2). */
#define NQ 4
typedef struct integ {
    const cdl_bsdf *b;
    cdl_vec3 wo;
    dframe fr;       /* frame of the (cos theta, phi) coordinates */
    int has_lobe;    /* force refinement around a narrow lobe */
    dvec lobe;
    double sigma;    /* angular width of the lobe */
    int albedo;      /* also integrate f |cos| */
    long evals;
    int adj1, adj2;
    const cdl_bsdf *b2, *b3; /* or NULL */
    double tol_abs, tol_rel; /* 0: TOL_ABS, TOL_REL */
} integ;

#define TOL_ABS 3e-8
#define TOL_REL 1e-5
#define MAX_DEPTH 8
#define MIN_DEPTH 1 /* every bin gets at least 4x4 cells of 4x4 nodes */

static TS_UNUSED const double gl_x[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                               0.8611363115940526};
static TS_UNUSED const double gl_w[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                               0.3478548451374538};

static TS_UNUSED void integrand(integ *g, double c, double phi, double out[NQ])
{
    cdl_vec3 wi = to_f(dframe_dir(&g->fr, c, phi));
    g->evals++;
    out[0] = cdl_bsdf_pdf(g->b, g->wo, wi);
    out[1] = out[2] = out[3] = 0.0;
    if (g->albedo) {
        cdl_vec3 f = cdl_bsdf_eval(g->b, g->wo, wi, g->adj1);
        out[1] = f.x * fabs(cdl_dot(wi, g->b->frame.n));
        if (g->b2) {
            f = cdl_bsdf_eval(g->b2, g->wo, wi, g->adj2);
            out[2] = f.x * fabs(cdl_dot(wi, g->b2->frame.n));
        }
        if (g->b3) {
            f = cdl_bsdf_eval(g->b3, g->wo, wi, g->adj2);
            out[3] = f.x * fabs(cdl_dot(wi, g->b3->frame.n));
        }
    }
}

static TS_UNUSED void gl_cell(integ *g, double c0, double c1, double p0, double p1, double out[NQ])
{
    double cm = 0.5 * (c0 + c1), ch = 0.5 * (c1 - c0), pm = 0.5 * (p0 + p1), ph = 0.5 * (p1 - p0);
    for (int k = 0; k < NQ; k++)
        out[k] = 0.0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double v[NQ];
            integrand(g, cm + ch * gl_x[i], pm + ph * gl_x[j], v);
            for (int k = 0; k < NQ; k++)
                out[k] += gl_w[i] * gl_w[j] * v[k];
        }
    for (int k = 0; k < NQ; k++)
        out[k] *= ch * ph;
}

/* Whether a cell is too coarse for the lobe: angular radius above half the
 * lobe width and the lobe axis within a few widths of the cell. */
static TS_UNUSED int near_lobe(const integ *g, double c0, double c1, double p0, double p1)
{
    if (!g->has_lobe)
        return 0;
    double cm = 0.5 * (c0 + c1), pm = 0.5 * (p0 + p1);
    dvec ctr = dframe_dir(&g->fr, cm, pm);
    double cs[2] = {c0, c1}, ps[3] = {p0, pm, p1}, rad = 0.0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 3; j++)
            rad = fmax(rad, dangle(ctr, dframe_dir(&g->fr, cs[i], ps[j])));
    return rad > 0.5 * g->sigma && dangle(ctr, g->lobe) < rad + 6.0 * g->sigma;
}

static TS_UNUSED void adapt(integ *g, double c0, double c1, double p0, double p1, const double whole[NQ],
                  int depth, double acc[NQ])
{
    double cm = 0.5 * (c0 + c1), pm = 0.5 * (p0 + p1);
    double q[4][NQ], sum[NQ] = {0.0};
    double cc[4][2] = {{c0, cm}, {c0, cm}, {cm, c1}, {cm, c1}};
    double pp[4][2] = {{p0, pm}, {pm, p1}, {p0, pm}, {pm, p1}};
    for (int k = 0; k < 4; k++) {
        gl_cell(g, cc[k][0], cc[k][1], pp[k][0], pp[k][1], q[k]);
        for (int i = 0; i < NQ; i++)
            sum[i] += q[k][i];
    }
    int done = depth >= MAX_DEPTH;
    if (!done && depth >= MIN_DEPTH) {
        done = 1;
        double ta = g->tol_abs > 0.0 ? g->tol_abs : TOL_ABS, tr = g->tol_rel > 0.0 ? g->tol_rel : TOL_REL;
        for (int i = 0; i < NQ; i++)
            if (fabs(sum[i] - whole[i]) > fmax(ta, tr * fabs(sum[i])))
                done = 0;
        if (done && near_lobe(g, c0, c1, p0, p1))
            done = 0;
    }
    if (done) {
        for (int i = 0; i < NQ; i++)
            acc[i] += sum[i];
        return;
    }
    for (int k = 0; k < 4; k++)
        adapt(g, cc[k][0], cc[k][1], pp[k][0], pp[k][1], q[k], depth + 1, acc);
}

static TS_UNUSED void integrate_cell(integ *g, double c0, double c1, double p0, double p1, double out[NQ])
{
    double whole[NQ];
    gl_cell(g, c0, c1, p0, p1, whole);
    for (int i = 0; i < NQ; i++)
        out[i] = 0.0;
    adapt(g, c0, c1, p0, p1, whole, 0, out);
}

/* The geometric normal of every test: deliberately not axis aligned. */
static TS_UNUSED dvec geo_normal(void) { return dnorm(dv(0.3, -0.5, 0.8)); }

/* Direction at polar angle theta from n, azimuth phi (in n's frame). */
static TS_UNUSED dvec polar(const dframe *f, double theta, double phi)
{
    return dframe_dir(f, cos(theta), phi);
}

/* Fresnel for unpolarized light in the angle form (independent of the
 * library's): rs = -sin(ti - tt) / sin(ti + tt), rp = tan(ti - tt) / tan(ti + tt). */
static TS_UNUSED double fresnel_ref(double ti, double eta_i, double eta_t)
{
    double st = eta_i / eta_t * sin(ti);
    if (st >= 1.0)
        return 1.0;
    double tt = asin(st);
    if (ti < 1e-9) {
        double r = (eta_i - eta_t) / (eta_i + eta_t);
        return r * r;
    }
    double rs = sin(ti - tt) / sin(ti + tt), rp = tan(ti - tt) / tan(ti + tt);
    return 0.5 * (rs * rs + rp * rp);
}

/* A uniform direction on the sphere (float, as the BSDFs take them). */
static TS_UNUSED cdl_vec3 random_sphere_dir(cdl_rng *rng)
{
    float z = 2.0f * cdl_rng_float(rng) - 1.0f, ph = 2.0f * CDL_PI * cdl_rng_float(rng);
    float rr = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return cdl_v3(rr * cosf(ph), rr * sinf(ph), z);
}

#endif
