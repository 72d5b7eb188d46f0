/* Statistical and exactness tests of the microfacet BSDFs (scene/bsdf.c,
 * scene/microfacet.c): GGX conductor, plastic, rough glass. The classic
 * BSDFs are tested by test_bsdf.c; the quadrature and chi-square machinery
 * both programs use lives in test_stats.h.
 *
 * Deterministic seeds: the outcome never changes between runs. Returns 0
 * when every check passes. */
#include <complex.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/vec.h"
#include "scene/bsdf.h"
#include "scene/material.h"
#include "scene/microfacet.h"

#include "test_stats.h"


/* Chi-square tests in this program, for the Sidak correction of P_MIN
 * (test_stats.h). */
#define N_CHI2 168

/* ---- microfacet materials ------------------------------------------------ */

/* Conductor (gold, and a "perfect" conductor for furnace tests), plastic and
 * rough glass, each against:
 *  - the machinery of test_stats.h: chi-square of the samples against cdl_bsdf_pdf over
 *    the sphere in the geometric normal's frame and, for narrow lobes, in
 *    the frame of each lobe axis (bins uniform in the GGX slope CDF), pdf
 *    mass vs success rate, per-sample pdf / weight consistency, albedo by
 *    Monte Carlo and by quadrature;
 *  - an independent double precision reference of f: GGX D in slope space,
 *    Smith's height-correlated G, Fresnel of a complex index (complex
 *    arithmetic), angle-form dielectric Fresnel, Walter et al. 2007
 *    transmission;
 *  - the exact weights of VNDF sampling: F G(lo,li) / G1(lo) for the
 *    conductor, G / G1 for rough glass in importance transport;
 *  - reciprocity; for refraction the generalized form (Veach 1997, 5.14)
 *    and the adjoint f*(wo, wi) = f(wi, wo);
 *  - energy: white furnace of the perfect conductor, plastic's Lambert and
 *    specular parts, rough glass in importance transport.
 * The sampling of the conductor does not depend on its Fresnel term and
 * that of rough glass not on the transport mode: the same random numbers
 * must give the same direction and pdf (gold vs perfect, radiance vs
 * importance).
 *
 * Float conditioning: near the critical angle 1 - F has an infinite
 * derivative, G and 1/cos blow up at grazing angles, and the support of
 * f ends abruptly (total internal reflection, back-facing microfacets).
 * There a float evaluation legitimately disagrees with a double one, or
 * with itself at the same direction computed another way. A comparison
 * that misses its tolerance is therefore repeated with the library value's
 * own sensitivity: its largest change when wo or wi moves by 1e-6 (a few
 * float ulps) along an axis; twice that is allowed on top. The output
 * counts the pairs explained this way; any left over fails. */

#define NMF 60000       /* samples per microfacet case */
#define NREF 12000      /* sampled pairs also checked against the reference */
#define LOBE_S_MAX 0.98 /* lobe-frame bins cover this share of the GGX slopes */
#define PERFECT_K 1e4f  /* eta 0 + i 1e4: F = 1 at every angle */
#define JIT 1e-6f       /* nudge of the conditioning estimate */
#define MF_TOL_ABS 1e-7 /* quadrature tolerances: expected counts to ~0.01 */
#define MF_TOL_REL 3e-5

typedef struct mf_case {
    const char *name;
    cdl_mat_type type;
    float ax, ay;
} mf_case;

static const float GOLD_ETA[3] = {0.143f, 0.374f, 1.442f};
static const float GOLD_K[3] = {3.983f, 2.385f, 1.603f};

/* GGX distribution in slope space: D(h) = P22(hx/hz, hy/hz) / hz^4. */
static double ref_D(dvec h, double ax, double ay)
{
    if (h.z <= 0.0)
        return 0.0;
    double sx = h.x / (h.z * ax), sy = h.y / (h.z * ay);
    double e = 1.0 + sx * sx + sy * sy, z2 = h.z * h.z;
    return 1.0 / (PI_D * ax * ay * z2 * z2 * e * e);
}
static double ref_lambda(dvec w, double ax, double ay)
{
    double z2 = w.z * w.z;
    if (z2 == 0.0)
        return INFINITY;
    return 0.5 * (sqrt(1.0 + (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / z2) - 1.0);
}
static double ref_G1(dvec w, double ax, double ay) { return 1.0 / (1.0 + ref_lambda(w, ax, ay)); }
static double ref_G(dvec a, dvec b, double ax, double ay)
{
    return 1.0 / (1.0 + ref_lambda(a, ax, ay) + ref_lambda(b, ax, ay));
}
/* G(lo,li) / G1(lo) and its largest change when li moves by JIT. */
static double ref_gg(dvec lo, dvec li, double ax, double ay) { return ref_G(lo, li, ax, ay) / ref_G1(lo, ax, ay); }
static double ref_gg_jitter(dvec lo, dvec li, double ax, double ay)
{
    double v = ref_gg(lo, li, ax, ay), m = 0.0;
    for (int k = 0; k < 6; k++) {
        double d = (k & 1 ? -1.0 : 1.0) * JIT;
        dvec l2 = dv(li.x + (k / 2 == 0 ? d : 0.0), li.y + (k / 2 == 1 ? d : 0.0), li.z + (k / 2 == 2 ? d : 0.0));
        m = fmax(m, fabs(ref_gg(lo, l2, ax, ay) - v));
    }
    return m;
}

/* Fresnel reflectance from vacuum onto a medium of complex index eta + i k:
 * rs = (c - w) / (c + w), rp = (n^2 c - w) / (n^2 c + w), w = n cos_t =
 * sqrt(n^2 - sin^2) on the principal branch. */
static double ref_fresnel_conductor(double cos_i, double eta, double k)
{
    double complex n2 = (eta + I * k) * (eta + I * k);
    double c = fmin(1.0, fabs(cos_i));
    double complex w = csqrt(n2 - (1.0 - c * c));
    double complex rs = (c - w) / (c + w), rp = (n2 * c - w) / (n2 * c + w);
    double as = cabs(rs), ap = cabs(rp);
    return 0.5 * (as * as + ap * ap);
}

/* Dielectric Fresnel for |cos_i| from index eta_i into eta_t. */
static double ref_fresnel_dielectric(double cos_i, double eta_i, double eta_t)
{
    return fresnel_ref(acos(fmin(1.0, fabs(cos_i))), eta_i, eta_t);
}

typedef struct mf_ref {
    cdl_mat_type type;
    double ax, ay, eta, kd, ks, kt;
    double eta3[3], k3[3];
} mf_ref;

/* f in the local shading frame (opaque: both directions already flipped to
 * wo's side; glass: +z = outside). Radiance transport unless adjoint. */
static void ref_eval(const mf_ref *r, dvec lo, dvec li, int adjoint, double f[3])
{
    f[0] = f[1] = f[2] = 0.0;
    if (r->type != CDL_MAT_ROUGH_DIELECTRIC) {
        if (lo.z <= 0.0 || li.z <= 0.0)
            return;
        dvec h = dnorm(dadd(lo, li));
        double m = ref_D(h, r->ax, r->ay) * ref_G(lo, li, r->ax, r->ay) / (4.0 * lo.z * li.z);
        double ch = ddot(li, h);
        for (int c = 0; c < 3; c++)
            f[c] = r->type == CDL_MAT_CONDUCTOR
                       ? m * ref_fresnel_conductor(ch, r->eta3[c], r->k3[c])
                       : r->kd / PI_D + r->ks * m * ref_fresnel_dielectric(ch, 1.0, r->eta);
        return;
    }
    double co = lo.z, ci = li.z;
    if (co == 0.0 || ci == 0.0)
        return;
    double eo = co > 0.0 ? 1.0 : r->eta, ei = ci > 0.0 ? 1.0 : r->eta; /* index on each side */
    double G = ref_G(lo, li, r->ax, r->ay), v;
    if (co * ci > 0.0) {
        dvec h = dnorm(dadd(lo, li));
        if (h.z < 0.0)
            h = dscale(h, -1.0);
        double F = ref_fresnel_dielectric(ddot(lo, h), eo, co > 0.0 ? r->eta : 1.0);
        v = r->ks * ref_D(h, r->ax, r->ay) * G * F / (4.0 * fabs(co * ci));
    } else {
        /* Walter et al. eq. 16 and 21 with i = li (where light comes from), o = lo */
        dvec h = dnorm(dscale(dadd(dscale(lo, eo), dscale(li, ei)), -1.0));
        if (h.z < 0.0)
            h = dscale(h, -1.0);
        double doh = ddot(lo, h), dih = ddot(li, h);
        if (doh * co <= 0.0 || dih * ci <= 0.0)
            return;
        double F = ref_fresnel_dielectric(doh, eo, ei);
        double den = ei * dih + eo * doh;
        /* radiance: eta_o^2; importance, the adjoint f*(wo, wi) = f(wi, wo): eta_i^2 */
        double num = adjoint ? ei * ei : eo * eo;
        v = r->kt * fabs(dih * doh / (ci * co)) * num * (1.0 - F) * G * ref_D(h, r->ax, r->ay) /
            (den * den);
    }
    f[0] = f[1] = f[2] = v;
}

static dvec to_local_d(const dframe *f, dvec w) { return dv(ddot(w, f->t), ddot(w, f->b), ddot(w, f->n)); }

/* Library value: what 0/1 = f (radiance / importance) channel c, 2 = pdf. */
static double lib_val(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int what, int c)
{
    if (what == 2)
        return cdl_bsdf_pdf(b, wo, wi);
    cdl_vec3 f = cdl_bsdf_eval(b, wo, wi, what);
    return c == 0 ? f.x : c == 1 ? f.y : f.z;
}

/* Largest change of a library value when wo or wi moves by JIT along an axis. */
static double lib_jitter(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi, int what, int c)
{
    double v0 = lib_val(b, wo, wi, what, c), m = 0.0;
    for (int k = 0; k < 6; k++) {
        float d = (k & 1 ? -1.0f : 1.0f) * JIT;
        cdl_vec3 e = cdl_v3(k / 2 == 0 ? d : 0.0f, k / 2 == 1 ? d : 0.0f, k / 2 == 2 ? d : 0.0f);
        m = fmax(m, fabs(lib_val(b, cdl_add(wo, e), wi, what, c) - v0));
        m = fmax(m, fabs(lib_val(b, wo, cdl_add(wi, e), what, c) - v0));
    }
    return m;
}

/* Whether the zero / non-zero status of f or of the pdf changes when wo or
 * wi moves by JIT. */
static int support_edge(const cdl_bsdf *b, cdl_vec3 wo, cdl_vec3 wi)
{
    int f0 = lib_val(b, wo, wi, 0, 0) > 0.0, p0 = lib_val(b, wo, wi, 2, 0) > 0.0;
    for (int k = 0; k < 6; k++) {
        float d = (k & 1 ? -1.0f : 1.0f) * JIT;
        cdl_vec3 e = cdl_v3(k / 2 == 0 ? d : 0.0f, k / 2 == 1 ? d : 0.0f, k / 2 == 2 ? d : 0.0f);
        for (int side = 0; side < 2; side++) {
            cdl_vec3 o = side ? wo : cdl_add(wo, e), i = side ? cdl_add(wi, e) : wi;
            if ((lib_val(b, o, i, 0, 0) > 0.0) != f0 || (lib_val(b, o, i, 2, 0) > 0.0) != p0)
                return 1;
        }
    }
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* A comparison over many pairs: largest relative error, pairs beyond the
 * tolerance explained by float conditioning, and the others. */
typedef struct cmp_stat {
    double max_err;
    long n, explained, beyond;
} cmp_stat;

static int cmp_within(double a, double b, double tol, double slack)
{
    return fabs(a - b) <= tol * fmax(fabs(a), fabs(b)) + slack;
}

/* jit is evaluated only when the plain tolerance is missed. */
#define CMP(st, a, b, tol, slack, jit)                                                             \
    do {                                                                                           \
        double a_ = (a), b_ = (b);                                                                 \
        (st).max_err = fmax((st).max_err, rel_err(a_, b_));                                        \
        (st).n++;                                                                                  \
        if (!cmp_within(a_, b_, (tol), (slack))) {                                                 \
            if (cmp_within(a_, b_, (tol), (slack) + 2.0 * (jit)))                                  \
                (st).explained++;                                                                  \
            else                                                                                   \
                (st).beyond++;                                                                     \
        }                                                                                          \
    } while (0)

static void cmp_check(const cmp_stat *st, double tol, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    check(st->beyond == 0,
          "%s: max relative error %.2e over %ld; beyond %g: %ld within float conditioning, %ld "
          "not (0)",
          what, st->max_err, st->n, tol, st->explained, st->beyond);
}

static void test_conductor_fresnel(void)
{
    double worst = 0.0, worst_p = 0.0;
    for (int i = 0; i <= 90; i++) {
        float c = (float)cos(i * DEG);
        for (int k = 0; k < 3; k++) {
            double want = ref_fresnel_conductor(c, GOLD_ETA[k], GOLD_K[k]);
            worst = fmax(worst, fabs(cdl_fresnel_conductor1(c, GOLD_ETA[k], GOLD_K[k]) - want));
        }
        worst_p = fmax(worst_p, fabs(cdl_fresnel_conductor1(c, 0.0f, PERFECT_K) - 1.0));
    }
    check(worst <= 1e-5,
          "conductor Fresnel of gold (0.143, 0.374, 1.442) + i (3.983, 2.385, 1.603) vs complex "
          "arithmetic, 0..90deg: max |diff| %.2e (<= 1e-5)",
          worst);
    check(worst_p <= 1e-5, "conductor Fresnel of eta 0 + i %g: max |F - 1| %.2e (<= 1e-5)",
          (double)PERFECT_K, worst_p);
    /* Normal incidence: ((n-1)^2 + k^2) / ((n+1)^2 + k^2). */
    cdl_vec3 f = cdl_fresnel_conductor(1.0f, cdl_v3(GOLD_ETA[0], GOLD_ETA[1], GOLD_ETA[2]),
                                       cdl_v3(GOLD_K[0], GOLD_K[1], GOLD_K[2]));
    double got[3] = {f.x, f.y, f.z}, w0 = 0.0;
    for (int k = 0; k < 3; k++) {
        double n = GOLD_ETA[k], kk = GOLD_K[k];
        w0 = fmax(w0, fabs(got[k] - ((n - 1) * (n - 1) + kk * kk) / ((n + 1) * (n + 1) + kk * kk)));
    }
    check(w0 <= 1e-6,
          "conductor Fresnel of gold at normal incidence (%.4f, %.4f, %.4f) vs "
          "((n-1)^2+k^2)/((n+1)^2+k^2): max |diff| %.2e (<= 1e-6)",
          got[0], got[1], got[2], w0);
}

static void test_microfacet(const mf_case *mc, double wo_deg, int tilted, uint64_t stream)
{
    const int glass = mc->type == CDL_MAT_ROUGH_DIELECTRIC;
    const int cond = mc->type == CDL_MAT_CONDUCTOR;
    const int plastic = mc->type == CDL_MAT_PLASTIC;
    const double eta = 1.5, kd = plastic ? 0.5 : 0.0, ks = plastic ? 0.5 : 1.0;
    const double ax = mc->ax, ay = mc->ay;
    dvec ngd = geo_normal();
    dframe gf = dframe_from(ngd);
    dvec nsd = tilted ? polar(&gf, 10.0 * DEG, 40.0 * DEG) : ngd;
    cdl_vec3 wo = to_f(polar(&gf, wo_deg * DEG, 0.0));
    dvec wod = from_f(wo); /* exactly what the library sees */

    cdl_material m;
    memset(&m, 0, sizeof m);
    m.type = mc->type;
    m.kd_tex = -1;
    m.kd = cdl_v3((float)kd, (float)kd, (float)kd);
    m.ks = cdl_v3((float)ks, (float)ks, (float)ks);
    m.kt = cdl_v3(1.0f, 1.0f, 1.0f);
    m.eta = (float)eta;
    m.alpha_x = mc->ax;
    m.alpha_y = mc->ay;
    m.eta3 = cdl_v3(GOLD_ETA[0], GOLD_ETA[1], GOLD_ETA[2]);
    m.k3 = cdl_v3(GOLD_K[0], GOLD_K[1], GOLD_K[2]);
    /* b2: conductor -> the perfect one; plastic -> its specular part alone.
     * b3 (plastic): the perfect conductor of the same roughness. */
    cdl_material m2 = m, m3 = m;
    m2.eta3 = m3.eta3 = cdl_v3(0.0f, 0.0f, 0.0f);
    m2.k3 = m3.k3 = cdl_v3(PERFECT_K, PERFECT_K, PERFECT_K);
    m2.kd = cdl_v3(0.0f, 0.0f, 0.0f);
    m3.type = CDL_MAT_CONDUCTOR;
    m3.ks = cdl_v3(1.0f, 1.0f, 1.0f); /* a conductor's ks scales it */
    cdl_bsdf b, b2, b3;
    cdl_bsdf_init(&b, &m, m.kd, to_f(nsd), to_f(ngd));
    cdl_bsdf_init(&b2, &m2, m2.kd, to_f(nsd), to_f(ngd));
    cdl_bsdf_init(&b3, &m3, m3.kd, to_f(nsd), to_f(ngd));
    mf_ref ref = {mc->type, ax, ay, eta, kd, ks, 1.0, {0}, {0}};
    for (int c = 0; c < 3; c++) {
        ref.eta3[c] = GOLD_ETA[c];
        ref.k3[c] = GOLD_K[c];
    }
    mf_ref ref2 = ref;
    ref2.kd = 0.0;
    for (int c = 0; c < 3; c++) {
        ref2.eta3[c] = 0.0;
        ref2.k3[c] = PERFECT_K;
    }

    char tag[200], al[48];
    if (mc->ax == mc->ay)
        snprintf(al, sizeof al, "alpha=%g", mc->ax);
    else
        snprintf(al, sizeof al, "alpha=(%g,%g)", mc->ax, mc->ay);
    if (glass)
        snprintf(tag, sizeof tag, "%s %s wo from %s %gdeg%s", mc->name, al,
                 wo_deg > 90.0 ? "inside" : "outside", wo_deg > 90.0 ? 180.0 - wo_deg : wo_deg,
                 tilted ? " ns tilted 10deg" : "");
    else
        snprintf(tag, sizeof tag, "%s %s wo=%gdeg%s%s", mc->name, al, wo_deg,
                 wo_deg > 90.0 ? " (back side)" : "", tilted ? " ns tilted 10deg" : "");

    /* The library's shading frame, in double: it orients alpha_x. */
    dframe sf = {from_f(b.frame.t), from_f(b.frame.b), from_f(b.frame.n)};
    double go = ddot(wod, ngd);
    dvec lo = to_local_d(&sf, wod);
    /* glass: index on wo's side, by the shading side as the library decides */
    double eta_wo = lo.z > 0.0 ? 1.0 : eta;

    /* Lobe axes: mirror of wo about ns; refraction of wo through ns. */
    double cso = lo.z;
    dvec raxis = dnorm(dsub(dscale(sf.n, 2.0 * cso), wod)), taxis = raxis;
    int has_t = 0;
    double kscale[2] = {2.0, 1.0}; /* lobe angle ~ kscale * microfacet angle */
    if (glass) {
        dvec nw = cso > 0.0 ? sf.n : dscale(sf.n, -1.0);
        double ci = fabs(cso), er = cso > 0.0 ? eta : 1.0 / eta;
        double s2t = (1.0 - ci * ci) / (er * er);
        if (s2t < 1.0) {
            has_t = 1;
            taxis = dnorm(dadd(dscale(wod, -1.0 / er), dscale(nw, ci / er - sqrt(1.0 - s2t))));
            kscale[1] = fabs(1.0 - 1.0 / er);
        }
    }
    /* alpha from float: compare with a margin (0.1f > 0.1) */
    double amin = fmin(ax, ay) - 1e-6, aeff = sqrt(ax * ay);
    int nl = amin <= 0.1 ? 1 + has_t : 0; /* lobe-frame chi-square tests */
    dvec axes[2] = {raxis, taxis};
    dframe lf[2];
    double cb[2][NC + 1]; /* lobe-frame bin boundaries in cos(angle to axis), decreasing */
    for (int l = 0; l < nl; l++) {
        lf[l] = dframe_from(axes[l]);
        for (int i = 0; i <= NC; i++) {
            double s = LOBE_S_MAX * i / NC;
            cb[l][i] = cos(kscale[l] * atan(aeff * sqrt(s / (1.0 - s))));
        }
        cb[l][0] = 1.0;
    }

    /* Sampling. */
    static double obs[NC * NP + 1], lobs[2][NC * NP + 1];
    memset(obs, 0, sizeof obs);
    memset(lobs, 0, sizeof lobs);
    cdl_rng rng;
    cdl_rng_seed(&rng, 0x6d1c2f3aULL, stream);
    long fails = 0, bad_side = 0, bad_unit = 0, bad_misc = 0, bad_pair = 0, nrefl = 0;
    double max_w[2] = {0.0, 0.0};
    cmp_stat st_pdf = {0}, st_w = {0}, st_gw = {0}, st_ref = {0}, st_rec = {0}, st_adj = {0};
    double ws[2] = {0.0, 0.0}, ws2[2] = {0.0, 0.0};
    static double ratios[NREF];
    long nratio = 0;
    for (int s = 0; s < NMF; s++) {
        float u0 = cdl_rng_float(&rng), u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
        cdl_scatter sc, sc2;
        int ok = cdl_bsdf_sample(&b, wo, u0, u1, u2, 0, &sc);
        /* glass: the same sample in importance transport; conductor: the perfect one */
        int ok2 = 0;
        if (glass || cond) {
            ok2 = cdl_bsdf_sample(glass ? &b : &b2, wo, u0, u1, u2, glass, &sc2);
            if (ok2 != ok || (ok && (sc2.wi.x != sc.wi.x || sc2.wi.y != sc.wi.y ||
                                     sc2.wi.z != sc.wi.z || sc2.pdf != sc.pdf)))
                bad_pair++;
        }
        if (!ok) {
            fails++;
            obs[NC * NP] += 1.0;
            lobs[0][NC * NP] += 1.0;
            lobs[1][NC * NP] += 1.0;
            continue;
        }
        if (sc.delta || !(sc.pdf > 0.0f) || !cdl_is_finite3(sc.weight) || !isfinite(sc.pdf) ||
            (ok2 && !cdl_is_finite3(sc2.weight)))
            bad_misc++;
        dvec wi = from_f(sc.wi);
        if (fabs(sqrt(ddot(wi, wi)) - 1.0) > 1e-5)
            bad_unit++;
        dvec li = to_local_d(&sf, wi);
        int same = ddot(wi, ngd) * go > 0.0;
        if (glass ? same != (li.z * lo.z > 0.0) : !same)
            bad_side++;
        nrefl += same;
        double eta_wi = li.z > 0.0 ? 1.0 : eta;
        double pdf2 = cdl_bsdf_pdf(&b, wo, sc.wi);
        CMP(st_pdf, pdf2, sc.pdf, 1e-3, 0.0, lib_jitter(&b, wo, sc.wi, 2, 0));

        /* weight = f |cos| / pdf, for both samples */
        double cs = fabs(cdl_dot(sc.wi, b.frame.n));
        for (int k = 0; k < (ok2 ? 2 : 1); k++) {
            const cdl_scatter *q = k ? &sc2 : &sc;
            const cdl_bsdf *bk = k && cond ? &b2 : &b;
            int mode = k && glass;
            cdl_vec3 f = cdl_bsdf_eval(bk, wo, sc.wi, mode);
            double fs[3] = {f.x, f.y, f.z}, wg[3] = {q->weight.x, q->weight.y, q->weight.z};
            for (int c = 0; c < 3; c++) {
                /* the sampler's cosine is the local z before the rotation to world space */
                double we = fs[c] * cs / q->pdf, slack = fs[c] * COS_ABS_ERR / q->pdf;
                CMP(st_w, wg[c], we, 1e-3, slack,
                    we * (lib_jitter(bk, wo, sc.wi, mode, c) / fmax(fs[c], 1e-30) +
                          lib_jitter(bk, wo, sc.wi, 2, 0) / q->pdf));
                max_w[k] = fmax(max_w[k], wg[c]);
            }
        }

        /* Exact VNDF weights, in the local frame flipped to wo's side. */
        dvec flo = lo, fli = li;
        if (!glass && go < 0.0) {
            flo.z = -flo.z;
            fli.z = -fli.z;
        }
        if (glass || (cond && s < NREF)) {
            double gg = ref_gg(flo, fli, ax, ay);
            if (cond) {
                dvec h = dnorm(dadd(flo, fli));
                double wg[3] = {sc.weight.x, sc.weight.y, sc.weight.z};
                for (int c = 0; c < 3; c++) {
                    double F = ref_fresnel_conductor(ddot(fli, h), GOLD_ETA[c], GOLD_K[c]);
                    CMP(st_gw, wg[c], gg * F, 1e-4, 0.0, F * ref_gg_jitter(flo, fli, ax, ay));
                }
                if (ok2)
                    CMP(st_gw, sc2.weight.x, gg, 1e-4, 0.0, ref_gg_jitter(flo, fli, ax, ay));
            } else {
                double r = (eta_wo * eta_wo) / (eta_wi * eta_wi);
                CMP(st_gw, sc.weight.x, gg * r, 1e-4, 0.0, r * ref_gg_jitter(flo, fli, ax, ay));
                if (ok2)
                    CMP(st_gw, sc2.weight.x, gg, 1e-4, 0.0, ref_gg_jitter(flo, fli, ax, ay));
            }
        }

        if (s < NREF) {
            /* f against the double precision reference */
            for (int k = 0; k < 2; k++) {
                const cdl_bsdf *bk = k && !glass ? &b2 : &b;
                int mode = k && glass;
                cdl_vec3 f = cdl_bsdf_eval(bk, wo, sc.wi, mode);
                double want[3], got[3] = {f.x, f.y, f.z};
                ref_eval(k && !glass ? &ref2 : &ref, flo, fli, mode, want);
                for (int c = 0; c < 3; c++)
                    CMP(st_ref, got[c], want[c], 1e-4, 0.0, lib_jitter(bk, wo, sc.wi, mode, c));
            }
            /* reciprocity on the sampled pair */
            cdl_vec3 f0 = cdl_bsdf_eval(&b, wo, sc.wi, 0), r0 = cdl_bsdf_eval(&b, sc.wi, wo, 0);
            if (!glass) {
                double a[3] = {f0.x, f0.y, f0.z}, r[3] = {r0.x, r0.y, r0.z};
                for (int c = 0; c < 3; c++)
                    CMP(st_rec, a[c], r[c], 1e-4, 0.0,
                        lib_jitter(&b, wo, sc.wi, 0, c) + lib_jitter(&b, sc.wi, wo, 0, c));
            } else {
                cdl_vec3 f1 = cdl_bsdf_eval(&b, wo, sc.wi, 1);
                /* Veach 5.14: f(wi->wo) / eta_o^2 = f(wo->wi) / eta_i^2 */
                double so = 1.0 / (eta_wo * eta_wo), si = 1.0 / (eta_wi * eta_wi);
                CMP(st_rec, f0.x * so, r0.x * si, 1e-4, 0.0,
                    lib_jitter(&b, wo, sc.wi, 0, 0) * so + lib_jitter(&b, sc.wi, wo, 0, 0) * si);
                /* the adjoint BSDF: f*(wo, wi) = f(wi, wo) */
                CMP(st_adj, f1.x, r0.x, 1e-4, 0.0,
                    lib_jitter(&b, wo, sc.wi, 1, 0) + lib_jitter(&b, sc.wi, wo, 0, 0));
                if (!same && r0.x > 0.0f && f0.x > 0.0f)
                    ratios[nratio++] = (double)f0.x / r0.x;
            }
        }

        /* albedo: [0] b (glass: importance transport), [1] perfect conductor / glass radiance */
        double w0 = glass ? (ok2 ? sc2.weight.x : 0.0) : sc.weight.x;
        double w1 = glass ? sc.weight.x : cond && ok2 ? sc2.weight.x : 0.0;
        ws[0] += w0;
        ws2[0] += w0 * w0;
        ws[1] += w1;
        ws2[1] += w1 * w1;

        double c, phi;
        dframe_coords(&gf, wi, &c, &phi);
        int ic = (int)((c + 1.0) * 0.5 * NC), ip = (int)(phi / (2.0 * PI_D) * NP);
        ic = ic < 0 ? 0 : ic >= NC ? NC - 1 : ic;
        ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
        obs[ic * NP + ip] += 1.0;
        for (int l = 0; l < nl; l++) {
            dframe_coords(&lf[l], wi, &c, &phi);
            int it = 0;
            while (it < NC && c < cb[l][it + 1])
                it++;
            if (it == NC) {
                lobs[l][NC * NP] += 1.0;
                continue;
            }
            ip = (int)(phi / (2.0 * PI_D) * NP);
            ip = ip < 0 ? 0 : ip >= NP ? NP - 1 : ip;
            lobs[l][it * NP + ip] += 1.0;
        }
    }

    /* Expected counts by quadrature, in the geometric normal's frame. No
     * forced refinement around the lobes (near_lobe): GGX lobes of alpha >=
     * 0.05 are >= 0.1 rad wide, resolved by the 4x4-node cells of
     * MIN_DEPTH (forcing it changes p-values by ~1e-4 at twice the cost),
     * and a missed peak could only make a test fail, never pass. */
    integ g = {.b = &b, .wo = wo, .fr = gf, .albedo = 1, .adj1 = glass, .adj2 = 0,
               .b2 = glass ? &b : &b2, .b3 = plastic ? &b3 : NULL,
               .tol_abs = MF_TOL_ABS, .tol_rel = MF_TOL_REL};
    static double expd[NC * NP + 1], lexp[NC * NP + 1];
    double ipdf = 0.0, ialb[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < NC; i++)
        for (int j = 0; j < NP; j++) {
            double v[NQ];
            integrate_cell(&g, -1.0 + 2.0 * i / NC, -1.0 + 2.0 * (i + 1) / NC,
                           2.0 * PI_D * j / NP, 2.0 * PI_D * (j + 1) / NP, v);
            expd[i * NP + j] = v[0] * NMF;
            ipdf += v[0];
            for (int k = 0; k < 3; k++)
                ialb[k] += v[k + 1];
        }
    expd[NC * NP] = fmax(0.0, 1.0 - ipdf) * NMF;
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

    /* Lobe frames: bins uniform in the GGX slope CDF tan^2 / (alpha^2 + tan^2)
     * of (angle to the axis) / kscale. */
    for (int l = 0; l < nl; l++) {
        g.fr = lf[l];
        g.albedo = 0;
        double icap = 0.0;
        for (int i = 0; i < NC; i++)
            for (int j = 0; j < NP; j++) {
                double v[NQ];
                integrate_cell(&g, cb[l][i + 1], cb[l][i], 2.0 * PI_D * j / NP,
                               2.0 * PI_D * (j + 1) / NP, v);
                lexp[i * NP + j] = v[0] * NMF;
                icap += v[0];
            }
        lexp[NC * NP] = fmax(0.0, 1.0 - icap) * NMF;
        r = chi2_test(lobs[l], lexp, NC * NP + 1, 5.0);
        check(r.p >= P_MIN,
              "%s: chi2 (GGX slope CDF around the %s axis, phi; %dx%d bins + rest) = %.1f, "
              "dof %d, p-value %.4f (>= %.2g)%s",
              tag, l ? "refraction" : "reflection", NC, NP, r.stat, r.dof, r.p, P_MIN,
              r.zero_hits > 0 ? " [samples in bins of expected count 0 pooled]" : "");
        check(r.zero_hits <= ZERO_HITS_MAX,
              "%s: %s lobe frame: %.0f samples in bins where quadrature of the pdf found no mass "
              "(<= %d)",
              tag, l ? "refraction" : "reflection", r.zero_hits, ZERO_HITS_MAX);
    }

    /* Mass of the pdf against the sample success rate. */
    double succ = 1.0 - (double)fails / NMF;
    double sd_succ = sqrt(fmax(succ * (1.0 - succ), 1.0 / NMF) / NMF);
    check(ipdf <= 1.0 + 1e-3, "%s: integral of pdf over the sphere %.5f (<= 1.001)", tag, ipdf);
    check(fabs(succ - ipdf) <= 5.0 * sd_succ + 1e-3,
          "%s: success rate %.5f vs integral of pdf %.5f (|diff| %.5f <= 5 sigma + 1e-3 = %.5f)",
          tag, succ, ipdf, fabs(succ - ipdf), 5.0 * sd_succ + 1e-3);

    /* Per-sample consistency. */
    check(bad_misc == 0 && bad_unit == 0 && bad_side == 0,
          "%s: samples with delta/non-finite/zero pdf %ld, |wi| != 1 %ld, %s %ld (all 0)", tag,
          bad_misc, bad_unit,
          glass ? "geometric and shading sides disagreeing on reflection vs transmission"
                : "wi across the geometric surface",
          bad_side);
    if (glass || cond)
        check(bad_pair == 0,
              "%s: same random numbers, same success, wi and pdf %s: %ld differences (0)", tag,
              glass ? "in radiance and importance transport" : "for gold and the perfect conductor",
              bad_pair);
    cmp_check(&st_pdf, 1e-3, "%s: sample pdf vs cdl_bsdf_pdf", tag);
    cmp_check(&st_w, 1e-3, "%s: weight vs eval |cos| / pdf%s (cos +- 1e-6)", tag,
              glass ? " (both transport modes)" : cond ? " (gold and perfect)" : "");
    if (cond)
        cmp_check(&st_gw, 1e-4,
                  "%s: weight vs reference F(wi.h) G(lo,li)/G1(lo) (gold per channel; perfect: "
                  "G/G1)",
                  tag);
    if (glass)
        cmp_check(&st_gw, 1e-4,
                  "%s: weight vs reference G(lo,li)/G1(lo) (importance), G/G1 eta_o^2/eta_i^2 "
                  "(radiance)",
                  tag);
    cmp_check(&st_ref, 1e-4, "%s: eval vs double precision reference (%s) at sampled pairs", tag,
              cond ? "gold and perfect" : plastic ? "whole and specular part" : "radiance and importance");

    /* Weight bounds: F G/G1 <= 1; plastic (kd cos/pi + s cos) / (cos/(2 pi) + pdf_s/2)
     * <= max(2 kd, 2 ks F G/G1) = 1; glass: G/G1 <= 1 in importance transport,
     * times eta_o^2 / eta_i^2 in radiance transport. */
    double wb0 = glass && eta_wo > 1.0 ? eta * eta : 1.0;
    check(max_w[0] <= wb0 + 1e-5 && max_w[1] <= 1.0 + 1e-5,
          "%s: max sample weight %.5f (<= %g)%s%.5f%s", tag, max_w[0], wb0,
          glass ? ", importance transport " : cond ? ", perfect conductor " : "", max_w[1],
          glass || cond ? " (<= 1)" : "");

    /* Albedo. */
    double alb[2], sd[2];
    for (int k = 0; k < 2; k++) {
        alb[k] = ws[k] / NMF;
        sd[k] = sqrt(fmax(0.0, ws2[k] / NMF - alb[k] * alb[k]) / NMF);
    }
    const char *aname[2] = {glass ? "importance transport " : cond ? "gold (red) " : "",
                            glass ? "radiance transport " : "perfect conductor "};
    for (int k = 0; k < (plastic ? 1 : 2); k++)
        check(fabs(alb[k] - ialb[k]) <= fmax(0.01 * ialb[k], 5.0 * sd[k]) + 1e-6,
              "%s: %sMonte Carlo albedo %.5f vs quadrature of f|cos| %.5f (within max(1%%, "
              "5 sigma = %.5f))",
              tag, aname[k], alb[k], ialb[k], 5.0 * sd[k]);
    int fu = cond ? 1 : 0; /* the albedo that must stay <= 1 */
    check(alb[fu] <= 1.0 + 5.0 * sd[fu] && ialb[fu] <= 1.0 + 1e-3,
          "%s: %s albedo: Monte Carlo %.5f (<= 1 + 5 sigma), quadrature %.5f (<= 1.001)", tag,
          cond ? "white furnace (perfect conductor)" : glass ? "importance transport" : "plastic",
          alb[fu], ialb[fu]);
    if (cond && wo_deg == 0.0 && amin <= 0.05)
        check(alb[1] > 0.95 && ialb[1] > 0.95,
              "%s: perfect conductor at normal incidence reflects nearly all: Monte Carlo %.5f, "
              "quadrature %.5f (> 0.95)",
              tag, alb[1], ialb[1]);
    /* At 80deg single scattering loses more than 10% to masking and to
     * reflections below the horizon, even for alpha 0.1. */
    double inc = wo_deg > 90.0 ? 180.0 - wo_deg : wo_deg;
    if (glass && amin <= 0.1 && inc <= 60.0)
        check(alb[0] > 0.9 && ialb[0] > 0.9,
              "%s: importance transport albedo %.5f (quadrature %.5f) > 0.9: lost only to masking",
              tag, alb[0], ialb[0]);
    if (plastic) {
        double spec = ialb[1], diff = ialb[0] - ialb[1], e3 = ialb[2];
        if (!tilted)
            check(fabs(diff - kd) <= 1e-4,
                  "%s: Lambert part of the albedo (quadrature) %.6f vs kd = %g (within 1e-4)", tag,
                  diff, kd);
        if (wo_deg == 0.0) {
            /* spec = ks E[F(wo.h) G/G1], e3 = E[G/G1] over the same VNDF samples:
             * spec / (ks e3) is an average of F over microfacets within
             * 45deg + (tilt of wo from ns) / 2 of wo. */
            double f0 = fresnel_ref(0.0, 1.0, eta);
            double fmx = fresnel_ref((45.0 + 0.5 * acos(fmin(1.0, cso)) / DEG) * DEG, 1.0, eta);
            double ratio = spec / (ks * e3);
            check(ratio >= f0 * (1.0 - 1e-4) && ratio <= fmx,
                  "%s: specular albedo %.5f = ks F_avg E_perfect: F_avg %.5f within [F(0) = "
                  "%.5f, F(max angle) = %.5f] (E_perfect = %.5f)",
                  tag, spec, ratio, f0, fmx, e3);
        }
    }
    if (glass)
        printf("    (reflected share of the samples %.4f; albedo radiance %.5f importance %.5f)\n",
               (double)nrefl / NMF, alb[1], alb[0]);

    /* Reciprocity over random pairs too, and the support of pdf vs eval. */
    long nonzero = 0, pdf_no_f = 0, f_no_pdf = 0, edge = 0;
    for (int s = 0; s < 20000; s++) {
        cdl_vec3 a = random_sphere_dir(&rng);
        cdl_vec3 bb = (s & 1) ? random_sphere_dir(&rng) : wo;
        cdl_vec3 f1 = cdl_bsdf_eval(&b, bb, a, 0), f2 = cdl_bsdf_eval(&b, a, bb, 0);
        float p1 = cdl_bsdf_pdf(&b, bb, a);
        if (!cdl_is_black(f1))
            nonzero++;
        if ((p1 > 0.0f) != (f1.x > 0.0f)) {
            if (support_edge(&b, bb, a))
                edge++; /* at the very edge of the support either may round to 0 */
            else if (p1 > 0.0f)
                pdf_no_f++;
            else
                f_no_pdf++;
        }
        if (!glass) {
            double x[3] = {f1.x, f1.y, f1.z}, y[3] = {f2.x, f2.y, f2.z};
            for (int c = 0; c < 3; c++)
                CMP(st_rec, x[c], y[c], 1e-4, 0.0, lib_jitter(&b, bb, a, 0, c) + lib_jitter(&b, a, bb, 0, c));
            continue;
        }
        double ea = cdl_dot(b.frame.n, a) > 0.0f ? 1.0 : eta;
        double eb = cdl_dot(b.frame.n, bb) > 0.0f ? 1.0 : eta;
        double sa = 1.0 / (ea * ea), sb = 1.0 / (eb * eb);
        CMP(st_rec, f1.x * sb, f2.x * sa, 1e-4, 0.0,
            lib_jitter(&b, bb, a, 0, 0) * sb + lib_jitter(&b, a, bb, 0, 0) * sa);
        CMP(st_adj, cdl_bsdf_eval(&b, bb, a, 1).x, f2.x, 1e-4, 0.0,
            lib_jitter(&b, bb, a, 1, 0) + lib_jitter(&b, a, bb, 0, 0));
    }
    if (!glass) {
        cmp_check(&st_rec, 1e-4, "%s: reciprocity f(wo,wi) = f(wi,wo) over %d sampled + 20000 random pairs (%ld non-zero)",
                  tag, NREF, nonzero);
    } else {
        cmp_check(&st_rec, 1e-4,
                  "%s: generalized reciprocity f(wo,wi)/eta_wo^2 = f(wi,wo)/eta_wi^2 (radiance, "
                  "Veach 5.14; equivalently f*(wo,wi)/eta_wi^2 = f*(wi,wo)/eta_wo^2 in importance) "
                  "over %d sampled + 20000 random pairs (%ld non-zero)",
                  tag, NREF, nonzero);
        cmp_check(&st_adj, 1e-4, "%s: adjoint f_importance(wo,wi) = f_radiance(wi,wo)", tag);
        if (nratio > 0) {
            qsort(ratios, (size_t)nratio, sizeof(double), cmp_double);
            double med = ratios[nratio / 2], want = eta_wo > 1.0 ? eta * eta : 1.0 / (eta * eta);
            check(rel_err(med, want) <= 1e-5,
                  "%s: plain symmetry does not hold for refraction: median f(wo,wi)/f(wi,wo) "
                  "%.6f = eta_wo^2/eta_wi^2 = %.6f (%ld sampled refraction pairs)",
                  tag, med, want, nratio);
        }
    }
    check(pdf_no_f == 0 && f_no_pdf == 0,
          "%s: random pairs with pdf > 0 but f = 0: %ld, with f > 0 but pdf = 0: %ld (0, 0; "
          "%ld more at the edge of the support)",
          tag, pdf_no_f, f_no_pdf, edge);
    printf("    (%ld quadrature evaluations)\n", g.evals);
}

int main(void)
{
    test_conductor_fresnel();
    static const mf_case mcases[] = {
        {"conductor gold", CDL_MAT_CONDUCTOR, 0.05f, 0.05f},
        {"conductor gold", CDL_MAT_CONDUCTOR, 0.3f, 0.3f},
        {"conductor gold", CDL_MAT_CONDUCTOR, 0.8f, 0.8f},
        {"conductor gold", CDL_MAT_CONDUCTOR, 0.1f, 0.5f},
        {"plastic kd=0.5 ks=0.5 eta=1.5", CDL_MAT_PLASTIC, 0.1f, 0.1f},
        {"plastic kd=0.5 ks=0.5 eta=1.5", CDL_MAT_PLASTIC, 0.5f, 0.5f},
        {"rough glass eta=1.5", CDL_MAT_ROUGH_DIELECTRIC, 0.1f, 0.1f},
        {"rough glass eta=1.5", CDL_MAT_ROUGH_DIELECTRIC, 0.4f, 0.4f},
    };
    /* Angles from ng: opaque back side 135 = 45deg, 100 = 80deg; glass from
     * inside 180, 150, 120, 100 = 0, 30, 60, 80deg. */
    static const double mf_opaque_wo[] = {0.0, 30.0, 60.0, 80.0, 135.0, 100.0};
    static const double mf_glass_wo[] = {0.0, 30.0, 60.0, 80.0, 180.0, 150.0, 120.0, 100.0};
    uint64_t mstream = 0;
    for (size_t c = 0; c < sizeof mcases / sizeof mcases[0]; c++) {
        int gl = mcases[c].type == CDL_MAT_ROUGH_DIELECTRIC;
        const double *ws = gl ? mf_glass_wo : mf_opaque_wo;
        size_t nw = gl ? sizeof mf_glass_wo / sizeof mf_glass_wo[0]
                       : sizeof mf_opaque_wo / sizeof mf_opaque_wo[0];
        for (int tilted = 0; tilted < 2; tilted++)
            for (size_t w = 0; w < nw; w++)
                test_microfacet(&mcases[c], ws[w], tilted, mstream++);
    }

    check(chi2_count == N_CHI2, "%d chi-square tests run (N_CHI2 = %d, for the Sidak correction)",
          chi2_count, N_CHI2);
    printf("%d checks, %d failures\n", checks, failures);
    return failures ? 1 : 0;
}