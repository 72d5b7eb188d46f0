/* Raw Embree throughput on a scene, the yardstick for candela's Mrays/s:
 * incoherent closest-hit rays (rtcIntersect1) from random surface points
 * in random directions, and as many shadow rays (rtcOccluded1) between
 * random surface points, traced on all threads from pre-generated arrays
 * so that nothing but Embree is timed.
 * usage: bench_rays SCENE [--point-light x,y,z,r,g,b] [--rays N] */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "io/loader.h"

static cdl_vec3 random_surface_point(const cdl_scene *s, cdl_rng *r, cdl_vec3 *n)
{
    uint32_t t = cdl_rng_u32(r) % s->ntris;
    float b1, b2;
    cdl_sample_triangle(cdl_rng_float(r), cdl_rng_float(r), &b1, &b2);
    const uint32_t *ix = s->idx + 3 * (size_t)t;
    cdl_vec3 p[3];
    for (int k = 0; k < 3; k++)
        p[k] = cdl_v3(s->pos[3 * ix[k]], s->pos[3 * ix[k] + 1], s->pos[3 * ix[k] + 2]);
    *n = s->face_n[t];
    return cdl_add(p[0], cdl_add(cdl_scale(cdl_sub(p[1], p[0]), b1), cdl_scale(cdl_sub(p[2], p[0]), b2)));
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_rays SCENE [--point-light x,y,z,r,g,b] [--rays N]\n");
        return 2;
    }
    long nrays = 4000000;
    float pl[6];
    int has_pl = 0;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--rays"))
            nrays = atol(argv[i + 1]);
        else if (!strcmp(argv[i], "--point-light"))
            has_pl = sscanf(argv[i + 1], "%f,%f,%f,%f,%f,%f", &pl[0], &pl[1], &pl[2], &pl[3], &pl[4], &pl[5]) == 6;
    }
    if (nrays < 1000)
        nrays = 1000;
    static const cdl_log_sink quiet = {NULL, NULL, 1};
    cdl_log_push(&quiet);
    cdl_scene s;
    cdl_error err;
    int rc = cdl_scene_init(&s, argv[1], &err);
    if (!rc)
        rc = cdl_scene_load(&s, argv[1], NULL, &err);
    if (!rc && has_pl)
        rc = cdl_scene_add_point_light(&s, cdl_v3(pl[0], pl[1], pl[2]), cdl_v3(pl[3], pl[4], pl[5]), &err);
    if (!rc)
        rc = cdl_scene_commit(&s, &err);
    if (rc) {
        char buf[2048];
        cdl_error_format(&err, buf, sizeof buf);
        fprintf(stderr, "bench_rays: %s\n", buf);
        return 1;
    }
    cdl_vec3 *o = malloc(sizeof(cdl_vec3) * (size_t)nrays), *d = malloc(sizeof(cdl_vec3) * (size_t)nrays);
    cdl_vec3 *so = malloc(sizeof(cdl_vec3) * (size_t)nrays), *sd = malloc(sizeof(cdl_vec3) * (size_t)nrays);
    float *st = malloc(sizeof(float) * (size_t)nrays);
#pragma omp parallel for schedule(static)
    for (long i = 0; i < nrays; i++) {
        cdl_rng r;
        cdl_rng_seed(&r, 42, (uint64_t)i);
        cdl_vec3 n, n2;
        cdl_vec3 p = random_surface_point(&s, &r, &n);
        cdl_vec3 dir = cdl_sample_uniform_sphere(cdl_rng_float(&r), cdl_rng_float(&r));
        o[i] = cdl_offset(&s, p, n, dir);
        d[i] = dir;
        cdl_vec3 q = random_surface_point(&s, &r, &n2);
        cdl_vec3 e = cdl_sub(q, p);
        float len = cdl_length(e);
        sd[i] = len > 0.0f ? cdl_scale(e, 1.0f / len) : cdl_v3(0.0f, 0.0f, 1.0f);
        so[i] = cdl_offset(&s, p, n, sd[i]);
        st[i] = len * 0.999f;
    }
    long hits = 0, blocked = 0;
    double t0 = cdl_time_now();
#pragma omp parallel for schedule(dynamic, 4096) reduction(+ : hits, blocked)
    for (long i = 0; i < nrays; i++) {
        cdl_hit h;
        hits += cdl_intersect(&s, o[i], d[i], 1e30f, &h);
        blocked += cdl_occluded(&s, so[i], sd[i], st[i]);
    }
    double t = cdl_time_now() - t0;
    printf("%s: %u triangles, %d threads, %ld closest-hit + %ld shadow rays in %.3f s: %.2f Mrays/s "
           "(%.1f%% hit, %.1f%% blocked)\n",
           argv[1], s.ntris, omp_get_max_threads(), nrays, nrays, t, 2.0 * (double)nrays / t * 1e-6,
           100.0 * (double)hits / (double)nrays, 100.0 * (double)blocked / (double)nrays);
    free(o);
    free(d);
    free(so);
    free(sd);
    free(st);
    cdl_scene_free(&s);
    return 0;
}
