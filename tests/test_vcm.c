/* vcm's building blocks (Georgiev et al. 2012):
 *   - the hash grid over light vertices finds every point of a ball once,
 *     as a brute-force scan does, whatever the radius (wider than its
 *     cells too);
 *   - the MIS weights of every strategy of a path, bdpt's connections
 *     (s, t) and the merges at each interior non-delta vertex, sum to 1
 *     (balance and power heuristics, random densities, specular vertices,
 *     point lights, the s = 1 density of light sampling, merging alone and
 *     connections alone);
 *   - the O(1) merge weights from partial sums along each subpath
 *     (cdl_merge_partials_*) equal the walk over the merged path's records
 *     (cdl_merge_weight), on eye and light subpaths of the caustic scene
 *     (diffuse, Phong, mirror and glass; area, point and infinite lights).
 * usage: test_vcm CAUSTIC_RING.obj */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/loader.h"
#include "spatial/hashgrid.h"
#include "transport/connect.h"
#include "transport/subpath.h"
#include "test_pm_common.h"

static void count_visit(void *ctx, uint32_t i, float d2)
{
    (void)d2;
    ((uint32_t *)ctx)[i]++;
}

static void test_hashgrid(void)
{
    enum { N = 20000 };
    float *pts = malloc(sizeof(float) * 4 * N);
    uint32_t *hits = calloc(N, sizeof(uint32_t));
    for (int i = 0; i < N; i++) { /* clustered on planes, as light vertices are, plus stragglers */
        int plane = i % 3;
        for (int a = 0; a < 3; a++)
            pts[4 * i + a] = a == plane ? (float)(i % 7 == 0 ? rnd() : 0.25) : (float)rnd();
        pts[4 * i + 3] = -1.0f; /* payload, skipped by the stride */
    }
    cdl_hashgrid g;
    cdl_hashgrid_init(&g);
    cdl_error err;
    int bad = 0, queries = 0;
    uint64_t found = 0;
    for (int round = 0; round < 2; round++) { /* the second rebuild reuses the memory, with a smaller radius */
        float r = round ? 0.01f : 0.03f;
        die_on(cdl_hashgrid_build(&g, pts, 4, N, r, &err), &err);
        for (int q = 0; q < 400; q++, queries++) {
            cdl_vec3 c = cdl_v3((float)rnd(), (float)rnd(), (float)rnd());
            int plane = q % 3;
            if (q % 2) /* on a plane, where the points are */
                c = cdl_v3(plane == 0 ? 0.25f : c.x, plane == 1 ? 0.25f : c.y, plane == 2 ? 0.25f : c.z);
            float rq = q % 5 == 4 ? 3.0f * r : r; /* some queries wider than the cells */
            memset(hits, 0, sizeof(uint32_t) * N);
            uint32_t n = cdl_hashgrid_ball(&g, c, rq * rq, count_visit, hits);
            uint32_t want = 0;
            for (int i = 0; i < N; i++) {
                float dx = pts[4 * i] - c.x, dy = pts[4 * i + 1] - c.y, dz = pts[4 * i + 2] - c.z;
                int in = dx * dx + dy * dy + dz * dz <= rq * rq;
                want += (uint32_t)in;
                bad += hits[i] != (uint32_t)in;
            }
            bad += n != want;
            found += want;
        }
    }
    CHECK(bad == 0 && found > 1000, "hash grid: %d queries find every point of the ball once (%llu in all), "
          "%d mismatches", queries, (unsigned long long)found, bad);
    cdl_hashgrid_free(&g);
    free(pts);
    free(hits);
}

/* One random full path of n vertices (z_0 the camera, z_{n-1} on a light). */
static int random_path(cdl_mis_vertex *v, int n)
{
    for (int k = 0; k < n; k++) {
        v[k].pdf_eye = (float)exp(6.0 * rnd() - 3.0);
        v[k].pdf_light = (float)exp(6.0 * rnd() - 3.0);
        v[k].delta = k > 0 && k < n - 1 && rnd() < 0.25;
        v[k].g_next = 0.0f;
        v[k].pdf_s1 = 0.0f;
    }
    /* after a specular vertex the neighbours' densities are Dirac: 0 */
    for (int k = 1; k < n - 1; k++)
        if (v[k].delta) {
            v[k + 1].pdf_eye = 0.0f;
            v[k - 1].pdf_light = 0.0f;
        }
    if (rnd() < 0.3)
        v[n - 1].pdf_s1 = (float)exp(4.0 * rnd() - 2.0);
    return rnd() < 0.2; /* a point light */
}

static void test_partition(void)
{
    int worst_n = 0, paths = 0;
    double worst = 0.0;
    for (int trial = 0; trial < 4000; trial++) {
        cdl_mis_vertex v[12];
        int n = 3 + trial % 8, L = n - 1;
        int delta_light = random_path(v, n);
        cdl_mis_kind kind = trial % 2 ? CDL_MIS_POWER : CDL_MIS_BALANCE;
        int mode = (trial / 2) % 3; /* full, connections alone, merges alone */
        float eta = (float)exp(8.0 * rnd() - 4.0);
        cdl_mis_counts c = {1.0f, (float)(0.5 + rnd()), 1.0f, 0.0f, 0.0f, mode == 1 ? 0.0f : eta};
        if (mode == 2)
            c.eye = c.light_trace = c.connect = 0.0f;
        double sum = 0.0;
        int used = 0; /* strategies that can sample the path */
        for (int t = 1; t <= n && mode != 2; t++) { /* connections: bdpt's strategies */
            int s = n - t;
            int ok = t == 1 ? s >= 2 && !v[1].delta : s == 0 ? !delta_light : !v[t - 1].delta && !v[t].delta;
            if (ok) {
                sum += cdl_mis_weight(kind, v, s, t, delta_light, &c, 0.0f);
                used++;
            }
        }
        for (int k = 1; k <= L - 1 && mode != 1; k++)
            if (!v[k].delta) {
                sum += cdl_mis_weight_merge(kind, v, n, k, delta_light, &c);
                used++;
            }
        /* merging alone leaves a path with no mergeable vertex to the eye
         * path (vcm.c); a path no strategy samples has no weights */
        if (!used)
            continue;
        paths++;
        if (fabs(sum - 1.0) > worst) {
            worst = fabs(sum - 1.0);
            worst_n = n;
        }
    }
    CHECK(worst < 2e-5, "MIS: the weights of all connections and merges of %d random paths sum to 1 "
          "(worst |sum - 1| %.2g at %d vertices)", paths, worst, worst_n);
}

static void test_partials(const char *scene_path)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, scene_path, &err), &err);
    die_on(cdl_scene_load(&s, scene_path, NULL, &err), &err);
    /* a point light and a sky too: delta lights and light paths from infinity */
    die_on(cdl_scene_add_point_light(&s, cdl_v3(0.3f, 1.2f, 0.2f), cdl_v3(2.0f, 2.0f, 2.0f), &err), &err);
    die_on(cdl_scene_add_infinite_light(&s, cdl_v3(0.5f, 0.6f, 0.7f), &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    cdl_camera cam;
    die_on(cdl_camera_init(&cam, cdl_v3(0.0f, 1.9f, 1.6f), cdl_v3(0.2f, 0.0f, -0.2f), cdl_v3(0.0f, 1.0f, 0.0f), 55.0f,
                           64, 64, &err),
           &err);
    cdl_walk walk = {10, 3, 1};
    cdl_vertex_store evs, lvs;
    cdl_vs_init(&evs);
    cdl_vs_init(&lvs);
    die_on(cdl_vs_reserve(&evs, 16, &err), &err);
    die_on(cdl_vs_reserve(&lvs, 16, &err), &err);
    float b1[16], b2[16], ge[16], a1[16], a2[16], gl[16];
    int pairs = 0, bad = 0, specular = 0;
    double worst = 0.0;
    int lights[3] = {0, 0, 0};
    for (int kind = 0; kind < 3; kind++) { /* balance, power, power merging alone */
        cdl_mis_counts c = {1.0f, 1.0f, 1.0f, 0.0f, 0.0f, 0.37f};
        if (kind == 2)
            c = (cdl_mis_counts){0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.37f};
        cdl_connect_ctx cx = {&s, &cam, kind ? CDL_MIS_POWER : CDL_MIS_BALANCE, 0.0f, &c, 1};
        for (uint32_t path = 0; path < 3000; path++) {
            cdl_sampler se, sl;
            cdl_sampler_start(&se, CDL_SAMPLER_INDEPENDENT, 5, path, 0);
            cdl_sampler_start(&sl, CDL_SAMPLER_INDEPENDENT, 5, path + 100000, 0);
            cdl_vs_clear(&evs);
            cdl_vs_clear(&lvs);
            uint64_t rays = 0;
            uint32_t ne = cdl_trace_eye_subpath(&s, &cam, 64.0f * cdl_sampler_1d(&se), 64.0f * cdl_sampler_1d(&se),
                                                &walk, &se, &evs, &rays);
            uint32_t nl = cdl_trace_light_subpath(&s, &walk, &sl, &lvs, &rays);
            if (nl)
                lights[(lvs.flags[0] & CDL_V_INFINITE) ? 2 : (lvs.flags[0] & CDL_V_DELTA_LIGHT) ? 1 : 0]++;
            cdl_merge_partials_eye(&cx, &evs, ne, b1, b2, ge);
            cdl_merge_partials_light(&cx, &lvs, 0, nl, a1, a2, gl);
            for (uint32_t k = 1; k < ne; k++) {
                if (evs.flags[k] & CDL_V_INFINITE)
                    break;
                cdl_bsdf b;
                cdl_vs_bsdf(&s, &evs, k, &b);
                if (cdl_bsdf_is_delta(&b))
                    continue;
                for (uint32_t m = 1; m < nl; m++) {
                    if (cdl_mat_is_delta(s.mats[lvs.mat[m]].type))
                        continue;
                    cdl_vec3 wo = evs.wi[k], wl = lvs.wi[m];
                    float w0 = cdl_merge_weight(&cx, &evs, k + 1, &b, &lvs, 0, m + 1);
                    float pe = cdl_bsdf_pdf(&b, wo, wl) * gl[m], pl = cdl_bsdf_pdf(&b, wl, wo) * ge[k];
                    float w1 = cdl_mis_merge_partials(cx.mis, a1[m], a2[m], pe, b1[k], b2[k], pl);
                    double d = fabs((double)w0 - (double)w1) / fmax(1e-3, (double)w0);
                    worst = fmax(worst, d);
                    if (!(d < 1e-4) && bad++ < 5)
                        printf("  kind %d k %u m %u ne %u nl %u: walk %.6g, partial sums %.6g a1 %g a2 %g pe %g b1 %g b2 %g pl %g\n", kind, k, m, ne, nl, (double)w0, (double)w1, a1[m], a2[m], pe, b1[k], b2[k], pl);
                    pairs++;
                    specular += (evs.flags[k - 1] & CDL_V_DELTA) || (lvs.flags[m - 1] & CDL_V_DELTA);
                }
            }
        }
    }
    CHECK(bad == 0 && pairs > 10000 && specular > 100 && lights[1] > 100 && lights[2] > 100,
          "merge weights from partial sums equal the walk's on %d eye x light vertex pairs of the caustic scene "
          "(%d next to a specular vertex; light paths from the area, point and infinite lights %d, %d, %d): worst "
          "relative difference %.2g", pairs, specular, lights[0], lights[1], lights[2], worst);
    cdl_vs_free(&evs);
    cdl_vs_free(&lvs);
    cdl_scene_free(&s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: test_vcm CAUSTIC_RING.obj\n");
        return 2;
    }
    test_hashgrid();
    test_partition();
    test_partials(argv[1]);
    return test_failures ? 1 : 0;
}
