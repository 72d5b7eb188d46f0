/* Statistical and exactness tests of the classic BSDFs (scene/bsdf.c); the
 * microfacet ones are tested by test_microfacet.c.
 *
 * Opaque materials (Lambert, Phong at several exponents, Phong without a
 * diffuse part, Oren-Nayar's qualitative and full models), for several outgoing directions on both sides of the
 * geometric normal, with the shading normal equal to the geometric normal
 * and tilted from it:
 *  - chi-square goodness of fit of cdl_bsdf_sample against cdl_bsdf_pdf,
 *    binned over the whole sphere in the geometric normal's frame (and, for
 *    Phong, a second time in the frame of the lobe axis, where the bins
 *    resolve the lobe); expected counts by adaptive quadrature of the pdf
 *    (test_stats.h); failed samples form their own bin (mass of the pdf
 *    missing on the sphere);
 *  - the pdf integrates to 1 (or to the sample success rate when part of the
 *    lobe lies below the surface, never above 1);
 *  - per-sample consistency of pdf and weight with cdl_bsdf_pdf / _eval;
 *  - weight bound, reciprocity of eval, directional albedo (Monte Carlo and
 *    by quadrature of f |cos|).
 * Mirror and dielectric: exact reflection / Snell directions, Fresnel
 * reflection probability, total internal reflection, weights for radiance
 * and importance transport.
 *
 * Deterministic seeds: the outcome never changes between runs. Returns 0
 * when every check passes. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/vec.h"
#include "scene/bsdf.h"
#include "scene/material.h"

#include "test_stats.h"


/* Chi-square tests in this program, for the Sidak correction of P_MIN
 * (test_stats.h). */
#define N_CHI2 156

/* ---- opaque materials ---------------------------------------------------- */

#define NSAMPLES 200000
#define LOBE_T_MIN 0.02 /* lobe-frame bins cover cos^(n+1) alpha in [this, 1] */

typedef struct opaque_case {
    const char *name;
    cdl_mat_type type;
    float kd, ks, ns;
    float sigma; /* rough diffuse; ks > 0 selects the full model */
} opaque_case;

static cdl_material make_material(cdl_mat_type type, float kd, float ks, float ns, float eta)
{
    cdl_material m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.kd = cdl_v3(kd, kd, kd);
    m.ks = cdl_v3(ks, ks, ks);
    m.kt = cdl_v3(1.0f, 1.0f, 1.0f);
    if (type == CDL_MAT_DIELECTRIC)
        m.ks = m.kt; /* clear glass: Fresnel alone decides */
    m.ns = ns;
    m.eta = eta;
    m.kd_tex = -1;
    return m;
}


/* Oren-Nayar at normal incidence and exit: rho / pi (A + rho C4) for the
 * full model (Mitsuba 0.6), rho A / pi for the qualitative one (pbrt). */
static void test_oren_nayar_normal(void)
{
    float s = 0.5f, s2 = s * s, a = 1.0f - 0.5f * s2 / (s2 + 0.33f), c4 = 0.17f * s2 / (s2 + 0.13f), rho = 0.8f;
    for (int full = 0; full < 2; full++) {
        cdl_material m = make_material(CDL_MAT_ROUGH_DIFFUSE, rho, 0.0f, 0.0f, 1.0f);
        m.sigma = s;
        m.on_full = full;
        cdl_bsdf b;
        cdl_vec3 n = cdl_v3(0.0f, 0.0f, 1.0f);
        cdl_bsdf_init(&b, &m, m.kd, n, n);
        float f = cdl_bsdf_eval(&b, n, n, 0).x, want = rho * CDL_INV_PI * (a + (full ? rho * c4 : 0.0f));
        check(fabsf(f - want) < 1e-5f, "oren-nayar %s at normal incidence: f = %.6f (%.6f)",
              full ? "full" : "qualitative", (double)f, (double)want);
    }
}

static void test_opaque(const opaque_case *mc, double wo_deg, int tilted, uint64_t stream)
{
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = tilted ? polar(&gf, 10.0 * DEG, 40.0 * DEG) : ngd;
    dvec wod = polar(&gf, wo_deg * DEG, 0.0);
    cdl_material m = make_material(mc->type, mc->kd, mc->ks, mc->ns, 1.0f);
    m.sigma = mc->sigma;
    m.on_full = mc->ks > 0.0f;
    if (mc->type == CDL_MAT_ROUGH_DIFFUSE)
        m.ks = cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    cdl_vec3 wo = to_f(wod);
    char tag[160];
    snprintf(tag, sizeof tag, "%s wo=%gdeg%s%s", mc->name, wo_deg,
             wo_deg > 90.0 ? " (back side)" : "", tilted ? " ns tilted 10deg" : "");
    int is_phong = mc->type == CDL_MAT_PHONG;
    double n = mc->ns;

    /* Lobe axis: mirror of wo about the shading normal. */
    dvec nsf = from_f(b.frame.n);
    dvec lobe = dsub(dscale(nsf, 2.0 * ddot(wod, nsf)), wod);
    dframe lf = dframe_from(dnorm(lobe));
    double lobe_cmin = is_phong ? pow(LOBE_T_MIN, 1.0 / (n + 1.0)) : 0.0;

    /* Sampling. */
    static double obs[NC * NP + 1], lobs[NC * NP + 1];
    memset(obs, 0, sizeof obs);
    memset(lobs, 0, sizeof lobs);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0xb5df5eedULL, stream);
    long fails = 0, bad_side = 0, bad_unit = 0, bad_misc = 0;
    double max_pdf_err = 0.0, max_w_err = 0.0, max_w = 0.0, wsum = 0.0, wsum2 = 0.0;
    for (int s = 0; s < NSAMPLES; s++) {
        float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        cdl_scatter sc;
        if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc)) {
            fails++;
            obs[NC * NP] += 1.0;
            lobs[NC * NP] += 1.0; /* the lobe frame's "rest" bin holds failures too */
            continue;
        }
        if (sc.delta || !(sc.pdf > 0.0f) || !cdl_is_finite3(sc.weight) || !isfinite(sc.pdf))
            bad_misc++;
        dvec wi = from_f(sc.wi);
        if (fabs(sqrt(ddot(wi, wi)) - 1.0) > 1e-5)
            bad_unit++;
        if (ddot(wi, ngd) * ddot(wod, ngd) <= 0.0)
            bad_side++;
        double pdf2 = cdl_bsdf_pdf(&b, wo, sc.wi);
        max_pdf_err = fmax(max_pdf_err, rel_err(pdf2, sc.pdf));
        cdl_vec3 f = cdl_bsdf_eval(&b, wo, sc.wi, 0);
        double cs = fabs(cdl_dot(sc.wi, b.frame.n));
        double we[3] = {f.x * cs / sc.pdf, f.y * cs / sc.pdf, f.z * cs / sc.pdf};
        double fs[3] = {f.x, f.y, f.z};
        double wg[3] = {sc.weight.x, sc.weight.y, sc.weight.z};
        for (int k = 0; k < 3; k++) {
            /* The sampler's cosine is the local z before the rotation to
             * world space; ours is recomputed from the float wi, off by
             * ~1e-7 absolute, which matters for near-grazing wi. */
            double slack = fs[k] * COS_ABS_ERR / sc.pdf;
            max_w_err = fmax(max_w_err, fabs(we[k] - wg[k]) / (fmax(fabs(we[k]), fabs(wg[k])) + slack / 1e-3));
            max_w = fmax(max_w, wg[k]);
        }
        wsum += wg[0];
        wsum2 += wg[0] * wg[0];
        double c, phi;
        dframe_coords(&gf, wi, &c, &phi);
        int ic = (int)((c + 1.0) * 0.5 * NC), ip = (int)(phi / (2.0 * PI_D) * NP);
        ic = ic < 0 ? 0 : ic >= NC ? NC - 1 : ic;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[ic * NP + ip] += 1.0;
        if (is_phong) {
            dframe_coords(&lf, wi, &c, &phi);
            if (c >= lobe_cmin) {
                double t = pow(fmin(c, 1.0), n + 1.0);
                int it = (int)((t - LOBE_T_MIN) / (1.0 - LOBE_T_MIN) * NC);
                ip = (int)(phi / (2.0 * PI_D) * NP);
                it = it < 0 ? 0 : it >= NC ? NC - 1 : it;
                ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
                lobs[it * NP + ip] += 1.0;
            } else {
                lobs[NC * NP] += 1.0;
            }
        }
    }

    /* Expected counts by quadrature, in the geometric normal's frame. */
    integ g = {.b = &b, .wo = wo, .fr = gf, .has_lobe = is_phong, .lobe = dnorm(lobe),
               .sigma = is_phong ? 1.0 / sqrt(n) : 1.0, .albedo = 1};
    static double expd[NC * NP + 1], lexp[NC * NP + 1];
    double ipdf = 0.0, ialb = 0.0;
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NP; j++) {
            double v[NQ];
            integrate_cell(&g, -1.0 + 2.0 * i / NC, -1.0 + 2.0 * (i + 1) / NC,
                           2.0 * PI_D * j / NP, 2.0 * PI_D * (j + 1) / NP, v);
            expd[i * NP + j] = v[0] * NSAMPLES;
            ipdf += v[0];
            ialb += v[1];
        }
    /* Failures form a bin of their own when some mass is expected there;
     * otherwise (isolated failures of measure zero, e.g. u1 = 0 exactly
     * putting a lobe sample on the horizon) they are left to the
     * failure-rate check below. */
    expd[NC * NP] = fmax(0.0, 1.0 - ipdf) * NSAMPLES;
    int nbins = expd[NC * NP] >= 5.0 ? NC * NP + 1 : NC * NP;
    chi2_result r = chi2_test(obs, expd, nbins, 5.0);
    check(r.p >= P_MIN,
          "%s: chi2 (cos theta, phi in ng frame, %dx%d bins%s) = %.1f, dof %d, "
          "p-value %.4f (>= %.2g)%s",
          tag, NC, NP, nbins > NC * NP ? " + failures" : "", r.stat, r.dof, r.p, P_MIN,
          r.zero_hits > 0 ? " [samples in bins of expected count 0 pooled]" : "");
    check(r.zero_hits <= ZERO_HITS_MAX,
          "%s: %.0f samples in bins where quadrature of the pdf found no mass (<= %d)", tag,
          r.zero_hits, ZERO_HITS_MAX);

    if (is_phong) {
        /* Bins uniform in cos^(n+1) of the angle to the lobe axis: each
         * holds the same share of the lobe, whatever its width. */
        g.fr = lf;
        g.albedo = 0;
        double icap = 0.0;
        for (int i = 0; i < NC; i++) {
            double c0 = pow(LOBE_T_MIN + (1.0 - LOBE_T_MIN) * i / NC, 1.0 / (n + 1.0));
            double c1 = pow(LOBE_T_MIN + (1.0 - LOBE_T_MIN) * (i + 1) / NC, 1.0 / (n + 1.0));
            if (i == NC - 1)
                c1 = 1.0;
            for (int j = 0; j < NP; j++) {
                double v[NQ];
                integrate_cell(&g, c0, c1, 2.0 * PI_D * j / NP, 2.0 * PI_D * (j + 1) / NP, v);
                lexp[i * NP + j] = v[0] * NSAMPLES;
                icap += v[0];
            }
        }
        lexp[NC * NP] = fmax(0.0, 1.0 - icap) * NSAMPLES;
        r = chi2_test(lobs, lexp, NC * NP + 1, 5.0);
        check(r.p >= P_MIN,
              "%s: chi2 (cos^(n+1) to lobe axis, phi; %dx%d bins + rest) = %.1f, dof %d, "
              "p-value %.4f (>= %.2g)%s",
              tag, NC, NP, r.stat, r.dof, r.p, P_MIN,
              r.zero_hits > 0 ? " [samples in bins of expected count 0 pooled]" : "");
        check(r.zero_hits <= ZERO_HITS_MAX,
              "%s: lobe frame: %.0f samples in bins where quadrature of the pdf found no mass "
              "(<= %d)",
              tag, r.zero_hits, ZERO_HITS_MAX);
    }

    /* Mass of the pdf against the sample success rate. */
    double succ = 1.0 - (double)fails / NSAMPLES;
    check(ipdf <= 1.0 + 1e-3, "%s: integral of pdf over the sphere %.5f (<= 1.001)", tag, ipdf);
    check(fabs(succ - ipdf) <= 0.01,
          "%s: failed samples %.5f vs 1 - integral of pdf %.5f (|diff| %.5f <= 0.01)", tag,
          1.0 - succ, 1.0 - ipdf, fabs(succ - ipdf));
    /* All mass above the surface: Lambert, and narrow lobes far from the
     * horizon, with the shading normal on the geometric one. */
    double wo_front = wo_deg > 90.0 ? 180.0 - wo_deg : wo_deg;
    int full = !tilted && (mc->type == CDL_MAT_DIFFUSE || (n >= 100.0 && wo_front <= 60.0));
    if (full)
        check(fabs(ipdf - 1.0) <= 0.01, "%s: integral of pdf %.5f (1 within 1%%)", tag, ipdf);
    /* A cosine lobe about ns loses (1 - cos tilt) / 2 below the geometric
     * surface (in the disk projection, between a half circle and a half
     * ellipse of axes 1 and cos tilt). */
    if (tilted && mc->type == CDL_MAT_DIFFUSE && succ > 0.0) {
        double want = 0.5 * (1.0 + cos(10.0 * DEG));
        check(fabs(ipdf - want) <= 1e-4,
              "%s: integral of pdf %.5f vs (1 + cos 10deg) / 2 = %.5f (within 1e-4)", tag, ipdf,
              want);
    }

    /* Per-sample consistency. */
    check(bad_misc == 0 && bad_unit == 0 && bad_side == 0,
          "%s: samples with delta/non-finite/zero pdf %ld, |wi| != 1 %ld, wi across the "
          "geometric surface %ld (all 0)",
          tag, bad_misc, bad_unit, bad_side);
    check(max_pdf_err <= 1e-3, "%s: sample pdf vs cdl_bsdf_pdf: max relative error %.2e (<= 1e-3)",
          tag, max_pdf_err);
    check(max_w_err <= 1e-3,
          "%s: weight vs eval |cos| / pdf: max relative error %.2e (<= 1e-3, cos +- 1e-6)", tag,
          max_w_err);
    /* Weight bound. With p_spec = ks / (kd + ks) the Phong weight is
     * (kd + ks) (kd cos + ks (n+2)/2 x cos) / (kd cos + ks (n+1)/2 x), x =
     * cos^n alpha, whose supremum (cos = x = 1, wo on the normal) is
     * (kd + ks) (kd + ks (n+2)/2) / (kd + ks (n+1)/2): above 1 for kd 0.3,
     * ks 0.6, n = 1 (1.2). The weight must stay <= 1 whenever that is. */
    double wb = mc->kd;
    if (is_phong)
        wb = (mc->kd + mc->ks) * (mc->kd + mc->ks * (n + 2.0) / 2.0) /
             (mc->kd + mc->ks * (n + 1.0) / 2.0);
    /* Oren-Nayar's weight pi f (cosine-sampled) grows without bound towards
     * grazing back-scattering (its tan beta); the albedo below is bounded */
    if (mc->type == CDL_MAT_ROUGH_DIFFUSE)
        wb = INFINITY;
    double wlimit = fmax(1.0, wb) + 1e-4;
    check(max_w <= wlimit, "%s: max sample weight %.5f (<= %.4f%s)", tag, max_w, wlimit,
          wb > 1.0 ? ": this sampler's supremum for this material exceeds 1" : "");

    /* Directional albedo. */
    double alb = wsum / NSAMPLES;
    double sd = sqrt(fmax(0.0, wsum2 / NSAMPLES - alb * alb) / NSAMPLES);
    check(alb <= 1.0, "%s: Monte Carlo albedo %.5f (<= 1)", tag, alb);
    check(fabs(alb - ialb) <= fmax(0.01 * ialb, 5.0 * sd) + 1e-6,
          "%s: Monte Carlo albedo %.5f vs quadrature of f|cos| %.5f (within max(1%%, 5 sigma = "
          "%.5f))",
          tag, alb, ialb, 5.0 * sd);
    if (is_phong && wo_deg == 0.0 && !tilted) {
        /* At normal incidence the normalized lobe lies entirely above the
         * surface and reflects exactly ks: the albedo is kd + ks. */
        double want = mc->kd + mc->ks;
        check(fabs(ialb - want) <= 1e-3 * want && fabs(alb - want) <= fmax(0.01 * want, 5.0 * sd),
              "%s: albedo at normal incidence: quadrature %.5f, Monte Carlo %.5f vs kd + ks = %.5f",
              tag, ialb, alb, want);
    }
    if (mc->type == CDL_MAT_DIFFUSE) {
        double want = mc->kd * succ;
        check(fabs(alb - want) <= 0.01 * want,
              "%s: Lambert albedo %.5f vs kd * success rate %.5f (within 1%%)", tag, alb, want);
    }

    /* Reciprocity, pairs with wo and random pairs over the sphere. */
    double max_rec = 0.0;
    long nonzero = 0;
    for (int s = 0; s < 20000; s++) {
        cdl_vec3 a = random_sphere_dir(&rng);
        cdl_vec3 bb = (s & 1) ? random_sphere_dir(&rng) : wo;
        cdl_vec3 f1 = cdl_bsdf_eval(&b, bb, a, 0), f2 = cdl_bsdf_eval(&b, a, bb, 0);
        if (!cdl_is_black(f1))
            nonzero++;
        max_rec = fmax(max_rec, rel_err(f1.x, f2.x));
        max_rec = fmax(max_rec, rel_err(f1.y, f2.y));
        max_rec = fmax(max_rec, rel_err(f1.z, f2.z));
    }
    check(max_rec <= 1e-4 && nonzero > 1000,
          "%s: reciprocity f(wo,wi) = f(wi,wo): max relative error %.2e (<= 1e-4) over 20000 "
          "pairs (%ld non-zero)",
          tag, max_rec, nonzero);
    printf("    (%ld quadrature evaluations)\n", g.evals);
}

/* ---- mirror ----------------------------------------------------------- */

static void test_mirror(double wo_deg, int tilted, double tilt_az_deg)
{
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = tilted ? polar(&gf, 10.0 * DEG, tilt_az_deg * DEG) : ngd;
    dvec wod = polar(&gf, wo_deg * DEG, 0.0);
    cdl_material m = make_material(CDL_MAT_MIRROR, 0.0f, 0.9f, 0.0f, 1.0f);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    cdl_vec3 wo = to_f(wod);
    char tag[160];
    snprintf(tag, sizeof tag, "mirror ks=0.9 wo=%gdeg%s", wo_deg, wo_deg > 90.0 ? " (back side)" : "");
    if (tilted)
        snprintf(tag + strlen(tag), sizeof tag - strlen(tag), " ns tilted 10deg az %gdeg",
                 tilt_az_deg);
    dvec want = dsub(dscale(nsd, 2.0 * ddot(wod, nsd)), wod);
    int want_ok = ddot(want, ngd) * ddot(wod, ngd) > 0.0;
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x3141ULL, (uint64_t)(wo_deg * 10.0) + (uint64_t)tilted * 7919u);
    double max_dir = 0.0;
    long wrong_ret = 0, wrong_misc = 0;
    for (int s = 0; s < 1000; s++) {
        cdl_scatter sc;
        float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        int ok = cdl_bsdf_sample(&b, wo, u0, u1, u2, s & 1, &sc);
        if (ok != want_ok)
            wrong_ret++;
        if (!ok)
            continue;
        dvec d = dsub(from_f(sc.wi), want);
        max_dir = fmax(max_dir, sqrt(ddot(d, d)));
        if (sc.weight.x != 0.9f || sc.weight.y != 0.9f || sc.weight.z != 0.9f || sc.pdf != 1.0f ||
            !sc.delta)
            wrong_misc++;
    }
    check(wrong_ret == 0, "%s: sample returns %d (reflection %s the geometric surface): %ld wrong",
          tag, want_ok, want_ok ? "above" : "below", wrong_ret);
    if (want_ok) {
        check(max_dir <= 1e-5, "%s: |wi - reflect(wo, ns)| max %.2e (<= 1e-5)", tag, max_dir);
        check(wrong_misc == 0, "%s: weight = ks, pdf = 1, delta = 1: %ld violations", tag,
              wrong_misc);
    }
    cdl_vec3 f = cdl_bsdf_eval(&b, wo, to_f(want), 0);
    float p = cdl_bsdf_pdf(&b, wo, to_f(want));
    check(cdl_is_black(f) && p == 0.0f, "%s: eval (%g) and pdf (%g) of a delta BSDF are 0", tag,
          f.x, p);
}

/* ---- dielectric ----------------------------------------------------------- */


#define NDIEL 100000

static void test_dielectric(double theta_deg, int entering, int tilted)
{
    const float eta = 1.5f;
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = tilted ? polar(&gf, 10.0 * DEG, 40.0 * DEG) : ngd;
    /* theta is measured from the normal on wo's side. */
    dvec wod = polar(&gf, (entering ? theta_deg : 180.0 - theta_deg) * DEG, 0.0);
    cdl_material m = make_material(CDL_MAT_DIELECTRIC, 0.0f, 0.0f, 0.0f, eta);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    cdl_vec3 wo = to_f(wod);
    double eta_i = entering ? 1.0 : eta, eta_t = entering ? eta : 1.0;
    double eta_rel = eta_t / eta_i;
    char tag[160];
    snprintf(tag, sizeof tag, "dielectric eta=1.5 %s theta=%gdeg%s",
             entering ? "entering (front)" : "exiting (back)", theta_deg,
             tilted ? " ns tilted 10deg" : "");
    /* Normal on wo's side, and the incidence angle to it. */
    dvec nw = ddot(wod, ngd) > 0.0 ? nsd : dscale(nsd, -1.0);
    double cos_i = ddot(wod, nw), th_i = acos(fmin(1.0, cos_i));
    double fref = fresnel_ref(th_i, eta_i, eta_t);
    float flib = cdl_fresnel_dielectric((float)cos_i, (float)eta_rel);
    float flib2 = cdl_fresnel_dielectric((float)-cos_i, (float)(1.0 / eta_rel));
    check(fabs(flib - fref) <= 1e-5 && flib == flib2,
          "%s: cdl_fresnel_dielectric %.6f (also with cos < 0: %.6f) vs angle-form Fresnel "
          "%.6f (|diff| <= 1e-5)",
          tag, flib, flib2, fref);
    double sin_i = sin(th_i), sin_t = eta_i / eta_t * sin_i;
    int tir = sin_t >= 1.0;
    if (tir)
        check(flib == 1.0f, "%s: beyond the critical angle %.2fdeg: F = %g (1)", tag,
              asin(eta_t / eta_i) / DEG, flib);
    dvec refl = dsub(dscale(nw, 2.0 * cos_i), wod);
    dvec trans = dv(0, 0, 0);
    if (!tir) {
        double cos_t = sqrt(1.0 - sin_t * sin_t);
        trans = dsub(dscale(dscale(wod, -1.0), 1.0 / eta_rel), dscale(nw, cos_t - cos_i / eta_rel));
    }
    dvec perp = dcross(wod, nw);
    double perp_len = sqrt(ddot(perp, perp));

    cdl_rng rng;
    cdl_rng_seed(&rng, 0xd1e1ULL, (uint64_t)(theta_deg * 10.0) * 4u + (uint64_t)entering * 2u +
                                     (uint64_t)tilted);
    long ntrans = 0, fails = 0, bad_w = 0, bad_pdf = 0, bad_delta = 0;
    double max_refl = 0.0, max_trans = 0.0, max_snell = 0.0, max_plane = 0.0, max_unit = 0.0;
    double pdf_r = -1.0, pdf_t = -1.0; /* discrete probabilities of the two events */
    for (int adjoint = 0; adjoint < 2; adjoint++) {
        long nr = 0;
        for (int s = 0; s < NDIEL; s++) {
            cdl_scatter sc;
            float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
            if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, adjoint, &sc)) {
                fails++;
                continue;
            }
            if (!sc.delta)
                bad_delta++;
            dvec wi = from_f(sc.wi);
            max_unit = fmax(max_unit, fabs(sqrt(ddot(wi, wi)) - 1.0));
            if (ddot(wi, ngd) * ddot(wod, ngd) > 0.0) {
                nr++;
                dvec d = dsub(wi, refl);
                max_refl = fmax(max_refl, sqrt(ddot(d, d)));
                if (sc.weight.x != 1.0f || sc.weight.y != 1.0f || sc.weight.z != 1.0f)
                    bad_w++;
                if (pdf_r < 0.0)
                    pdf_r = sc.pdf;
                if (sc.pdf != pdf_r)
                    bad_pdf++;
            } else {
                ntrans++;
                if (!tir) {
                    dvec d = dsub(wi, trans);
                    max_trans = fmax(max_trans, sqrt(ddot(d, d)));
                }
                /* Snell: eta_i sin_i = eta_t sin_t, measured on the sample. */
                double ct = -ddot(wi, nw);
                double st = sqrt(fmax(0.0, 1.0 - ct * ct));
                max_snell = fmax(max_snell, fabs(eta_i * sin_i - eta_t * st));
                if (perp_len > 1e-6)
                    max_plane = fmax(max_plane, fabs(ddot(wi, perp)) / perp_len);
                double want_w = adjoint ? 1.0 : 1.0 / (eta_rel * eta_rel);
                if (rel_err(sc.weight.x, want_w) > 1e-6 || sc.weight.x != sc.weight.y ||
                    sc.weight.x != sc.weight.z)
                    bad_w++;
                if (pdf_t < 0.0)
                    pdf_t = sc.pdf;
                if (sc.pdf != pdf_t)
                    bad_pdf++;
            }
        }
        double freq = (double)nr / NDIEL;
        double sd = sqrt(fmax(flib * (1.0 - flib), 1e-12) / NDIEL);
        check(fabs(freq - flib) <= 0.01 && fabs(freq - flib) <= 5.0 * sd + 1e-12,
              "%s adjoint=%d: reflection frequency %.5f vs Fresnel %.5f (|diff| %.5f <= 0.01 and "
              "<= 5 sigma = %.5f)",
              tag, adjoint, freq, flib, fabs(freq - flib), 5.0 * sd);
    }
    check(fails == 0 && bad_delta == 0, "%s: failed samples %ld, non-delta samples %ld (0)", tag,
          fails, bad_delta);
    check(max_refl <= 1e-5, "%s: reflected wi vs reflect(wo, n): max |diff| %.2e (<= 1e-5)", tag,
          max_refl);
    check(max_unit <= 1e-5, "%s: max ||wi| - 1| %.2e (<= 1e-5)", tag, max_unit);
    if (tir) {
        check(ntrans == 0, "%s: total internal reflection: %ld refracted samples (0)", tag, ntrans);
    } else {
        check(ntrans > 0 && max_trans <= 1e-5,
              "%s: refracted wi vs Snell direction: max |diff| %.2e (<= 1e-5, %ld samples)", tag,
              max_trans, ntrans);
        check(max_snell <= 1e-5,
              "%s: sin ratio: max |eta_i sin_i - eta_t sin_t| %.2e (<= 1e-5; sin_i %.5f, "
              "sin_t %.5f)",
              tag, max_snell, sin_i, sin_t);
        if (perp_len > 1e-6)
            check(max_plane <= 1e-5, "%s: refracted wi in the plane of incidence: max %.2e (<= 1e-5)",
                  tag, max_plane);
    }
    check(bad_w == 0, "%s: weights (reflection 1; refraction 1/eta^2 = %.5f radiance, 1 "
                      "importance): %ld violations",
          tag, 1.0 / (eta_rel * eta_rel), bad_w);
    /* The sampler computes cos_o from the float wo and shading normal: its
     * F may differ from ours by a few ulps times dF/dcos. */
    double pr = pdf_r < 0.0 ? 0.0 : pdf_r, pt = pdf_t < 0.0 ? 0.0 : pdf_t;
    check(bad_pdf == 0 && fabs(pr - flib) <= 1e-4 && (pdf_r < 0.0 || pdf_t < 0.0 || fabs(pr + pt - 1.0) <= 1e-6),
          "%s: pdf of reflection %.6f (F = %.6f within 1e-4), of refraction %.6f (sum 1 within "
          "1e-6), %ld samples with another pdf",
          tag, pr, flib, pt, bad_pdf);
    cdl_vec3 f = cdl_bsdf_eval(&b, wo, to_f(refl), 0);
    float p = cdl_bsdf_pdf(&b, wo, to_f(refl));
    check(cdl_is_black(f) && p == 0.0f, "%s: eval (%g) and pdf (%g) of a delta BSDF are 0", tag,
          f.x, p);
}

static void test_fresnel(void)
{
    float f0 = cdl_fresnel_dielectric(1.0f, 1.5f), f1 = cdl_fresnel_dielectric(1.0f, 1.0f / 1.5f);
    float f2 = cdl_fresnel_dielectric(-1.0f, 1.5f);
    double want = (0.5 / 2.5) * (0.5 / 2.5);
    check(fabs(f0 - want) < 1e-6 && fabs(f1 - want) < 1e-6 && fabs(f2 - want) < 1e-6,
          "fresnel at normal incidence: %.7f entering, %.7f exiting, %.7f (cos < 0) vs "
          "((eta-1)/(eta+1))^2 = %.7f",
          f0, f1, f2, want);
    /* Reciprocity: the same interface seen from both sides. */
    double worst = 0.0;
    for (int i = 1; i < 90; i++) {
        double ti = i * DEG, tt = asin(sin(ti) / 1.5);
        double a = cdl_fresnel_dielectric((float)cos(ti), 1.5f);
        double bb = cdl_fresnel_dielectric((float)cos(tt), 1.0f / 1.5f);
        worst = fmax(worst, fabs(a - bb));
    }
    /* Near grazing ti the exiting side sits near its critical angle, where
     * cos_t = sqrt(1 - sin2_t) loses float digits: 1e-4, not 1e-6. */
    check(worst <= 1e-4,
          "fresnel reciprocity F(ti, 1.5) = F(tt, 1/1.5), ti = 1..89deg: max |diff| %.2e (<= 1e-4)",
          worst);
    float g = cdl_fresnel_dielectric(cosf(60.0f * CDL_PI / 180.0f), 1.0f / 1.5f);
    check(g == 1.0f, "fresnel exiting glass at 60deg (critical 41.81deg): %g (1)", g);
}

static void test_init(void)
{
    /* A shading normal on the far side of ng (flipped winding) is flipped. */
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = polar(&gf, 170.0 * DEG, 40.0 * DEG);
    cdl_material m = make_material(CDL_MAT_DIFFUSE, 0.8f, 0.0f, 0.0f, 1.0f);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    double d = ddot(from_f(b.frame.n), ngd), e = ddot(from_f(b.frame.n), dscale(nsd, -1.0));
    check(d > 0.0 && e > 1.0 - 1e-6,
          "bsdf_init with ns on the back of ng: frame.n . ng = %.5f (> 0), frame.n . -ns = %.7f (1)",
          d, e);
    double orth = fmax(fabs(cdl_dot(b.frame.t, b.frame.b)),
                       fmax(fabs(cdl_dot(b.frame.t, b.frame.n)), fabs(cdl_dot(b.frame.b, b.frame.n))));
    check(orth < 1e-6, "bsdf_init shading frame orthonormal: max |dot| %.2e (< 1e-6)", orth);
}

/* A one-sided opaque bsdf (Mitsuba's, outside twosided) equals the
 * two-sided one seen from the front and is black from the back: eval, pdf
 * and sampling, for diffuse, phong and a rough conductor. */
static void test_one_sided(void)
{
    static const cdl_mat_type types[] = {CDL_MAT_DIFFUSE, CDL_MAT_PHONG, CDL_MAT_CONDUCTOR};
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    int bad = 0, front_ok = 0;
    for (size_t t = 0; t < sizeof types / sizeof types[0]; t++) {
        cdl_material m = make_material(types[t], 0.5f, 0.4f, 10.0f, 1.0f);
        m.alpha_x = m.alpha_y = 0.3f;
        cdl_bsdf two, one;
        cdl_bsdf_init(&two, &m, m.kd, to_f(ngd), to_f(ngd));
        m.one_sided = 1;
        cdl_bsdf_init(&one, &m, m.kd, to_f(ngd), to_f(ngd));
        for (int side = 0; side < 2; side++) {
            double off = side ? 180.0 : 0.0; /* polar angles beyond 90: the back */
            cdl_vec3 wo = to_f(polar(&gf, (off ? 180.0 - 40.0 : 40.0) * DEG, 20.0 * DEG));
            cdl_vec3 wi = to_f(polar(&gf, (off ? 180.0 - 30.0 : 30.0) * DEG, 200.0 * DEG));
            cdl_vec3 f1 = cdl_bsdf_eval(&one, wo, wi, 0), f2 = cdl_bsdf_eval(&two, wo, wi, 0);
            float p1 = cdl_bsdf_pdf(&one, wo, wi), p2 = cdl_bsdf_pdf(&two, wo, wi), pe;
            cdl_vec3 fe = cdl_bsdf_eval_pdf(&one, wo, wi, 1, &pe);
            cdl_scatter sc;
            int s1 = cdl_bsdf_sample(&one, wo, 0.3f, 0.4f, 0.6f, 0, &sc);
            if (!side) {
                bad += f1.x != f2.x || p1 != p2 || !(f2.x > 0.0f) || fe.x != f1.x || pe != p1 || !s1;
                front_ok += f2.x > 0.0f;
            } else {
                bad += f1.x != 0.0f || p1 != 0.0f || fe.x != 0.0f || pe != 0.0f || s1 || !(f2.x > 0.0f);
            }
        }
    }
    check(bad == 0 && front_ok == 3, "one-sided opaque bsdfs: the two-sided values in front, black behind "
                                     "(%d mismatches)", bad);
}

int main(void)
{
    test_gamma(1);
    test_init();
    test_one_sided();

    static const opaque_case cases[] = {
        {"lambert kd=0.8", CDL_MAT_DIFFUSE, 0.8f, 0.0f, 0.0f, 0.0f},
        {"phong kd=0.3 ks=0.6 n=1", CDL_MAT_PHONG, 0.3f, 0.6f, 1.0f, 0.0f},
        {"phong kd=0.3 ks=0.6 n=10", CDL_MAT_PHONG, 0.3f, 0.6f, 10.0f, 0.0f},
        {"phong kd=0.3 ks=0.6 n=100", CDL_MAT_PHONG, 0.3f, 0.6f, 100.0f, 0.0f},
        {"phong kd=0.3 ks=0.6 n=1000", CDL_MAT_PHONG, 0.3f, 0.6f, 1000.0f, 0.0f},
        {"phong kd=0 ks=0.9 n=30", CDL_MAT_PHONG, 0.0f, 0.9f, 30.0f, 0.0f},
        {"oren-nayar qualitative kd=1 sigma=0.6", CDL_MAT_ROUGH_DIFFUSE, 1.0f, 0.0f, 0.0f, 0.6f},
        {"oren-nayar full kd=1 sigma=0.6", CDL_MAT_ROUGH_DIFFUSE, 1.0f, 1.0f, 0.0f, 0.6f},
    };
    /* Angles from ng: > 90 is on the back side (135 = 45deg, 95 = 85deg). */
    static const double wos[] = {0.0, 30.0, 60.0, 85.0, 135.0, 95.0};
    uint64_t stream = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        for (int tilted = 0; tilted < 2; tilted++)
            for (size_t w = 0; w < sizeof wos / sizeof wos[0]; w++)
                test_opaque(&cases[c], wos[w], tilted, stream++);

    static const double mw[] = {0.0, 30.0, 60.0, 85.0, 135.0, 95.0};
    for (size_t w = 0; w < sizeof mw / sizeof mw[0]; w++)
        test_mirror(mw[w], 0, 0.0);
    test_mirror(30.0, 1, 40.0);
    test_mirror(135.0, 1, 40.0);
    test_mirror(85.0, 1, 180.0); /* reflection about ns dips below the surface */

    test_fresnel();
    test_oren_nayar_normal();
    static const double ent[] = {0.0, 30.0, 60.0, 85.0};
    static const double ext[] = {0.0, 30.0, 40.0, 45.0, 60.0, 85.0};
    for (size_t i = 0; i < sizeof ent / sizeof ent[0]; i++)
        test_dielectric(ent[i], 1, 0);
    for (size_t i = 0; i < sizeof ext / sizeof ext[0]; i++)
        test_dielectric(ext[i], 0, 0);
    test_dielectric(30.0, 1, 1);
    test_dielectric(30.0, 0, 1);


    check(chi2_count == N_CHI2, "%d chi-square tests run (N_CHI2 = %d, for the Sidak correction)",
          chi2_count, N_CHI2);
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}