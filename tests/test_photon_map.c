/* Photon maps (pm) against closed forms:
 *  - octahedral direction encoding: worst angular error at 15, 16 and 8 bits;
 *  - density estimation: photons stratified over a unit square with flux
 *    Phi / N each give irradiance Phi / area and Lambertian radiance
 *    rho / pi * Phi / area for every kernel (the kernel normalizations),
 *    also when the maximum radius caps the estimate; photons from the
 *    other side and photons with skip flags drop out;
 *  - precomputed irradiance (Christensen 1999): lookups return the value
 *    computed at the photon, and nothing for a surface facing elsewhere.
 * Photon tracing is tested in test_photons.c. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "spatial/photon_map.h"
#include "transport/importance.h"
#include "transport/photons.h"
#include "test_pm_common.h"

/* ---- octahedral encoding ---- */

static void octahedral(void)
{
    const int bits[] = {15, 16, 8};
    /* measured worst errors over 2e6 directions: 0.0074, 0.0037, 0.95 deg
     * (photon_map.c documents 15 bits as better than 0.01 deg) */
    const double limit[] = {0.009, 0.0045, 1.2};
    for (int b = 0; b < 3; b++) {
        double worst = 0.0;
        int range_ok = 1;
        rng_state = 12345;
        for (int i = 0; i < 2000000 + 27; i++) {
            cdl_vec3 d;
            if (i < 27) { /* the axes, the seams and the corners of the octahedron */
                int v[3] = {i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1};
                if (!v[0] && !v[1] && !v[2])
                    continue;
                d = cdl_normalize(cdl_v3((float)v[0], (float)v[1], (float)v[2]));
            } else {
                d = rnd_dir();
            }
            uint32_t e = cdl_oct_encode_bits(d, bits[b]);
            if (bits[b] < 16 && (e >> (2 * bits[b])) != 0)
                range_ok = 0;
            worst = fmax(worst, angle_deg(d, cdl_oct_decode_bits(e, bits[b])));
        }
        CHECK(worst < limit[b], "octahedral %d bits: worst angular error %.5f deg over 2e6 directions (limit %g)",
              bits[b], worst, limit[b]);
        CHECK(range_ok, "octahedral %d bits: codes fit in %d bits (the photon's flag bits stay free)", bits[b],
              2 * bits[b]);
    }
    /* the flags of a photon do not disturb its direction */
    cdl_vec3 d = cdl_normalize(cdl_v3(-0.3f, 0.2f, -0.9f));
    cdl_photon ph;
    memset(&ph, 0, sizeof ph);
    ph.wi = cdl_oct_encode_bits(d, 15) | (uint32_t)(CDL_PH_PRIMARY | CDL_PH_CAUSTIC) << 30;
    CHECK(cdl_photon_flags(&ph) == (CDL_PH_PRIMARY | CDL_PH_CAUSTIC) && angle_deg(cdl_photon_wi(&ph), d) < 0.005,
          "photon flags %u and direction (off by %.5f deg) share wi", cdl_photon_flags(&ph),
          angle_deg(cdl_photon_wi(&ph), d));
    CHECK(sizeof(cdl_photon) == 32, "a photon is %zu bytes (32 documented)", sizeof(cdl_photon));
}

/* ---- density estimation on a square ---- */

static cdl_photon make_photon(double x, double y, cdl_vec3 power, cdl_vec3 wi, cdl_vec3 n, uint32_t flags)
{
    cdl_photon ph;
    ph.p[0] = (float)x;
    ph.p[1] = (float)y;
    ph.p[2] = 0.0f;
    ph.power[0] = power.x;
    ph.power[1] = power.y;
    ph.power[2] = power.z;
    ph.wi = cdl_oct_encode_bits(wi, 15) | flags << 30;
    ph.n = (uint16_t)cdl_oct_encode_bits(n, 8);
    ph.light = 0;
    return ph;
}

/* G x G jittered photons on [0,1]^2 (z = 0) carrying Phi in all; every
 * `flag_every`-th (in raster order) gets `flags`. */
static void add_square(cdl_photon_map *m, int G, cdl_vec3 Phi, cdl_vec3 wi, cdl_vec3 n, uint32_t flags,
                       int flag_every)
{
    cdl_error err;
    cdl_vec3 power = cdl_scale(Phi, 1.0f / (float)(G * G));
    for (int j = 0; j < G; j++)
        for (int i = 0; i < G; i++) {
            uint32_t f = flag_every && (j * G + i) % flag_every == 0 ? flags : 0u;
            cdl_photon ph = make_photon((i + rnd()) / G, (j + rnd()) / G, power, wi, n, f);
            die_on(cdl_pmap_append(m, &ph, 1, &err), &err);
        }
}

typedef struct est_stats {
    double mean, worst; /* relative error: of the mean over the points, worst single point */
} est_stats;

/* Estimates at a Q x Q grid of points in [0.2, 0.8]^2 against `expect`
 * (per channel); what = 0 radiance towards wo with BSDF b, 1 irradiance with normal nrm. */
static est_stats estimate(const cdl_photon_map *m, const cdl_pm_query *q, int what, const cdl_bsdf *b, cdl_vec3 wo,
                          cdl_vec3 nrm, cdl_vec3 expect)
{
    enum { Q = 24 };
    double sum[3] = {0, 0, 0}, worst = 0.0;
    for (int j = 0; j < Q; j++)
        for (int i = 0; i < Q; i++) {
            cdl_vec3 x = cdl_v3(0.2f + 0.6f * (i + 0.5f) / Q, 0.2f + 0.6f * (j + 0.5f) / Q, 0.0f);
            cdl_vec3 v = what == 0 ? cdl_pmap_radiance(m, q, x, wo, b) : cdl_pmap_irradiance(m, q, x, nrm);
            float vv[3] = {v.x, v.y, v.z}, ee[3] = {expect.x, expect.y, expect.z};
            for (int c = 0; c < 3; c++) {
                sum[c] += vv[c];
                worst = fmax(worst, ee[c] > 0.0f ? fabs(vv[c] / ee[c] - 1.0) : fabs(vv[c]));
            }
        }
    float ee[3] = {expect.x, expect.y, expect.z};
    double mean = 0.0;
    for (int c = 0; c < 3; c++) {
        double mc = sum[c] / (Q * Q);
        mean = fmax(mean, ee[c] > 0.0f ? fabs(mc / ee[c] - 1.0) : fabs(mc));
    }
    return (est_stats){mean, worst};
}


static void density(void)
{
    cdl_error err;
    rng_state = 777;
    const int G = 300; /* 90000 photons, unit area */
    const cdl_vec3 Phi = cdl_v3(2.0f, 1.0f, 0.5f), up = cdl_v3(0.0f, 0.0f, 1.0f), down = cdl_v3(0.0f, 0.0f, -1.0f);
    const float rho = 0.6f;
    cdl_material mat = cdl_material_default(CDL_MAT_DIFFUSE);
    cdl_bsdf b;
    cdl_bsdf_init(&b, &mat, cdl_v3(rho, rho, rho), up, up);
    cdl_vec3 L = cdl_scale(Phi, rho / CDL_PI);
    cdl_vec3 wo = cdl_normalize(cdl_v3(0.3f, -0.5f, 0.8f)); /* any direction above: Lambert */

    cdl_photon_map top, both, none;
    cdl_pmap_init(&top);
    cdl_pmap_init(&both);
    cdl_pmap_init(&none);
    /* every second photon flagged primary */
    add_square(&top, G, Phi, up, up, CDL_PH_PRIMARY, 2);
    die_on(cdl_pmap_build(&top, &err), &err);
    CHECK(top.n == (uint32_t)(G * G) && top.built, "photon map holds %u photons", top.n);

    uint32_t kmax = 400;
    cdl_pm_query q = {0, 1.0f, CDL_KERNEL_BOX, 0, malloc(sizeof(uint32_t) * kmax), malloc(sizeof(float) * kmax)};
    /* k-NN noise: relative sd about 1/sqrt(k) for Poisson photons, less
     * for stratified ones. Measured (mean over 576 points / worst point):
     * k 25: box 2.2 / 23 %, cone 0.76 / 17 %, epanechnikov 0.82 / 19 %;
     * k 100: 0.60 / 7.3, 0.13 / 4.9, 0.13 / 4.6; k 400: 0.14 / 3.0,
     * 0.025 / 1.4, 0.027 / 1.2. The box kernel counts the k-th photon on
     * the rim at full weight: biased up by about 0.55 / k. A wrong kernel
     * normalization is off by 33 % (cone) or 50 % (epanechnikov). */
    const uint32_t ks[] = {25, 100, 400};
    for (int kk = 0; kk < 3; kk++)
        for (int kern = 0; kern < 3; kern++) {
            q.k = ks[kk];
            q.kernel = (cdl_kernel)kern;
            q.skip = 0;
            double lim_pt = 1.5 / sqrt((double)q.k), lim_mean = 0.005 + 0.7 / q.k;
            est_stats r = estimate(&top, &q, 0, &b, wo, up, L);
            CHECK(r.mean < lim_mean && r.worst < lim_pt,
                  "%s kernel, k %u: radiance rho/pi Phi/A off by %.3f%% on average (limit %.2f%%), worst point "
                  "%.2f%% (limit 1.5/sqrt(k) = %.1f%%)",
                  kernel_name[kern], q.k, 100 * r.mean, 100 * lim_mean, 100 * r.worst, 100 * lim_pt);
            est_stats e = estimate(&top, &q, 1, &b, wo, up, Phi);
            CHECK(e.mean < lim_mean && e.worst < lim_pt,
                  "%s kernel, k %u: irradiance Phi/A off by %.3f%% on average, worst point %.2f%%",
                  kernel_name[kern], q.k, 100 * e.mean, 100 * e.worst);
            if (kk == 1) {
                /* skip flags: the radius stays that of all photons, the sum
                 * loses the flagged half */
                q.skip = CDL_PH_PRIMARY;
                est_stats s = estimate(&top, &q, 0, &b, wo, up, cdl_scale(L, 0.5f));
                CHECK(s.mean < 2 * lim_mean && s.worst < 2 * lim_pt,
                      "%s kernel, k %u, skipping the primary half: radiance L/2 off by %.3f%% on average, worst "
                      "%.2f%%",
                      kernel_name[kern], q.k, 100 * s.mean, 100 * s.worst);
                q.skip = CDL_PH_CAUSTIC; /* no photon has it */
                est_stats s2 = estimate(&top, &q, 1, &b, wo, up, Phi);
                CHECK(s2.mean == e.mean && s2.worst == e.worst,
                      "%s kernel: skipping an absent flag changes nothing", kernel_name[kern]);
            }
        }

    /* the maximum radius caps the estimate: fewer than k photons inside,
     * the estimate over the fixed disc (expected count pi r^2 N = 28) */
    q.k = 100;
    q.skip = 0;
    q.max_r2 = 0.01f * 0.01f;
    for (int kern = 0; kern < 3; kern++) {
        q.kernel = (cdl_kernel)kern;
        est_stats r = estimate(&top, &q, 0, &b, wo, up, L);
        CHECK(r.mean < 0.02 && r.worst < 0.5,
              "%s kernel, radius capped (about 28 photons): radiance off by %.3f%% on average (limit 2%%), "
              "worst %.1f%%",
              kernel_name[kern], 100 * r.mean, 100 * r.worst);
    }
    q.max_r2 = 1.0f;

    /* all photons flagged and skipped: nothing */
    cdl_photon_map all;
    cdl_pmap_init(&all);
    add_square(&all, 100, Phi, up, up, CDL_PH_PRIMARY, 1);
    die_on(cdl_pmap_build(&all, &err), &err);
    q.skip = CDL_PH_PRIMARY;
    est_stats z = estimate(&all, &q, 0, &b, wo, up, cdl_v3(0, 0, 0));
    est_stats z2 = estimate(&all, &q, 1, &b, wo, up, cdl_v3(0, 0, 0));
    CHECK(z.worst == 0.0 && z2.worst == 0.0, "all photons primary and skipped: radiance %g, irradiance %g",
          z.worst, z2.worst);
    q.skip = 0;

    /* photons that arrived from below only: nothing above */
    add_square(&none, G, Phi, down, down, 0, 0);
    die_on(cdl_pmap_build(&none, &err), &err);
    q.kernel = CDL_KERNEL_CONE;
    est_stats o1 = estimate(&none, &q, 1, &b, wo, up, cdl_v3(0, 0, 0));
    est_stats o2 = estimate(&none, &q, 0, &b, wo, up, cdl_v3(0, 0, 0));
    CHECK(o1.worst == 0.0 && o2.worst == 0.0,
          "photons from the other side: irradiance above %g, radiance above %g (both 0)", o1.worst, o2.worst);

    /* both sides at once, fluxes Phi above and 3 Phi below: each side sees its own */
    add_square(&both, G, Phi, up, up, 0, 0);
    add_square(&both, G, cdl_scale(Phi, 3.0f), down, down, 0, 0);
    die_on(cdl_pmap_build(&both, &err), &err);
    for (int kern = 0; kern < 3; kern++) {
        q.kernel = (cdl_kernel)kern;
        est_stats u = estimate(&both, &q, 1, &b, wo, up, Phi);
        est_stats d = estimate(&both, &q, 1, &b, wo, down, cdl_scale(Phi, 3.0f));
        est_stats lu = estimate(&both, &q, 0, &b, wo, up, L);
        est_stats ld = estimate(&both, &q, 0, &b, cdl_neg(wo), up, cdl_scale(L, 3.0f));
        CHECK(fmax(fmax(u.mean, d.mean), fmax(lu.mean, ld.mean)) < 0.015 &&
                  fmax(fmax(u.worst, d.worst), fmax(lu.worst, ld.worst)) < 0.2,
              "%s kernel, photons on both sides: irradiance above/below off by %.2f%%/%.2f%%, radiance "
              "%.2f%%/%.2f%% on average (limit 1.5%%)",
              kernel_name[kern], 100 * u.mean, 100 * d.mean, 100 * lu.mean, 100 * ld.mean);
    }

    /* an empty or unbuilt map answers 0 */
    cdl_photon_map empty;
    cdl_pmap_init(&empty);
    die_on(cdl_pmap_build(&empty, &err), &err);
    cdl_vec3 e0 = cdl_pmap_radiance(&empty, &q, cdl_v3(0.5f, 0.5f, 0.0f), wo, &b);
    cdl_vec3 e1 = cdl_pmap_irradiance(&empty, &q, cdl_v3(0.5f, 0.5f, 0.0f), up);
    CHECK(cdl_is_black(e0) && cdl_is_black(e1), "an empty map gives 0");

    /* scaling the map scales the estimate */
    cdl_pmap_scale(&top, 0.25f);
    q.kernel = CDL_KERNEL_EPANECHNIKOV;
    est_stats sc = estimate(&top, &q, 1, &b, wo, up, cdl_scale(Phi, 0.25f));
    CHECK(sc.mean < 0.01, "cdl_pmap_scale(0.25): irradiance Phi/4 off by %.3f%%", 100 * sc.mean);
    cdl_pmap_scale(&top, 4.0f);

    /* ---- precomputed irradiance (smaller maps: a k-NN estimate per point) ---- */
    cdl_photon_map caus, both_s, top_s;
    cdl_pmap_init(&caus);
    cdl_pmap_init(&both_s);
    cdl_pmap_init(&top_s);
    add_square(&caus, 60, cdl_scale(Phi, 0.5f), up, up, CDL_PH_CAUSTIC, 1);
    add_square(&both_s, 120, Phi, up, up, 0, 0);
    add_square(&both_s, 120, cdl_scale(Phi, 3.0f), down, down, 0, 0);
    add_square(&top_s, 120, Phi, up, up, 0, 0);
    die_on(cdl_pmap_build(&caus, &err), &err);
    die_on(cdl_pmap_build(&both_s, &err), &err);
    die_on(cdl_pmap_build(&top_s, &err), &err);
    const uint32_t every[] = {1, 4};
    for (int ev = 0; ev < 2; ev++) {
        cdl_irr_map im;
        memset(&im, 0, sizeof im);
        die_on(cdl_irr_build(&im, &both_s, &caus, every[ev], 100, 1.0f, CDL_KERNEL_CONE, &err), &err);
        uint32_t expect_n = (both_s.n + every[ev] - 1) / every[ev];
        cdl_pm_query qi = {100, 1.0f, CDL_KERNEL_CONE, 0, q.idx, q.d2};
        int exact = 1, found_all = 1;
        double worst_val = 0.0;
        uint32_t tested = 0;
        for (uint32_t i = 0; i < both_s.n; i += every[ev] * 7) {
            const cdl_photon *ph = &both_s.ph[i];
            cdl_vec3 x = cdl_v3(ph->p[0], ph->p[1], ph->p[2]), n = cdl_photon_n(ph);
            cdl_vec3 E = cdl_add(cdl_pmap_irradiance(&both_s, &qi, x, n), cdl_pmap_irradiance(&caus, &qi, x, n));
            int found;
            cdl_vec3 got = cdl_irr_lookup(&im, x, n, 1e-4f, &found);
            found_all &= found;
            exact &= got.x == E.x && got.y == E.y && got.z == E.z;
            tested++;
            /* interior photons: the closed form (caustic map adds Phi/2 above) */
            if (x.x > 0.1f && x.x < 0.9f && x.y > 0.1f && x.y < 0.9f) {
                cdl_vec3 ex = n.z > 0.0f ? cdl_scale(Phi, 1.5f) : cdl_scale(Phi, 3.0f);
                worst_val = fmax(worst_val, fabs(got.y / ex.y - 1.0));
            }
        }
        CHECK(im.n == expect_n, "irradiance points: %u for every %u-th of %u photons (expected %u)", im.n,
              every[ev], both_s.n, expect_n);
        CHECK(found_all && exact,
              "cdl_irr_lookup at %u photon positions (every %u): found %d, equal to the estimate there %d", tested,
              every[ev], found_all, exact);
        CHECK(worst_val < 0.3, "precomputed irradiance (every %u) within %.1f%% of the closed form (limit 30%%)",
              every[ev], 100 * worst_val);
        /* far from every point */
        int found;
        cdl_irr_lookup(&im, cdl_v3(5.0f, 5.0f, 0.0f), up, 0.01f, &found);
        CHECK(!found, "cdl_irr_lookup far away (every %u): found = %d", every[ev], found);
        cdl_irr_free(&im);
    }
    /* one-sided: the opposite normal (or a perpendicular one) finds nothing */
    {
        cdl_irr_map im;
        memset(&im, 0, sizeof im);
        cdl_photon_map nocaus;
        cdl_pmap_init(&nocaus);
        die_on(cdl_pmap_build(&nocaus, &err), &err);
        die_on(cdl_irr_build(&im, &top_s, &nocaus, 1, 100, 1.0f, CDL_KERNEL_BOX, &err), &err);
        int any_down = 0, any_side = 0, all_up = 1;
        for (uint32_t i = 0; i < top_s.n; i += 17) {
            cdl_vec3 x = cdl_v3(top_s.ph[i].p[0], top_s.ph[i].p[1], top_s.ph[i].p[2]);
            int f;
            cdl_irr_lookup(&im, x, down, 1.0f, &f);
            any_down |= f;
            cdl_irr_lookup(&im, x, cdl_v3(1.0f, 0.0f, 0.0f), 1.0f, &f);
            any_side |= f;
            cdl_irr_lookup(&im, x, up, 1.0f, &f);
            all_up &= f;
        }
        CHECK(!any_down && !any_side && all_up,
              "one-sided irradiance points: opposite normal found %d, perpendicular %d (both 0), same side %d",
              any_down, any_side, all_up);
        cdl_irr_free(&im);
        cdl_pmap_free(&nocaus);
    }

    free(q.idx);
    free(q.d2);
    cdl_pmap_free(&top);
    cdl_pmap_free(&both);
    cdl_pmap_free(&none);
    cdl_pmap_free(&all);
    cdl_pmap_free(&empty);
    cdl_pmap_free(&caus);
    cdl_pmap_free(&both_s);
    cdl_pmap_free(&top_s);
}

int main(void)
{
    test_scale_init();
    double t0 = now();
    octahedral();
    double t1 = now();
    density();
    double t2 = now();
    printf("times: octahedral %.2f s, density %.2f s\n", t1 - t0, t2 - t1);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
