/* Tests of Mitsuba 3's principled and principledthin BSDFs
 * (scene/bsdf_principled.c) through candela's BSDF interface:
 *  - chi-square goodness of fit of cdl_bsdf_sample against cdl_bsdf_pdf
 *    over the whole sphere (test_stats.h: adaptive quadrature of the pdf per
 *    bin, failed samples in their own bin), for parameter sets like the
 *    Mitsuba render tests' and ones that exercise every lobe, from both
 *    sides, with the shading normal equal to the geometric one and tilted;
 *  - per-sample consistency: the sample's pdf equals cdl_bsdf_pdf, its
 *    weight equals f |cos| / pdf;
 *  - adjoint symmetry: f(wo, wi) in radiance transport equals f(wi, wo) in
 *    importance transport (plain reciprocity for the reflection lobes and
 *    the thin sheet, the generalized one for principled's refraction);
 *  - white furnace: albedo <= 1 where Mitsuba's model conserves energy
 *    (metallic, dielectric, thin lobes, the scenes' materials); the lobes
 *    that add energy (sheen, clearcoat on a white base) are only reported;
 *  - point values derived by hand from Mitsuba's formulas (normal
 *    incidence, sheen at 60 degrees, pdf);
 *  - parameters from textures, the dp/du tangent, and the Mitsuba reader.
 * Deterministic seeds. Returns 0 when every check passes. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/rng.h"
#include "core/vec.h"
#include "io/loader.h"
#include "scene/bsdf.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "scene/texture.h"

#define N_CHI2 26
#include "test_stats.h"

#define NSAMP 100000

typedef struct pcase {
    const char *name;
    int thin;
    float base[3];
    float p[CDL_PR_NPARAMS]; /* negative: Mitsuba's default */
} pcase;

#define DEF -1.0f
/* roughness, anisotropic, metallic, spec_trans, spec_tint, sheen, sheen_tint, flatness, clearcoat,
 * clearcoat_gloss, diff_trans, eta */
static const pcase CASES[] = {
    {"principled scene 1 (checker means)", 0, {0.2f, 0.8f, 0.1f},
     {0.15f, 0.425f, 0.4f, DEF, DEF, 0.55f, DEF, DEF, 0.5f, DEF, DEF, 1.62f}},
    {"principled scene 2 (rougher)", 0, {0.3f, 0.6f, 0.8f},
     {0.35f, 0.45f, DEF, 0.4f, DEF, 0.55f, DEF, DEF, 0.45f, DEF, DEF, 1.4357f}},
    {"principled every lobe", 0, {0.9f, 0.5f, 0.2f},
     {0.45f, 0.6f, 0.3f, 0.5f, 0.5f, 0.7f, 0.6f, 0.4f, 0.6f, 0.3f, DEF, 1.45f}},
    {"principledthin scene (checker means)", 1, {0.7f, 0.1f, 0.1f},
     {DEF, 0.425f, DEF, 0.5f, DEF, 0.45f, DEF, DEF, DEF, DEF, 0.9f, 1.33f}},
    {"principledthin every lobe", 1, {0.4f, 0.7f, 0.5f},
     {0.3f, 0.5f, DEF, 0.35f, 0.5f, 0.6f, 0.5f, 0.5f, DEF, DEF, 0.6f, 1.6f}},
};

static cdl_material make(const pcase *c)
{
    cdl_material m = cdl_material_default(CDL_MAT_PRINCIPLED);
    m.pr = cdl_principled_default(c->thin);
    m.kd = cdl_v3(c->base[0], c->base[1], c->base[2]);
    for (int i = 0; i < CDL_PR_NPARAMS; i++)
        if (c->p[i] >= 0.0f)
            m.pr.value[i] = c->p[i];
    return m;
}

/* A BSDF with geometric normal geo_normal(), the shading normal tilted by
 * tilt degrees, and a tangent (dp/du) not aligned with the default frame. */
static cdl_bsdf setup(const cdl_material *m, double tilt)
{
    dvec ng = geo_normal();
    dframe gf = dframe_from(ng);
    dvec ns = tilt > 0.0 ? polar(&gf, tilt * DEG, 40.0 * DEG) : ng;
    cdl_bsdf b;
    cdl_bsdf_init(&b, m, m->kd, to_f(ns), to_f(ng));
    cdl_principled_tangent(&b, to_f(dadd(gf.t, dscale(gf.b, 0.7))));
    return b;
}

/* ---- sampling against pdf ------------------------------------------------- */

static void test_sampling(const pcase *c, double wo_deg, double tilt, uint64_t stream)
{
    cdl_material m = make(c);
    cdl_bsdf b = setup(&m, tilt);
    dvec ng = geo_normal();
    dframe gf = dframe_from(ng);
    dvec wod = polar(&gf, wo_deg * DEG, 0.0);
    cdl_vec3 wo = to_f(wod);
    static double obs[NC * NP + 1], expd[NC * NP + 1];
    memset(obs, 0, sizeof obs);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x9e1c1b1eULL, stream);
    long fails = 0, bad = 0, off = 0;
    double max_pdf_err = 0.0, max_w_err = 0.0;
    for (int s = 0; s < NSAMP; s++) {
        float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        cdl_scatter sc;
        if (!cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc)) {
            fails++;
            obs[NC * NP] += 1.0;
            continue;
        }
        if (sc.delta || !(sc.pdf > 0.0f) || !cdl_is_finite3(sc.weight) || fabsf(cdl_length(sc.wi) - 1.0f) > 1e-5f)
            bad++;
        double pe = rel_err(cdl_bsdf_pdf(&b, wo, sc.wi), sc.pdf);
        max_pdf_err = fmax(max_pdf_err, pe);
        off += pe > 1e-3; /* refraction: the half vector from a float wi, near total reflection */
        cdl_vec3 f = cdl_bsdf_eval(&b, wo, sc.wi, 0);
        double cs = fabs(cdl_dot(sc.wi, b.frame.n));
        double we[3] = {f.x * cs / sc.pdf, f.y * cs / sc.pdf, f.z * cs / sc.pdf};
        double wg[3] = {sc.weight.x, sc.weight.y, sc.weight.z};
        for (int k = 0; k < 3; k++) /* cos after the change of frame: ~1e-7 absolute */
            max_w_err = fmax(max_w_err, fabs(we[k] - wg[k]) / (fmax(fabs(we[k]), fabs(wg[k])) + 1e-3));
        double cth, phi;
        dframe_coords(&gf, from_f(sc.wi), &cth, &phi);
        int ic = (int)((cth + 1.0) * 0.5 * NC), ip = (int)(phi / (2.0 * PI_D) * NP);
        ic = ic < 0 ? 0 : ic >= NC ? NC - 1 : ic;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[ic * NP + ip] += 1.0;
    }
    /* expected counts: the pdf integrated over each bin, refined around the
     * specular lobe (mirror of wo about the shading normal) */
    integ g;
    memset(&g, 0, sizeof g);
    g.b = &b;
    g.wo = wo;
    g.fr = gf;
    g.has_lobe = 1;
    dvec n = from_f(b.frame.n);
    g.lobe = dnorm(dsub(dscale(n, 2.0 * ddot(wod, n)), wod));
    g.sigma = 0.05;
    double mass = 0.0;
    for (int ic = 0; ic < NC; ic++)
        for (int ip = 0; ip < NP; ip++) {
            double out[NQ];
            integrate_cell(&g, -1.0 + 2.0 * ic / NC, -1.0 + 2.0 * (ic + 1) / NC, 2.0 * PI_D * ip / NP,
                           2.0 * PI_D * (ip + 1) / NP, out);
            expd[ic * NP + ip] = out[0] * NSAMP;
            mass += out[0];
        }
    expd[NC * NP] = (1.0 - mass) * NSAMP;
    chi2_result r = chi2_test(obs, expd, NC * NP + 1, 5.0);
    char tag[200];
    snprintf(tag, sizeof tag, "%s, wo %g deg%s", c->name, wo_deg, tilt > 0.0 ? ", ns tilted" : "");
    check(r.p > P_MIN && mass <= 1.0 + 1e-3,
          "%s: chi2 %.1f dof %d p %.3g (> %.2g), pdf mass %.4f, success %.4f", tag, r.stat, r.dof, r.p, P_MIN,
          mass, 1.0 - (double)fails / NSAMP);
    check(bad == 0 && off <= NSAMP / 1000 && max_pdf_err < 2e-2 && max_w_err < 2e-2,
          "%s: per sample pdf rel err %.1e (%ld above 1e-3), weight err %.1e, %ld bad", tag, max_pdf_err, off,
          max_w_err, bad);
}

/* ---- adjoint symmetry, energy ---------------------------------------------- */

static void test_symmetry(const pcase *c, uint64_t stream)
{
    cdl_material m = make(c);
    cdl_bsdf b = setup(&m, 0.0);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x5eedULL, stream);
    double worst = 0.0;
    long nonzero = 0, off = 0, thin_odd = 0;
    cdl_vec3 ng = b.ng;
    for (int i = 0; i < 40000; i++) {
        cdl_vec3 a = random_sphere_dir(&rng), d = random_sphere_dir(&rng);
        cdl_vec3 f1 = cdl_bsdf_eval(&b, a, d, 0), f2 = cdl_bsdf_eval(&b, d, a, 1);
        double e = fmax(rel_err(f1.x, f2.x), fmax(rel_err(f1.y, f2.y), rel_err(f1.z, f2.z)));
        if (c->thin && cdl_dot(a, ng) * cdl_dot(d, ng) < 0.0f) {
            /* Mitsuba's thin transmission masks by the sampled microfacet's
             * side, which is not symmetric: not reciprocal, only counted */
            thin_odd += e > 2e-3;
            continue;
        }
        if (fmax(f1.x, f2.x) > 1e-4) { /* float rounding of tiny values */
            worst = fmax(worst, e);
            off += e > 2e-3;
        }
        nonzero += f1.x > 0.0f;
    }
    check(off <= 20 && worst < 5e-2 && nonzero > 1000,
          "%s: f(wo, wi) = f*(wi, wo)%s, max rel err %.1e, %ld of %ld nonzero pairs above 2e-3", c->name,
          c->thin ? " on one side" : "", worst, off, nonzero);
    if (c->thin)
        printf("info: %s: %ld transmission pairs not reciprocal (Mitsuba's side mask)\n", c->name, thin_odd);
}

/* Directional albedo for wo at theta (channel x), importance transport when
 * adjoint (refraction then carries no 1 / eta^2). */
static double albedo(const cdl_material *m, double theta_deg, int adjoint)
{
    cdl_bsdf b = setup(m, 0.0);
    dframe gf = dframe_from(geo_normal());
    dvec wod = polar(&gf, theta_deg * DEG, 0.0);
    integ g;
    memset(&g, 0, sizeof g);
    g.b = &b;
    g.wo = to_f(wod);
    g.fr = gf;
    g.albedo = 1;
    g.adj1 = adjoint;
    g.has_lobe = 1;
    g.lobe = dsub(dscale(gf.n, 2.0 * ddot(wod, gf.n)), wod);
    g.sigma = 0.05;
    double a = 0.0;
    for (int ic = 0; ic < NC; ic++)
        for (int ip = 0; ip < 4; ip++) {
            double out[NQ];
            integrate_cell(&g, -1.0 + 2.0 * ic / NC, -1.0 + 2.0 * (ic + 1) / NC, PI_D * ip / 2, PI_D * (ip + 1) / 2,
                           out);
            a += out[1];
        }
    return a;
}

static void test_energy(void)
{
    static const double TH[] = {0.0, 45.0, 75.0};
    struct {
        const char *name;
        pcase c;
        int adjoint;
        double lo; /* albedo at least this (lobes that lose only by masking) */
    } E[] = {
        {"metallic 1 white", {0, 0, {1, 1, 1}, {0.5f, DEF, 1, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF}}, 0, 0.8},
        {"spec_trans 1 white (importance)",
         {0, 0, {1, 1, 1}, {0.5f, DEF, DEF, 1, DEF, DEF, DEF, DEF, DEF, DEF, DEF, 1.5f}}, 1, 0.85},
        {"thin spec_trans 1 white", {0, 1, {1, 1, 1}, {0.5f, DEF, DEF, 1, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF}}, 0,
         0.5},
        {"thin diff_trans 2 white", {0, 1, {1, 1, 1}, {DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, 2, DEF}}, 0,
         0.999},
        {"scene 1 material", CASES[0], 0, 0.0},
        {"scene 2 material", CASES[1], 0, 0.0},
        {"thin scene material", CASES[3], 0, 0.0},
    };
    for (size_t i = 0; i < sizeof E / sizeof E[0]; i++) {
        cdl_material m = make(&E[i].c);
        double a[3];
        for (int t = 0; t < 3; t++)
            a[t] = albedo(&m, TH[t], E[i].adjoint);
        int ok = 1;
        for (int t = 0; t < 3; t++)
            ok &= a[t] <= 1.0 + 2e-3 && a[t] >= E[i].lo;
        check(ok, "white furnace, %s: albedo %.4f %.4f %.4f at 0/45/75 deg (<= 1, >= %g)", E[i].name, a[0], a[1],
              a[2], E[i].lo);
    }
    /* Not energy conserving in Mitsuba's (and Burley's) model: reported only. */
    pcase hot = {0, 0, {1, 1, 1}, {0.8f, DEF, DEF, DEF, DEF, 1, DEF, DEF, 1, DEF, DEF, DEF}};
    cdl_material m = make(&hot);
    printf("info: white base, roughness 0.8, sheen 1, clearcoat 1: albedo %.4f %.4f %.4f at 0/45/75 deg\n",
           albedo(&m, 0.0, 0), albedo(&m, 45.0, 0), albedo(&m, 75.0, 0));
}

/* ---- values derived by hand -------------------------------------------------- */

static cdl_vec3 eval_local(const cdl_material *m, cdl_vec3 wo, cdl_vec3 wi, int adjoint)
{
    cdl_bsdf b;
    cdl_vec3 n = cdl_v3(0, 0, 1);
    cdl_bsdf_init(&b, m, m->kd, n, n);
    return cdl_bsdf_eval(&b, wo, wi, adjoint);
}

static int near(double a, double b) { return fabs(a - b) <= 2e-5 * fmax(1.0, fabs(b)); }

static void test_values(void)
{
    const double pi = PI_D;
    cdl_vec3 up = cdl_v3(0, 0, 1), down = cdl_v3(0, 0, -1);
    /* specular 0.5: eta = 2 / (1 - sqrt(0.04)) - 1 = 1.5, F(0) = 0.04; roughness 0.5: alpha 0.25 */
    pcase d = {0, 0, {0.6f, 0.3f, 0.1f}, {DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF, DEF}};
    cdl_material m = make(&d);
    check(fabsf(m.pr.value[CDL_PR_ETA] - 1.5f) < 1e-6f, "default specular 0.5 gives eta %.7f (1.5)",
          (double)m.pr.value[CDL_PR_ETA]);
    double a = 0.25, D = 1.0 / (pi * a * a);
    /* normal in, normal out: Fo = Fi = 0, retro term 0, wh = n, G = 1 */
    cdl_vec3 f = eval_local(&m, up, up, 0);
    check(near(f.x, 0.6 / pi + 0.04 * D / 4.0) && near(f.z, 0.1 / pi + 0.04 * D / 4.0),
          "normal incidence: f = base / pi + F0 D / 4 = %.6f (%.6f)", (double)f.x, 0.6 / pi + 0.01 * D);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &m, m.kd, up, up);
    double pdf = cdl_bsdf_pdf(&b, up, up);
    check(near(pdf, 0.5 * (D / 4.0 + 1.0 / pi)), "normal incidence pdf = (D / 4 + 1 / pi) / 2 = %.6f (%.6f)", pdf,
          0.5 * (D / 4.0 + 1.0 / pi));
    /* metallic 1: Schlick with F0 = base, no diffuse */
    m.pr.value[CDL_PR_METALLIC] = 1.0f;
    f = eval_local(&m, up, up, 0);
    check(near(f.x, 0.6 * D / 4.0) && near(f.y, 0.3 * D / 4.0), "metallic 1 at normal incidence: base D / 4 = %.5f (%.5f)",
          (double)f.x, 0.6 * D / 4.0);
    /* clearcoat 1, gloss 0: 0.25 * 0.04 * GTR1(n; 0.1), no 1 / (4 cos cos) in Mitsuba's lobe */
    m = make(&d);
    m.pr.value[CDL_PR_CLEARCOAT] = 1.0f;
    double a2 = 0.01, Dcc = (a2 - 1.0) / (pi * log(a2) * a2);
    f = eval_local(&m, up, up, 0);
    check(near(f.x, 0.6 / pi + 0.01 * D + 0.01 * Dcc), "clearcoat at normal incidence adds 0.01 GTR1 = %.5f (%.5f)",
          (double)f.x - (0.6 / pi + 0.01 * D), 0.01 * Dcc);
    /* sheen 0.8, mirror pair at 60 deg (wh = n, cos_d = 0.5): adds sheen Fd = 0.8 * 0.5^5 (no 1 / pi);
     * sheen_tint 1 tints by base / lum */
    m = make(&d);
    cdl_vec3 w60 = cdl_v3(sqrtf(0.75f), 0.0f, 0.5f), m60 = cdl_v3(-sqrtf(0.75f), 0.0f, 0.5f);
    cdl_vec3 f0 = eval_local(&m, w60, m60, 0);
    m.pr.value[CDL_PR_SHEEN] = 0.8f;
    f = eval_local(&m, w60, m60, 0);
    check(near(f.y - f0.y, 0.8 * 0.03125), "sheen 0.8 at 60 deg adds %.6f (0.025)", (double)(f.y - f0.y));
    m.pr.value[CDL_PR_SHEEN_TINT] = 1.0f;
    f = eval_local(&m, w60, m60, 0);
    double lum = 0.212671 * 0.6 + 0.715160 * 0.3 + 0.072169 * 0.1;
    check(near(f.x - f0.x, 0.025 * 0.6 / lum), "tinted sheen adds 0.025 base.r / lum = %.6f (%.6f)",
          (double)(f.x - f0.x), 0.025 * 0.6 / lum);
    /* spec_trans 1, straight through: sqrt(base) (1 - F) D |eta^2 / (1 - eta)^2| / eta^2 (radiance) */
    m = make(&d);
    m.pr.value[CDL_PR_SPEC_TRANS] = 1.0f;
    f = eval_local(&m, up, down, 0);
    cdl_vec3 fi = eval_local(&m, up, down, 1);
    check(near(f.x, sqrt(0.6) * 0.96 * D / 0.25) && near(fi.x, sqrt(0.6) * 0.96 * D * 2.25 / 0.25),
          "spec_trans 1 at normal incidence: radiance %.4f (%.4f), importance %.4f (%.4f)", (double)f.x,
          sqrt(0.6) * 3.84 * D, (double)fi.x, sqrt(0.6) * 8.64 * D);
    /* principledthin eta 1.5, spec_trans 0.5, diff_trans 1: transmission roughness (0.65 * 1.5 - 0.35) 0.5 */
    pcase t = {0, 1, {0.6f, 0.3f, 0.1f}, {DEF, DEF, DEF, 0.5f, DEF, DEF, DEF, DEF, DEF, DEF, 1.0f, DEF}};
    m = make(&t);
    double at = pow(0.625 * 0.5, 2.0), Dt = 1.0 / (pi * at * at);
    f = eval_local(&m, up, down, 0);
    double want = 0.5 * 0.6 * 0.96 * Dt / 4.0 + 0.5 * 0.5 * 0.6 / pi;
    check(near(f.x, want), "thin straight through: st base (1 - F) D' / 4 + (1 - st) dt base / pi = %.5f (%.5f)",
          (double)f.x, want);
    f = eval_local(&m, down, up, 0);
    check(near(f.x, want), "thin from the back: the same %.5f", (double)f.x);
}

/* ---- textures, tangent, reader ------------------------------------------------ */

static void test_textures(void)
{
    float px[6] = {0.2f, 0.2f, 0.2f, 1.0f, 0.5f, 0.0f};
    cdl_texture tex;
    cdl_texture_init(&tex, CDL_TEX_BITMAP);
    tex.w = 2;
    tex.h = 1;
    tex.rgb = px;
    cdl_principled pr = cdl_principled_default(0);
    pr.value[CDL_PR_METALLIC] = 0.5f;
    pr.tex[CDL_PR_METALLIC] = 0;
    pr.value[CDL_PR_SHEEN] = 3.0f; /* out of range: clamped */
    cdl_principled_at p;
    cdl_principled_at_init(&p, &pr, &tex, 0.25f, 0.5f);
    float left = p.p[CDL_PR_METALLIC];
    cdl_principled_at_init(&p, &pr, &tex, 0.75f, 0.5f);
    float right = p.p[CDL_PR_METALLIC];
    float lum = 0.212671f + 0.715160f * 0.5f;
    check(fabsf(left - 0.1f) < 1e-5f && fabsf(right - 0.5f * lum) < 1e-5f && p.p[CDL_PR_SHEEN] == 1.0f,
          "texture parameters: scale x luminance %.4f / %.4f (0.1 / %.4f), sheen clamped to %g", (double)left,
          (double)right, (double)(0.5f * lum), (double)p.p[CDL_PR_SHEEN]);
    cdl_material m = cdl_material_default(CDL_MAT_PRINCIPLED);
    m.pr = cdl_principled_default(0);
    cdl_bsdf b;
    cdl_vec3 n = cdl_normalize(cdl_v3(0, 1, 1));
    cdl_bsdf_init(&b, &m, m.kd, n, n);
    cdl_principled_tangent(&b, cdl_v3(2, 0, 0));
    check(fabsf(b.frame.t.x - 1.0f) < 1e-6f && fabsf(cdl_dot(b.frame.b, n)) < 1e-6f &&
              fabsf(cdl_dot(cdl_cross(b.frame.t, b.frame.b), n) - 1.0f) < 1e-6f,
          "tangent along dp/du (1 0 0), frame right-handed");
}

static void test_reader(void)
{
    char dir[] = "/tmp/candela-principled.XXXXXX";
    if (!mkdtemp(dir)) {
        check(0, "mkdtemp");
        return;
    }
    char path[256];
    snprintf(path, sizeof path, "%s/p.xml", dir);
    FILE *fp = fopen(path, "w");
    fputs("<scene version=\"3.0.0\">\n"
          "<shape type=\"rectangle\"><bsdf type=\"principled\">"
          "<rgb name=\"base_color\" value=\"0.2, 0.8, 0.1\"/><float name=\"roughness\" value=\"0.15\"/>"
          "<float name=\"specular\" value=\"0.7\"/><float name=\"spec_trans\" value=\"0.3\"/>"
          "<float name=\"clearcoat\" value=\"0.9\"/></bsdf></shape>\n"
          "<shape type=\"rectangle\"><bsdf type=\"principledthin\">"
          "<float name=\"diff_trans\" value=\"1.4\"/><float name=\"eta\" value=\"1.33\"/>"
          "<float name=\"specular_transmittance_sampling_rate\" value=\"0.5\"/></bsdf></shape>\n"
          "<shape type=\"rectangle\"><bsdf type=\"principled\"><float name=\"eta\" value=\"1\"/>"
          "<float name=\"spec_trans\" value=\"1\"/></bsdf></shape>\n"
          "</scene>\n",
          fp);
    fclose(fp);
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    int rc = cdl_scene_init(&s, path, &err);
    if (!rc)
        rc = cdl_scene_load(&s, path, &set, &err);
    check(rc == 0 && s.nmats == 3, "reader: principled, principledthin load (%u materials)", rc ? 0 : s.nmats);
    if (!rc && s.nmats == 3) {
        const cdl_material *m = s.mats;
        double eta07 = 2.0 / (1.0 - sqrt(0.08 * 0.7)) - 1.0;
        check(m[0].type == CDL_MAT_PRINCIPLED && !m[0].pr.thin && fabsf(m[0].kd.y - 0.8f) < 1e-6f &&
                  fabsf(m[0].pr.value[CDL_PR_ROUGHNESS] - 0.15f) < 1e-6f &&
                  fabsf(m[0].pr.value[CDL_PR_CLEARCOAT] - 0.9f) < 1e-6f &&
                  fabsf(m[0].pr.value[CDL_PR_ETA] - (float)eta07) < 1e-5f && m[0].pr.rate[2] == 1.0f,
              "principled: base_color, roughness, clearcoat, eta from specular 0.7 = %.5f (%.5f)",
              (double)m[0].pr.value[CDL_PR_ETA], eta07);
        check(m[1].pr.thin && fabsf(m[1].pr.value[CDL_PR_DIFF_TRANS] - 1.4f) < 1e-6f &&
                  fabsf(m[1].pr.value[CDL_PR_ETA] - 1.33f) < 1e-6f && m[1].pr.rate[2] == 0.5f &&
                  fabsf(m[1].kd.x - 0.5f) < 1e-6f && fabsf(m[1].pr.value[CDL_PR_ROUGHNESS] - 0.5f) < 1e-6f,
              "principledthin: diff_trans 1.4, eta 1.33, sampling rate, defaults base 0.5, roughness 0.5");
        check(fabsf(m[2].pr.value[CDL_PR_ETA] - 1.001f) < 1e-6f, "eta 1 with spec_trans becomes 1.001 as in Mitsuba");
    }
    if (!rc)
        cdl_scene_free(&s);
    fp = fopen(path, "w");
    fputs("<scene version=\"3.0.0\"><shape type=\"rectangle\"><bsdf type=\"principled\">"
          "<float name=\"eta\" value=\"1.5\"/><float name=\"specular\" value=\"0.5\"/></bsdf></shape></scene>\n",
          fp);
    fclose(fp);
    rc = cdl_scene_init(&s, path, &err);
    if (!rc) {
        int rc2 = cdl_scene_load(&s, path, &set, &err);
        check(rc2 != 0 && err.line == 1, "eta and specular together: an error at line %d", err.line);
        cdl_scene_free(&s);
    }
    remove(path);
    rmdir(dir);
}

int main(void)
{
    test_gamma(0);
    static const double WO[] = {0.0, 35.0, 70.0, 88.0};
    uint64_t stream = 1;
    for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++) {
        for (int k = 0; k < 4; k++)
            test_sampling(&CASES[c], WO[k], 0.0, stream++);
        if (CASES[c].p[CDL_PR_SPEC_TRANS] > 0.0f) /* transmissive: from below too */
            test_sampling(&CASES[c], 140.0, 0.0, stream++);
    }
    test_sampling(&CASES[2], 50.0, 12.0, stream++);
    test_sampling(&CASES[4], 50.0, 12.0, stream++);
    for (size_t c = 0; c < sizeof CASES / sizeof CASES[0]; c++)
        test_symmetry(&CASES[c], stream++);
    test_energy();
    test_values();
    test_textures();
    test_reader();
    check(chi2_count == N_CHI2, "%d chi-square tests (N_CHI2 %d)", chi2_count, N_CHI2);
    printf("%d of %d checks failed\n", failures, checks);
    return failures != 0;
}
