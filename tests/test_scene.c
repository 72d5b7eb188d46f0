/* Scene import and ray queries on the shipped Cornell box: counts, lights,
 * camera orientation, and the shadow-ray bundle (Embree stream) agreeing
 * with single rays; an OBJ whose usemtl names a material its MTL lacks
 * loads, with a warning at that line, as Assimp and the renderers OBJ
 * files come from read it. Usage: test_scene CornellBox-Original.obj
 * [usemtl_undefined.obj] */
#include <string.h>

#include "core/log.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "scene/camera.h"
#include "io/loader.h"
#include "test_util.h"

static void on_warning(void *user, const char *file, int line, const char *msg)
{
    (void)file;
    *(int *)user += line == 11 && strstr(msg, "no_such_material") != NULL;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_scene CORNELL.obj\n");
        return 2;
    }
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, argv[1], &err), &err);
    die_on(cdl_scene_load(&s, argv[1], NULL, &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    CHECK(s.ntris == 36, "Cornell box has %u triangles (36)", s.ntris);
    CHECK(s.nlights == 2, "%u area lights (the two triangles of the light quad)", s.nlights);
    CHECK(s.nlights == 2 && s.lights[0].n.y < -0.99f, "light faces down (n.y = %.3f)", (double)s.lights[0].n.y);
    float area = 0.0f;
    for (uint32_t i = 0; i < s.nlights; i++)
        area += s.lights[i].area;
    CHECK(fabsf(area - 0.47f * 0.38f) < 1e-4f, "light area %.5f (0.47 x 0.38)", (double)area);
    CHECK(fabsf(s.bmin.x + 1.02f) < 1e-5f && fabsf(s.bmax.y - 1.99f) < 1e-5f, "bounds x >= %.3f, y <= %.3f",
          (double)s.bmin.x, (double)s.bmax.y);

    /* Red wall on the left: a ray through the left edge of the image hits
     * the material named leftWall. */
    cdl_camera cam;
    die_on(cdl_camera_init(&cam, cdl_v3(0, 1, 3.9f), cdl_v3(0, 1, 0), cdl_v3(0, 1, 0), 39.3077f, 256, 256, &err), &err);
    cdl_hit h;
    int hit = cdl_intersect(&s, cam.eye, cdl_camera_ray(&cam, 3.0f, 128.0f), 1e30f, &h);
    const char *name = hit ? s.mats[s.tri_mat[h.prim]].name : "(miss)";
    CHECK(hit && !strcmp(name, "leftWall"), "left edge of the image sees '%s' (leftWall)", name);
    hit = cdl_intersect(&s, cam.eye, cdl_camera_ray(&cam, 128.0f, 30.0f), 1e30f, &h);
    name = hit ? s.mats[s.tri_mat[h.prim]].name : "(miss)";
    CHECK(hit && !strcmp(name, "ceiling"), "top edge of the image sees '%s' (ceiling)", name);

    /* Bundles of shadow rays towards one point, as the point-light methods
     * trace them, against single rays. */
    enum { N = 5000 };
    static cdl_vec3 o[N], d[N];
    static float t[N];
    static uint8_t blocked[N];
    cdl_rng r;
    cdl_rng_seed(&r, 9, 0);
    cdl_vec3 target = cdl_v3(0.1f, 1.5f, -0.3f);
    int agree = 0, nblocked = 0;
    for (int i = 0; i < N; i++) {
        o[i] = cdl_v3(2.0f * cdl_rng_float(&r) - 1.0f, 1.98f * cdl_rng_float(&r), 2.0f * cdl_rng_float(&r) - 1.0f);
        cdl_vec3 e = cdl_sub(target, o[i]);
        t[i] = cdl_length(e);
        d[i] = cdl_scale(e, 1.0f / t[i]);
    }
    cdl_occluded_bundle(&s, N, o, d, t, UINT32_MAX, blocked);
    for (int i = 0; i < N; i++) {
        agree += blocked[i] == cdl_occluded(&s, o[i], d[i], t[i]);
        nblocked += blocked[i];
    }
    CHECK(agree == N, "bundle and single shadow rays agree on %d of %d rays", agree, N);
    CHECK(nblocked > N / 20 && nblocked < N - N / 20, "%d of %d rays blocked (the test sees both cases)", nblocked, N);
    cdl_scene_free(&s);

    if (argc > 2) {
        int warned = 0;
        cdl_log_sink sink = {on_warning, &warned, 0};
        const cdl_log_sink *prev = cdl_log_push(&sink);
        int rc = cdl_scene_init(&s, argv[2], &err);
        if (!rc)
            rc = cdl_scene_load(&s, argv[2], NULL, &err);
        if (!rc)
            rc = cdl_scene_commit(&s, &err);
        cdl_log_pop(prev);
        CHECK(!rc && warned == 1 && s.ntris > 0, "usemtl of a missing material: loads (rc %d), %d warning at line 11",
              rc, warned);
        if (!rc)
            cdl_scene_free(&s);
    }
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
