/* Tests of light sampling (scene/light.c) and of the alias table used to
 * pick lights (core/alias.h).
 *
 * Triangle area light (skew triangle, radiance (1, 2, 3)), seen from a
 * receiver in front of it and one behind it:
 *  - sampled points lie on the triangle and are uniform (chi-square over
 *    barycentrics);
 *  - the solid-angle pdf of cdl_light_sample_li equals cdl_light_pdf_li
 *    and dist^2 / (cos_l area); cdl_light_pdf_li integrates to 1 over the
 *    directions from the receiver (rays intersected here); the estimate of
 *    irradiance matches the closed form for a polygon; nothing is sampled
 *    from behind;
 *  - cdl_light_sample_le: uniform origins, cosine directions, pdfs, power.
 * Point light: Li = I / d^2, delta, uniform emission, pdfs, power.
 * Alias table: chi-square of sampled frequencies, the exact distribution
 * over every float the renderer's RNG can produce, zero weights never
 * drawn, bad weight lists rejected.
 *
 * Deterministic seeds: the outcome never changes between runs. Returns 0
 * when every check passes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alias.h"
#include "core/rng.h"
#include "core/vec.h"
#include "scene/light.h"

#include "test_stats.h"

/* Chi-square tests in this program, for the Sidak correction of P_MIN
 * (test_stats.h). */
#define N_CHI2 5

/* cdl_light_pdf_li of the light point p seen from ref, whichever of its
 * two signatures scene/light.h declares: (l, ref, p), or (l, ref, wi,
 * dist) with wi and dist computed as cdl_light_sample_li does. Only the
 * branch matching the declaration is evaluated. */
typedef float (*pdf_li_by_point)(const cdl_light *, cdl_vec3, cdl_vec3);
typedef float (*pdf_li_by_dir)(const cdl_light *, cdl_vec3, cdl_vec3, float);

static float pdf_li_at(const cdl_light *l, cdl_vec3 ref, cdl_vec3 p)
{
    cdl_vec3 d = cdl_sub(p, ref);
    float dist = sqrtf(cdl_dot(d, d));
    cdl_vec3 wi = cdl_scale(d, 1.0f / dist);
    void (*fn)(void) = (void (*)(void))cdl_light_pdf_li;
    return _Generic(&cdl_light_pdf_li,
                    pdf_li_by_point: ((pdf_li_by_point)fn)(l, ref, p),
                    default: ((pdf_li_by_dir)fn)(l, ref, wi, dist));
}

/* ---- triangle light ------------------------------------------------------ */

#define NTRI 200000
#define NB 10 /* barycentric histogram: NB x NB cells over the unit square */

static cdl_light make_triangle(dvec p0, dvec p1, dvec p2, cdl_vec3 L)
{
    /* As scene.c builds them. */
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_TRIANGLE;
    l.p = to_f(p0);
    l.e1 = cdl_sub(to_f(p1), l.p);
    l.e2 = cdl_sub(to_f(p2), l.p);
    cdl_vec3 c = cdl_cross(l.e1, l.e2);
    float len = cdl_length(c);
    l.n = cdl_scale(c, 1.0f / len);
    l.area = 0.5f * len;
    l.L = L;
    return l;
}

/* Barycentrics (b1, b2) of p on the light's plane, and the distance to it. */
static void barycentrics(const cdl_light *l, dvec p, double *b1, double *b2, double *off)
{
    dvec e1 = from_f(l->e1), e2 = from_f(l->e2), d = dsub(p, from_f(l->p));
    double a11 = ddot(e1, e1), a12 = ddot(e1, e2), a22 = ddot(e2, e2);
    double r1 = ddot(d, e1), r2 = ddot(d, e2), det = a11 * a22 - a12 * a12;
    *b1 = (a22 * r1 - a12 * r2) / det;
    *b2 = (a11 * r2 - a12 * r1) / det;
    *off = fabs(ddot(d, dnorm(dcross(e1, e2))));
}

/* Expected share of an NB x NB cell of the unit square of (b1, b2) under
 * uniform sampling of the triangle b1 + b2 <= 1 (area 1/2). */
static double bary_cell_prob(int i, int j)
{
    if (i + j < NB - 1)
        return 2.0 / (NB * NB);
    if (i + j == NB - 1)
        return 1.0 / (NB * NB); /* cut in half by the diagonal */
    return 0.0;
}

static void bary_bin(double *hist, double b1, double b2)
{
    int i = (int)(b1 * NB), j = (int)(b2 * NB);
    i = i < 0 ? 0 : i >= NB ? NB - 1 : i;
    j = j < 0 ? 0 : j >= NB ? NB - 1 : j;
    /* A point a rounding error past the diagonal (the range check above
     * bounds how far) goes to the diagonal cell. */
    if (i + j > NB - 1) {
        if (i > j)
            i = NB - 1 - j;
        else
            j = NB - 1 - i;
    }
    hist[i * NB + j] += 1.0;
}

/* Solid angle integral of cos(w, nr) over a polygon seen from x (Lambert's
 * formula: half the sum over the edges of the angle they subtend times
 * the normal of the plane through x and the edge). */
static double polygon_cos_integral(const dvec *p, int n, dvec x, dvec nr)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        dvec a = dnorm(dsub(p[i], x)), b = dnorm(dsub(p[(i + 1) % n], x));
        double theta = acos(fmax(-1.0, fmin(1.0, ddot(a, b))));
        s += 0.5 * theta * ddot(dnorm(dcross(a, b)), nr);
    }
    return fabs(s);
}

/* Moller-Trumbore in double: distance along d to the triangle, or -1. */
static double intersect(dvec o, dvec d, dvec p0, dvec e1, dvec e2)
{
    dvec pv = dcross(d, e2);
    double det = ddot(e1, pv);
    if (fabs(det) < 1e-15)
        return -1.0;
    double inv = 1.0 / det;
    dvec tv = dsub(o, p0);
    double u = ddot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0)
        return -1.0;
    dvec qv = dcross(tv, e1);
    double v = ddot(d, qv) * inv;
    if (v < 0.0 || u + v > 1.0)
        return -1.0;
    double t = ddot(e2, qv) * inv;
    return t > 0.0 ? t : -1.0;
}

static void test_triangle(void)
{
    dvec p[3] = {dv(0.1, -0.2, 0.3), dv(1.3, 0.2, -0.1), dv(0.4, 1.1, 0.8)};
    cdl_light l = make_triangle(p[0], p[1], p[2], cdl_v3(1.0f, 2.0f, 3.0f));
    dvec n = from_f(l.n), ctr = dscale(dadd(dadd(p[0], p[1]), p[2]), 1.0 / 3.0);
    dvec e1 = from_f(l.e1), e2 = from_f(l.e2), p0 = from_f(l.p);
    double area = 0.5 * dlen(dcross(dsub(p[1], p[0]), dsub(p[2], p[0])));
    check(rel_err(l.area, area) < 1e-6, "triangle light: area %.6f (double %.6f)", l.area, area);

    /* Receiver in front (off the centroid axis) and behind. */
    dvec front = dadd(dadd(ctr, dscale(n, 0.3)), dscale(dnorm(dsub(p[1], ctr)), 0.2));
    dvec behind = dsub(ctr, dscale(n, 0.5));
    cdl_vec3 ref = to_f(front);

    /* ---- sample_li from the front receiver ---- */
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x11647ULL, 1);
    static double hist[NB * NB], expd[NB * NB];
    memset(hist, 0, sizeof hist);
    long fails = 0, bad_misc = 0;
    double max_bary = 0.0, max_off = 0.0, max_pdf_li = 0.0, max_pdf_geo = 0.0, max_dir = 0.0;
    double inv_area_sum = 0.0, irr[3] = {0, 0, 0}, irr2 = 0.0;
    dvec nr = dscale(n, -1.0); /* receiver facing the light */
    for (int s = 0; s < NTRI; s++) {
        float u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        cdl_light_sample ls = {0};
        if (!cdl_light_sample_li(&l, ref, u1, u2, &ls)) {
            fails++;
            continue;
        }
        dvec pp = from_f(ls.p);
        double b1, b2, off;
        barycentrics(&l, pp, &b1, &b2, &off);
        max_bary = fmax(max_bary, fmax(fmax(-b1, -b2), b1 + b2 - 1.0));
        max_off = fmax(max_off, off);
        bary_bin(hist, b1, b2);
        dvec d = dsub(pp, front);
        double dist = dlen(d);
        dvec w = dscale(d, 1.0 / dist);
        max_dir = fmax(max_dir, fmax(dlen(dsub(from_f(ls.wi), w)), fabs(ls.dist - dist) / dist));
        double cos_l = -ddot(w, n);
        double pdf_geo = dist * dist / (cos_l * area);
        max_pdf_geo = fmax(max_pdf_geo, rel_err(ls.pdf, pdf_geo));
        max_pdf_li = fmax(max_pdf_li, rel_err(ls.pdf, pdf_li_at(&l, ref, ls.p)));
        if (ls.delta || ls.Li.x != 1.0f || ls.Li.y != 2.0f || ls.Li.z != 3.0f || !(ls.pdf > 0.0f))
            bad_misc++;
        /* Area density of the same point: pdf_li cos_l / dist^2 = 1 / area. */
        inv_area_sum += 1.0 / (ls.pdf * cos_l / (dist * dist));
        double c = fmax(0.0, ddot(from_f(ls.wi), nr)) / ls.pdf;
        irr[0] += ls.Li.x * c;
        irr[1] += ls.Li.y * c;
        irr[2] += ls.Li.z * c;
        irr2 += c * c;
    }
    check(fails == 0, "triangle sample_li from the front: %ld of %d samples failed (0)", fails, NTRI);
    check(max_bary <= 1e-5 && max_off <= 1e-5,
          "triangle sample_li: points on the triangle: barycentrics outside [0,1] by at most %.2e, "
          "off the plane by at most %.2e (<= 1e-5)",
          max_bary, max_off);
    for (int i = 0; i < NB * NB; i++)
        expd[i] = bary_cell_prob(i / NB, i % NB) * (NTRI - fails);
    chi2_result r = chi2_test(hist, expd, NB * NB, 5.0);
    check(r.p >= P_MIN && r.zero_hits == 0,
          "triangle sample_li: barycentrics uniform: chi2 %.1f, dof %d, p-value %.4f (>= %.2g), %.0f "
          "samples outside the triangle",
          r.stat, r.dof, r.p, P_MIN, r.zero_hits);
    check(max_dir <= 1e-5, "triangle sample_li: wi and dist vs the sampled point: max error %.2e (<= 1e-5)",
          max_dir);
    check(max_pdf_li <= 1e-4,
          "triangle sample_li: pdf vs cdl_light_pdf_li of the same point: max relative error %.2e "
          "(<= 1e-4)",
          max_pdf_li);
    check(max_pdf_geo <= 1e-4,
          "triangle sample_li: pdf vs dist^2 / (cos_l area): max relative error %.2e (<= 1e-4)",
          max_pdf_geo);
    check(bad_misc == 0, "triangle sample_li: Li = (1,2,3), delta = 0, pdf > 0: %ld violations",
          bad_misc);
    double mean_inv = inv_area_sum / NTRI;
    check(rel_err(mean_inv, area) <= 1e-4,
          "triangle sample_li: mean of 1 / pdf_area %.6f vs area %.6f (relative 1e-4)", mean_inv,
          area);
    double ff = polygon_cos_integral(p, 3, front, nr);
    double sd = sqrt(fmax(0.0, irr2 / NTRI - (irr[0] / NTRI) * (irr[0] / NTRI)) / NTRI);
    int irr_ok = 1;
    for (int c = 0; c < 3; c++)
        if (fabs(irr[c] / NTRI - (c + 1) * ff) > fmax(5.0 * (c + 1) * sd, 0.0) + 1e-3 * (c + 1) * ff)
            irr_ok = 0;
    check(irr_ok,
          "triangle sample_li: irradiance estimate (%.5f, %.5f, %.5f) vs Lambert's polygon formula "
          "L * %.5f (within 5 sigma = %.5f per unit L)",
          irr[0] / NTRI, irr[1] / NTRI, irr[2] / NTRI, ff, 5.0 * sd);

    /* ---- the pdf integrates to 1 over the directions from the receiver ---- */
    const int G = 1000; /* G x G jittered directions, uniform over the sphere */
    double sum_f = 0.0, sum_b = 0.0;
    long hits_f = 0, hits_b = 0, nonzero_b = 0;
    cdl_rng_seed(&rng, 0x11647ULL, 2);
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            double z = 1.0 - 2.0 * (i + cdl_rng_float(&rng)) / G;
            double phi = 2.0 * PI_D * (j + cdl_rng_float(&rng)) / G;
            double rr = sqrt(fmax(0.0, 1.0 - z * z));
            dvec d = dv(rr * cos(phi), rr * sin(phi), z);
            double t = intersect(front, d, p0, e1, e2);
            if (t > 0.0) {
                hits_f++;
                sum_f += pdf_li_at(&l, ref, to_f(dadd(front, dscale(d, t))));
            }
            t = intersect(behind, d, p0, e1, e2);
            if (t > 0.0) {
                hits_b++;
                double pb = pdf_li_at(&l, to_f(behind), to_f(dadd(behind, dscale(d, t))));
                sum_b += pb;
                nonzero_b += pb != 0.0;
            }
        }
    double integral = 4.0 * PI_D * sum_f / ((double)G * G);
    check(fabs(integral - 1.0) <= 0.01,
          "triangle pdf_li from the front: integral over the sphere %.5f (1 within 1%%; %ld of %d "
          "jittered directions hit, solid angle %.4f sr)",
          integral, hits_f, G * G, 4.0 * PI_D * hits_f / ((double)G * G));
    check(hits_b > 0 && nonzero_b == 0,
          "triangle pdf_li from behind: %ld directions hit the back face, %ld with pdf != 0 "
          "(integral %.5f; 0)",
          hits_b, nonzero_b, 4.0 * PI_D * sum_b / ((double)G * G));

    /* ---- nothing is sampled from behind ---- */
    long ok_behind = 0;
    cdl_rng_seed(&rng, 0x11647ULL, 3);
    for (int s = 0; s < 10000; s++) {
        cdl_light_sample ls = {0};
        float u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        ok_behind += cdl_light_sample_li(&l, to_f(behind), u1, u2, &ls);
    }
    check(ok_behind == 0, "triangle sample_li from behind the emitting face: %ld of 10000 succeed (0)",
          ok_behind);

    /* ---- sample_le ---- */
    static double ohist[NB * NB], dhist[NB * 20], dexp[NB * 20];
    memset(ohist, 0, sizeof ohist);
    memset(dhist, 0, sizeof dhist);
    dframe nf = dframe_from(n);
    long le_fail = 0, le_misc = 0;
    double le_bary = 0.0, le_off = 0.0, le_pos = 0.0, le_dir = 0.0;
    cdl_rng_seed(&rng, 0x11647ULL, 4);
    for (int s = 0; s < NTRI; s++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = cdl_rng_float(&rng);
        cdl_light_emit e;
        if (!cdl_light_sample_le(&l, u[0], u[1], u[2], u[3], &e)) {
            le_fail++;
            continue;
        }
        double b1, b2, off;
        barycentrics(&l, from_f(e.p), &b1, &b2, &off);
        le_bary = fmax(le_bary, fmax(fmax(-b1, -b2), b1 + b2 - 1.0));
        le_off = fmax(le_off, off);
        bary_bin(ohist, b1, b2);
        dvec d = from_f(e.d);
        double c = ddot(d, n);
        if (c <= 0.0 || fabs(dlen(d) - 1.0) > 1e-5 || e.n.x != l.n.x || e.n.y != l.n.y ||
            e.n.z != l.n.z || e.Le.x != 1.0f || e.Le.y != 2.0f || e.Le.z != 3.0f)
            le_misc++;
        le_pos = fmax(le_pos, rel_err(e.pdf_pos, 1.0 / area));
        /* cos from the world direction: allow 1e-6 absolute for rounding. */
        le_dir = fmax(le_dir, fabs(e.pdf_dir - c / PI_D) / (1e-4 * c / PI_D + 1e-6 / PI_D));
        /* cos^2 theta is uniform for cosine-distributed directions. */
        double phi = atan2(ddot(d, nf.b), ddot(d, nf.t));
        phi = phi < 0.0 ? phi + 2.0 * PI_D : phi;
        int i = (int)(c * c * NB), j = (int)(phi / (2.0 * PI_D) * 20);
        i = i < 0 ? 0 : i >= NB ? NB - 1 : i;
        j = j < 0 ? 0 : j >= 20 ? 19 : j;
        dhist[i * 20 + j] += 1.0;
    }
    check(le_fail <= 2, "triangle sample_le: %ld of %d samples failed (<= 2: only u on the disk's rim)",
          le_fail, NTRI);
    check(le_bary <= 1e-5 && le_off <= 1e-5,
          "triangle sample_le: origins on the triangle: barycentrics outside [0,1] by at most %.2e, "
          "off the plane by at most %.2e (<= 1e-5)",
          le_bary, le_off);
    for (int i = 0; i < NB * NB; i++)
        expd[i] = bary_cell_prob(i / NB, i % NB) * (NTRI - le_fail);
    r = chi2_test(ohist, expd, NB * NB, 5.0);
    check(r.p >= P_MIN && r.zero_hits == 0,
          "triangle sample_le: origins uniform: chi2 %.1f, dof %d, p-value %.4f (>= %.2g)", r.stat,
          r.dof, r.p, P_MIN);
    for (int i = 0; i < NB * 20; i++)
        dexp[i] = (double)(NTRI - le_fail) / (NB * 20);
    r = chi2_test(dhist, dexp, NB * 20, 5.0);
    check(r.p >= P_MIN,
          "triangle sample_le: directions cosine-distributed about n: chi2 over (cos^2 theta, phi) "
          "%dx20 bins %.1f, dof %d, p-value %.4f (>= %.2g)",
          NB, r.stat, r.dof, r.p, P_MIN);
    check(le_misc == 0,
          "triangle sample_le: d unit and in front of n, n = light normal, Le = (1,2,3): %ld "
          "violations",
          le_misc);
    check(le_pos <= 1e-6, "triangle sample_le: pdf_pos vs 1/area: max relative error %.2e (<= 1e-6)",
          le_pos);
    check(le_dir <= 1.0, "triangle sample_le: pdf_dir vs cos/pi: max error %.3f of tolerance (1e-4 "
                         "relative + 1e-6/pi)",
          le_dir);
    cdl_vec3 pw = cdl_light_power(&l);
    double pw_err = fmax(rel_err(pw.x, PI_D * area), fmax(rel_err(pw.y, 2 * PI_D * area),
                                                          rel_err(pw.z, 3 * PI_D * area)));
    check(pw_err <= 1e-6, "triangle power (%.5f, %.5f, %.5f) vs pi * area * L: relative error %.2e",
          pw.x, pw.y, pw.z, pw_err);
}

/* ---- point light ------------------------------------------------------ */

static void test_point(void)
{
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_POINT;
    l.p = cdl_v3(0.3f, 0.7f, -0.2f);
    l.L = cdl_v3(2.0f, 3.0f, 4.0f);
    dvec pl = from_f(l.p);
    dvec refs[3] = {dv(1.5, -0.4, 0.9), dv(0.3, 0.7, 2.8), dv(-4.0, 2.0, -1.0)};
    for (int i = 0; i < 3; i++) {
        cdl_light_sample ls = {0};
        int ok = cdl_light_sample_li(&l, to_f(refs[i]), 0.3f, 0.6f, &ls);
        dvec d = dsub(pl, refs[i]);
        double d2 = ddot(d, d), dist = sqrt(d2);
        double e = fmax(rel_err(ls.Li.x, 2.0 / d2),
                        fmax(rel_err(ls.Li.y, 3.0 / d2), rel_err(ls.Li.z, 4.0 / d2)));
        double ed = fmax(dlen(dsub(from_f(ls.wi), dscale(d, 1.0 / dist))), rel_err(ls.dist, dist));
        check(ok && e <= 1e-5 && ed <= 1e-5 && ls.delta == 1 && ls.pdf == 1.0f &&
                  pdf_li_at(&l, to_f(refs[i]), l.p) == 0.0f,
              "point light at d=%.3f: Li (%.5f, %.5f, %.5f) vs I/d^2 (%.5f, %.5f, %.5f) rel err %.1e, "
              "wi/dist err %.1e, delta %d, pdf %g, pdf_li %g",
              dist, ls.Li.x, ls.Li.y, ls.Li.z, 2.0 / d2, 3.0 / d2, 4.0 / d2, e, ed, ls.delta, ls.pdf,
              pdf_li_at(&l, to_f(refs[i]), l.p));
    }
    static double hist[10 * 20], expd[10 * 20];
    memset(hist, 0, sizeof hist);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x9017ULL, 1);
    long bad = 0, fails = 0;
    const int N = 200000;
    for (int s = 0; s < N; s++) {
        float u[4];
        for (int k = 0; k < 4; k++)
            u[k] = cdl_rng_float(&rng);
        cdl_light_emit e;
        if (!cdl_light_sample_le(&l, u[0], u[1], u[2], u[3], &e)) {
            fails++;
            continue;
        }
        dvec d = from_f(e.d);
        if (fabs(dlen(d) - 1.0) > 1e-5 || e.pdf_pos != 1.0f ||
            rel_err(e.pdf_dir, 0.25 / PI_D) > 1e-6 || e.p.x != l.p.x || e.p.y != l.p.y ||
            e.p.z != l.p.z || e.Le.x != 2.0f || e.Le.y != 3.0f || e.Le.z != 4.0f)
            bad++;
        double phi = atan2(d.y, d.x);
        phi = phi < 0.0 ? phi + 2.0 * PI_D : phi;
        int i = (int)((d.z + 1.0) * 0.5 * 10), j = (int)(phi / (2.0 * PI_D) * 20);
        i = i < 0 ? 0 : i >= 10 ? 9 : i;
        j = j < 0 ? 0 : j >= 20 ? 19 : j;
        hist[i * 20 + j] += 1.0;
    }
    for (int i = 0; i < 200; i++)
        expd[i] = (double)(N - fails) / 200.0;
    chi2_result r = chi2_test(hist, expd, 200, 5.0);
    check(fails == 0 && r.p >= P_MIN,
          "point light sample_le: directions uniform on the sphere: chi2 over (z, phi) 10x20 bins "
          "%.1f, dof %d, p-value %.4f (>= %.2g), %ld failures",
          r.stat, r.dof, r.p, P_MIN, fails);
    check(bad == 0,
          "point light sample_le: |d| = 1, pdf_pos = 1, pdf_dir = 1/(4 pi), p = position, Le = I: "
          "%ld violations",
          bad);
    cdl_vec3 pw = cdl_light_power(&l);
    double e = fmax(rel_err(pw.x, 8 * PI_D), fmax(rel_err(pw.y, 12 * PI_D), rel_err(pw.z, 16 * PI_D)));
    check(e <= 1e-6, "point light power (%.5f, %.5f, %.5f) vs 4 pi I: relative error %.2e", pw.x,
          pw.y, pw.z, e);
}

/* ---- alias table ---------------------------------------------------------- */

/* cdl_alias_sample takes one uniform (slot and acceptance both from u * n);
 * a two-uniform form (u_slot, u_accept) is the fix proposed for its
 * precision. The tests run with either: only the branch matching the
 * declaration in core/alias.h is evaluated. */
typedef uint32_t (*alias_1u)(const cdl_alias *, float, float *);
typedef uint32_t (*alias_2u)(const cdl_alias *, float, float, float *);
#define ALIAS_TWO_UNIFORMS _Generic(&cdl_alias_sample, alias_1u: 0, default: 1)

static uint32_t alias_draw(const cdl_alias *a, float u_slot, float u_accept, float *pmf)
{
    void (*fn)(void) = (void (*)(void))cdl_alias_sample;
    return _Generic(&cdl_alias_sample,
                    alias_1u: ((alias_1u)fn)(a, u_slot, pmf),
                    default: ((alias_2u)fn)(a, u_slot, u_accept, pmf));
}

/* The distribution the table defines: slot i taken with 1/n, then i with
 * prob[i], alias[i] otherwise. */
static double table_error(const cdl_alias *a)
{
    double *p = calloc(a->n, sizeof(double)), worst = 0.0;
    for (uint32_t i = 0; i < a->n; i++) {
        p[i] += a->prob[i] / a->n;
        p[a->alias[i]] += (1.0 - a->prob[i]) / a->n;
    }
    for (uint32_t i = 0; i < a->n; i++)
        worst = fmax(worst, fabs(p[i] - a->pmf[i]));
    free(p);
    return worst;
}

/* The distribution cdl_alias_sample really draws from with the renderer's
 * uniforms (cdl_rng_float, cdl_sampler_1d: multiples of 2^-24 in [0, 1)),
 * computed exactly: with one uniform, by drawing with each of the 2^24
 * values once; with two, for each u_slot the result switches once from
 * the slot's entry to its alias as u_accept grows, found by bisection.
 * Reports the largest relative deviation from the pmf over the entries of
 * pmf >= min_pmf, the number of entries with pmf > 0 never drawn, and the
 * total variation distance. */
static void exact_distribution(const cdl_alias *a, double min_pmf, double *max_rel, long *never,
                               double *tv, long *zero_drawn)
{
    const uint32_t M = 1u << 24;
    const float last = (float)(M - 1) * 0x1p-24f;
    double *cnt = calloc(a->n, sizeof(double)); /* in units of 2^-24 */
    if (!ALIAS_TWO_UNIFORMS) {
        for (uint32_t k = 0; k < M; k++)
            cnt[alias_draw(a, (float)k * 0x1p-24f, 0.0f, NULL)] += 1.0;
    } else {
        uint32_t k = 0;
        while (k < M) {
            float u = (float)k * 0x1p-24f;
            uint32_t lo = alias_draw(a, u, 0.0f, NULL), hi = alias_draw(a, u, last, NULL);
            uint32_t run = 1; /* u_slot values drawing the same pair */
            while (k + run < M) {
                float v = (float)(k + run) * 0x1p-24f;
                if (alias_draw(a, v, 0.0f, NULL) != lo || alias_draw(a, v, last, NULL) != hi)
                    break;
                run++;
            }
            uint32_t m = M; /* first u_accept index drawing hi */
            if (lo != hi) {
                uint32_t l = 0, r = M - 1;
                while (l < r) {
                    uint32_t mid = l + (r - l) / 2;
                    if (alias_draw(a, u, (float)mid * 0x1p-24f, NULL) == lo)
                        l = mid + 1;
                    else
                        r = mid;
                }
                m = l;
            }
            cnt[lo] += (double)run * m * 0x1p-24;
            cnt[hi] += (double)run * (M - m) * 0x1p-24;
            k += run;
        }
    }
    *max_rel = 0.0;
    *never = 0;
    *tv = 0.0;
    *zero_drawn = 0;
    for (uint32_t i = 0; i < a->n; i++) {
        double q = cnt[i] * 0x1p-24, p = a->pmf[i];
        *tv += 0.5 * fabs(q - p);
        if (p == 0.0 && q > 0.0)
            (*zero_drawn)++;
        if (p > 0.0 && q == 0.0)
            (*never)++;
        if (p >= min_pmf)
            *max_rel = fmax(*max_rel, fabs(q - p) / p);
    }
    free(cnt);
}

static void test_alias(void)
{
    const float w[5] = {1.0f, 0.0f, 3.0f, 6.0f, 0.5f};
    cdl_alias a;
    int rc = cdl_alias_build(&a, w, 5);
    check(rc == 0 && a.n == 5, "alias build {1, 0, 3, 6, 0.5}: rc %d, n %u", rc, a.n);
    if (rc)
        return;
    double pmf_err = 0.0;
    for (int i = 0; i < 5; i++)
        pmf_err = fmax(pmf_err, fabs(a.pmf[i] - w[i] / 10.5));
    check(pmf_err <= 1e-7, "alias pmf vs w / sum: max error %.2e (<= 1e-7)", pmf_err);
    double te = table_error(&a);
    check(te <= 1e-6, "alias table (prob, alias) reproduces the pmf: max error %.2e (<= 1e-6)", te);

    const int N = 1000000;
    double obs[5] = {0}, expd[5];
    long bad_pmf = 0;
    cdl_rng rng;
    cdl_rng_seed(&rng, 0xa11a5ULL, 1);
    for (int s = 0; s < N; s++) {
        float pm = -1.0f;
        float us = cdl_rng_float(&rng), ua = cdl_rng_float(&rng);
        uint32_t k = alias_draw(&a, us, ua, &pm);
        if (k >= 5) {
            bad_pmf++;
            continue;
        }
        obs[k] += 1.0;
        if (pm != a.pmf[k])
            bad_pmf++;
    }
    for (int i = 0; i < 5; i++)
        expd[i] = N * (double)w[i] / 10.5;
    chi2_result r = chi2_test(obs, expd, 5, 5.0);
    check(r.p >= P_MIN && r.dof == 3,
          "alias sampling {1, 0, 3, 6, 0.5}: frequencies (%.5f %.5f %.5f %.5f %.5f) vs pmf "
          "(%.5f %.5f %.5f %.5f %.5f): chi2 %.2f, dof %d, p-value %.4f (>= %.2g)",
          obs[0] / N, obs[1] / N, obs[2] / N, obs[3] / N, obs[4] / N, expd[0] / N, expd[1] / N,
          expd[2] / N, expd[3] / N, expd[4] / N, r.stat, r.dof, r.p, P_MIN);
    check(obs[1] == 0.0 && bad_pmf == 0,
          "alias sampling: zero-weight entry drawn %.0f times (0); returned pmf wrong or index out "
          "of range %ld times (0)",
          obs[1], bad_pmf);
    double mr, tv;
    long never, zd;
    exact_distribution(&a, 0.0, &mr, &never, &tv, &zd);
    check(mr <= 1e-5 && zd == 0 && never == 0,
          "alias sampling over all 2^24 RNG floats {1, 0, 3, 6, 0.5} (%s): max relative deviation "
          "from the pmf %.2e (<= 1e-5), zero weights drawn %ld, positive weights never drawn %ld",
          ALIAS_TWO_UNIFORMS ? "two uniforms" : "one uniform", mr, zd, never);
    cdl_alias_free(&a);
    check(a.prob == NULL && a.alias == NULL && a.pmf == NULL && a.n == 0,
          "alias free resets the table");

    /* Many lights: the same exact distribution for larger tables. */
    struct {
        const char *name;
        uint32_t n;
        int kind;
    } big[] = {
        {"1000 weights uniform in [0, 1), every 7th 0", 1000, 0},
        {"10000 weights log-uniform in [1e-3, 1]", 10000, 1},
        {"131072 weights alternating 1, 0.3", 131072, 2},
    };
    for (size_t t = 0; t < sizeof big / sizeof big[0]; t++) {
        uint32_t n = big[t].n;
        float *bw = malloc(sizeof(float) * n);
        cdl_rng_seed(&rng, 0xa11a5ULL, 10 + t);
        for (uint32_t i = 0; i < n; i++) {
            float u = cdl_rng_float(&rng);
            bw[i] = big[t].kind == 0 ? (i % 7 == 3 ? 0.0f : u)
                    : big[t].kind == 1 ? powf(10.0f, -3.0f * u)
                                       : (i & 1 ? 1.0f : 0.3f);
        }
        rc = cdl_alias_build(&a, bw, n);
        check(rc == 0, "alias build %s: rc %d", big[t].name, rc);
        if (!rc) {
            te = table_error(&a);
            check(te <= 1e-6 / n * 10,
                  "alias table %s reproduces the pmf: max error %.2e (<= %.1e)", big[t].name, te,
                  1e-6 / n * 10);
            exact_distribution(&a, 0.0, &mr, &never, &tv, &zd);
            check(mr <= 1e-2 && zd == 0 && never == 0,
                  "alias sampling over all 2^24 RNG floats, %s: max relative deviation from the pmf "
                  "%.2e (<= 1e-2), total variation %.2e, zero weights drawn %ld, positive weights "
                  "never drawn %ld",
                  big[t].name, mr, tv, zd, never);
            cdl_alias_free(&a);
        }
        free(bw);
    }

    /* Rejected weight lists; the table is left empty and freeable. */
    const float zeros[3] = {0.0f, 0.0f, 0.0f}, neg[3] = {1.0f, -0.5f, 2.0f};
    const float nan_w[3] = {1.0f, NAN, 2.0f}, inf_w[3] = {1.0f, INFINITY, 2.0f};
    const float *bad_lists[4] = {zeros, neg, nan_w, inf_w};
    const char *bad_names[4] = {"all zero", "negative", "NaN", "infinite"};
    for (int i = 0; i < 4; i++) {
        rc = cdl_alias_build(&a, bad_lists[i], 3);
        check(rc != 0 && a.n == 0 && a.prob == NULL, "alias build rejects %s weights: rc %d",
              bad_names[i], rc);
        cdl_alias_free(&a);
    }
    rc = cdl_alias_build(&a, w, 0);
    check(rc != 0, "alias build rejects an empty list: rc %d", rc);
    cdl_alias_free(&a);
}

int main(void)
{
    test_gamma(0);
    test_triangle();
    test_point();
    test_alias();
    check(chi2_count == N_CHI2, "%d chi-square tests run (N_CHI2 = %d, for the Sidak correction)",
          chi2_count, N_CHI2);
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
