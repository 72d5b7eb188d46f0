/* Mitsuba's models read from its files (issue 27): plastic and
 * roughplastic (scene/plastic.c), Mitsuba's microfacet distributions
 * (scene/microfacet_mts.c) on rough coats and conductors, and the mask's
 * pass-through component (scene/bsdf.c).
 *
 * For each material and several outgoing directions:
 *  - chi-square goodness of fit of cdl_bsdf_sample against cdl_bsdf_pdf
 *    over the sphere (10 x 20 bins in the geometric normal's frame; Dirac
 *    samples and failures share one bin expecting 1 - integral of pdf);
 *  - the Dirac share (coat mirror, pass-through) equals its stated
 *    probability;
 *  - per sample: pdf and weight agree with cdl_bsdf_pdf and
 *    cdl_bsdf_eval |cos| / pdf;
 *  - energy: Monte Carlo albedo <= 1, and its non-Dirac part agrees with
 *    quadrature of f |cos|;
 *  - reciprocity of eval.
 * Plus the building blocks: erfinv, Gauss-Legendre, the rough coat's
 * tables against the smooth limits. Deterministic seeds. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/vec.h"
#include "scene/bsdf.h"
#include "scene/material.h"
#include "scene/microfacet_mts.h"
#include "scene/plastic.h"

#define N_CHI2 48
#include "test_stats.h"

#define NSAMPLES 200000

typedef struct pcase {
    const char *name;
    cdl_mat_type type;
    int mf, nonlinear;
    float kd, ax, ay, eta, opacity;
} pcase;

static cdl_material make(const pcase *pc)
{
    cdl_material m = cdl_material_default(pc->type);
    m.kd = cdl_v3(pc->kd, pc->kd * 0.7f, pc->kd * 0.3f);
    m.ks = cdl_v3(1, 1, 1);
    m.eta = pc->eta;
    m.mf = pc->mf;
    m.nonlinear = pc->nonlinear;
    m.alpha_x = pc->ax;
    m.alpha_y = pc->ay;
    m.eta3 = cdl_v3(0.2f, 0.9f, 1.1f);
    m.k3 = cdl_v3(3.9f, 2.4f, 2.1f);
    float d = (m.kd.x + m.kd.y + m.kd.z) / 3.0f;
    m.spec_weight = 1.0f / (1.0f + d);
    if (pc->type == CDL_MAT_COATED || pc->type == CDL_MAT_ROUGH_COATED)
        cdl_coat_prepare(&m);
    if (pc->opacity < 1.0f) {
        m.masked = 1;
        m.opacity = pc->opacity;
        m.opacity_tex = -1;
    }
    return m;
}

static void test_case(const pcase *pc, double wo_deg, int tilted, uint64_t stream)
{
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = tilted ? polar(&gf, 10.0 * DEG, 40.0 * DEG) : ngd;
    dvec wod = polar(&gf, wo_deg * DEG, 0.0);
    cdl_material m = make(pc);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    cdl_vec3 wo = to_f(wod);
    char tag[160];
    snprintf(tag, sizeof tag, "%s wo=%gdeg%s", pc->name, wo_deg, tilted ? " ns tilted" : "");

    static double obs[NC * NP + 1];
    memset(obs, 0, sizeof obs);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x91a571cULL, stream);
    long ndelta = 0, bad = 0;
    double dprob = -1.0, dprob_err = 0.0, max_pdf_err = 0.0, max_w_err = 0.0;
    double wsum = 0.0, wsum2 = 0.0, wnd = 0.0, wnd2 = 0.0;
    for (int s = 0; s < NSAMPLES; s++) {
        float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        cdl_scatter sc;
        if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc)) {
            obs[NC * NP] += 1.0;
            continue;
        }
        if (!cdl_is_finite3(sc.weight) || !(sc.pdf > 0.0f) || fabsf(cdl_length(sc.wi) - 1.0f) > 1e-5f)
            bad++;
        double w = sc.weight.x;
        wsum += w;
        wsum2 += w * w;
        if (sc.delta) {
            ndelta++;
            obs[NC * NP] += 1.0;
            /* the mirror's or pass-through's probability, the same for every
             * such sample from this wo (the mask's pass-through has 1 - opacity) */
            if (dprob < 0.0)
                dprob = sc.pdf;
            dprob_err = fmax(dprob_err, fabs(sc.pdf - dprob));
            continue;
        }
        wnd += w;
        wnd2 += w * w;
        max_pdf_err = fmax(max_pdf_err, rel_err(cdl_bsdf_pdf(&b, wo, sc.wi), sc.pdf));
        cdl_vec3 f = cdl_bsdf_eval(&b, wo, sc.wi, 0);
        double we = f.x * fabs(cdl_dot(sc.wi, b.frame.n)) / sc.pdf;
        max_w_err = fmax(max_w_err, fabs(we - w) / (fmax(fabs(we), fabs(w)) + 1e-3));
        double c, phi;
        dframe_coords(&gf, from_f(sc.wi), &c, &phi);
        int ic = (int)((c + 1.0) * 0.5 * NC), ip = (int)(phi / (2.0 * PI_D) * NP);
        ic = ic < 0 ? 0 : ic >= NC ? NC - 1 : ic;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[ic * NP + ip] += 1.0;
    }
    /* expected counts by adaptive quadrature, refined around the mirror lobe */
    dvec lobe = dsub(dscale(nsd, 2.0 * ddot(wod, nsd)), wod);
    integ g = {.b = &b, .wo = wo, .fr = gf, .has_lobe = pc->ax < 0.5f, .lobe = dnorm(lobe),
               .sigma = fmax(0.02, pc->ax), .albedo = 1};
    static double expd[NC * NP + 1];
    double ipdf = 0.0, ialb = 0.0;
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NP; j++) {
            double v[NQ];
            integrate_cell(&g, -1.0 + 2.0 * i / NC, -1.0 + 2.0 * (i + 1) / NC, 2.0 * PI_D * j / NP,
                           2.0 * PI_D * (j + 1) / NP, v);
            expd[i * NP + j] = v[0] * NSAMPLES;
            ipdf += v[0];
            ialb += v[1];
        }
    expd[NC * NP] = fmax(0.0, 1.0 - ipdf) * NSAMPLES;
    int nbins = expd[NC * NP] >= 5.0 ? NC * NP + 1 : NC * NP;
    chi2_result r = chi2_test(obs, expd, nbins, 5.0);
    check(r.p >= P_MIN, "%s: chi2 = %.1f, dof %d, p %.4f (>= %.2g)", tag, r.stat, r.dof, r.p, P_MIN);
    check(r.zero_hits <= ZERO_HITS_MAX, "%s: %.0f samples where the pdf has no mass (<= %d)", tag, r.zero_hits,
          ZERO_HITS_MAX);
    check(ipdf <= 1.0 + 1e-3, "%s: integral of pdf %.5f (<= 1.001)", tag, ipdf);
    if (ndelta > 0) {
        double frac = (double)ndelta / NSAMPLES, sd = sqrt(dprob * (1.0 - dprob) / NSAMPLES);
        check(fabs(frac - dprob) <= 5.0 * sd + 1e-4 && dprob_err < 1e-6,
              "%s: Dirac share %.5f vs its probability %.5f (5 sigma %.5f)", tag, frac, dprob, 5.0 * sd);
    }
    /* rough glass: a refracted direction recomputed from wi loses digits in
     * Walter's denominator (more without -march=native's fused multiplies) */
    double tol = pc->type == CDL_MAT_ROUGH_DIELECTRIC ? 1e-2 : 1e-3;
    check(bad == 0 && max_pdf_err <= tol && max_w_err <= tol,
          "%s: bad samples %ld, pdf vs cdl_bsdf_pdf %.1e, weight vs eval |cos| / pdf %.1e (<= %g)", tag, bad,
          max_pdf_err, max_w_err, tol);
    double alb = wsum / NSAMPLES, sd = sqrt(fmax(0.0, wsum2 / NSAMPLES - alb * alb) / NSAMPLES);
    /* radiance leaving glass from inside gains eta^2: its albedo may pass 1 */
    int glass = pc->type == CDL_MAT_ROUGH_DIELECTRIC;
    if (!glass || wo_deg < 90.0)
        check(alb <= 1.0 + 5.0 * sd, "%s: albedo %.5f (<= 1 + 5 sigma)", tag, alb);
    double and = wnd / NSAMPLES, sdn = sqrt(fmax(0.0, wnd2 / NSAMPLES - and * and) / NSAMPLES);
    check(fabs(and - ialb) <= fmax(0.01 * ialb, 5.0 * sdn) + 1e-5,
          "%s: non-Dirac albedo %.5f vs quadrature of f|cos| %.5f", tag, and, ialb);
    double max_rec = 0.0;
    int nrec = 0, nbad = 0;
    for (int s = 0; s < 20000; s++) {
        cdl_vec3 a = random_sphere_dir(&rng), c = (s & 1) ? random_sphere_dir(&rng) : wo;
        /* glass: radiance one way is importance the other (the 1/eta^2) */
        cdl_vec3 f1 = cdl_bsdf_eval(&b, c, a, 0), f2 = cdl_bsdf_eval(&b, a, c, glass);
        /* where the Beckmann tail underflows (D below 1e-20 in one
         * direction only) both are ~0: compared from 1e-5 on */
        if (glass && fmax(fmax(f1.x, f2.x), fmax(f1.z, f2.z)) < 1e-5f)
            continue;
        double e = fmax(rel_err(f1.x, f2.x), rel_err(f1.z, f2.z));
        nrec++;
        nbad += e > 1e-3;
        max_rec = fmax(max_rec, e);
    }
    if (!glass)
        check(max_rec <= 1e-3, "%s: reciprocity max relative error %.1e (<= 1e-3)", tag, max_rec);
    else /* refraction at grazing angles loses digits in float (Walter's denominator) */
        check(nbad <= nrec / 200, "%s: adjoint reciprocity within 1e-3 for all but %d of %d pairs (<= 0.5 %%)", tag,
              nbad, nrec);
}

static void test_blocks(void)
{
    double worst = 0.0;
    for (int i = -99; i <= 99; i++) {
        float x = (float)i / 100.0f;
        worst = fmax(worst, fabs(erf(cdl_erfinvf(x)) - x));
    }
    check(worst < 2e-6, "erf(erfinv(x)) = x on [-0.99, 0.99]: max |diff| %.1e (< 2e-6)", worst);
    double x[32], w[32], sw = 0.0, s6 = 0.0;
    cdl_gauss_legendre(32, x, w);
    for (int i = 0; i < 32; i++) {
        sw += w[i];
        s6 += w[i] * pow(x[i], 62);
    }
    check(fabs(sw - 2.0) < 1e-12 && fabs(s6 - 2.0 / 63.0) < 1e-12,
          "Gauss-Legendre 32: sum of weights %.15f (2), integral of x^62 %.15f (2/63)", sw, s6);
    /* a nearly smooth rough coat: its transmittance at normal incidence
     * is 1 - F(1), its inside diffuse reflectance near the smooth fit */
    cdl_material m = cdl_material_default(CDL_MAT_ROUGH_COATED);
    m.eta = 1.5f;
    m.alpha_x = m.alpha_y = 0.01f;
    for (int t = CDL_MF_GGX; t <= CDL_MF_BECKMANN; t++) {
        m.mf = t;
        cdl_coat_prepare(&m);
        double t1 = 1.0 - cdl_fresnel_dielectric(1.0f, 1.5f), fdr = cdl_fresnel_diffuse_reflectance(1.0f / 1.5f);
        check(fabs(m.coat_t[CDL_COAT_RES - 1] - t1) < 1e-3 && fabs(m.coat_ri - fdr) < 0.02,
              "rough coat alpha 0.01 (%s): T(1) %.5f vs 1 - F %.5f, Ri %.4f vs Fdr(1/eta) %.4f", t == CDL_MF_GGX ?
              "ggx" : "beckmann", m.coat_t[CDL_COAT_RES - 1], t1, m.coat_ri, fdr);
        int mono = 1;
        /* (the entry at cos 1e-6, Mitsuba's too, is off the curve) */
        for (int k = 2; k < CDL_COAT_RES; k++)
            mono &= m.coat_t[k] >= m.coat_t[k - 1] - 1e-4f && m.coat_t[k] <= 1.0f;
        check(mono, "rough coat transmittance rises with cos theta and stays <= 1");
    }
}

int main(void)
{
    test_blocks();
    static const pcase cases[] = {
        {"plastic kd=0.5 eta=1.9", CDL_MAT_COATED, 0, 0, 0.5f, 0.1f, 0.1f, 1.9f, 1.0f},
        {"plastic kd=0.9 eta=1.5 nonlinear", CDL_MAT_COATED, 0, 1, 0.9f, 0.1f, 0.1f, 1.5f, 1.0f},
        {"roughplastic ggx 0.1 kd=0.5", CDL_MAT_ROUGH_COATED, CDL_MF_GGX, 0, 0.5f, 0.1f, 0.1f, 1.5f, 1.0f},
        {"roughplastic ggx 0.6 kd=0.9 nonlinear", CDL_MAT_ROUGH_COATED, CDL_MF_GGX, 1, 0.9f, 0.6f, 0.6f, 1.5f, 1.0f},
        {"roughplastic beckmann 0.1 kd=0", CDL_MAT_ROUGH_COATED, CDL_MF_BECKMANN, 0, 0.0f, 0.1f, 0.1f, 1.49f, 1.0f},
        {"roughplastic beckmann 0.3 kd=0.5", CDL_MAT_ROUGH_COATED, CDL_MF_BECKMANN, 1, 0.5f, 0.3f, 0.3f, 1.49f, 1.0f},
        {"conductor beckmann 0.2", CDL_MAT_CONDUCTOR, CDL_MF_BECKMANN, 0, 0.0f, 0.2f, 0.2f, 1.0f, 1.0f},
        {"conductor ggx 0.3/0.1", CDL_MAT_CONDUCTOR, CDL_MF_GGX, 0, 0.0f, 0.3f, 0.1f, 1.0f, 1.0f},
        {"mask 0.4 over diffuse", CDL_MAT_DIFFUSE, 0, 0, 0.8f, 0.1f, 0.1f, 1.0f, 0.4f},
        {"mask 0.7 over roughplastic", CDL_MAT_ROUGH_COATED, CDL_MF_GGX, 0, 0.5f, 0.2f, 0.2f, 1.5f, 0.7f},
        {"roughdielectric beckmann 0.3 eta=1.5", CDL_MAT_ROUGH_DIELECTRIC, CDL_MF_BECKMANN, 0, 0.0f, 0.3f, 0.3f, 1.5f,
         1.0f},
        {"roughdielectric ggx 0.2/0.4 eta=1.33", CDL_MAT_ROUGH_DIELECTRIC, CDL_MF_GGX, 0, 0.0f, 0.2f, 0.4f, 1.33f, 1.0f},
    };
    static const double wos[] = {0.0, 40.0, 75.0, 135.0};
    uint64_t stream = 0;
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        for (size_t w = 0; w < sizeof wos / sizeof wos[0]; w++)
        {
            /* Beckmann conductor: from 75deg the sampler (the exact visible
             * normals) and the pdf (Mitsuba's rational G1 fit, < 0.35 % off)
             * differ enough for 200k samples to see, in Mitsuba as here */
            double wd = cases[c].type == CDL_MAT_CONDUCTOR && cases[c].mf == CDL_MF_BECKMANN && wos[w] == 75.0
                            ? 65.0 : wos[w];
            test_case(&cases[c], wd, c == 3 && w == 1, stream++);
        }
    check(chi2_count == N_CHI2, "%d chi-square tests run (N_CHI2 = %d)", chi2_count, N_CHI2);
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}
