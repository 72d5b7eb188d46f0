/* The public API through candela.h alone, under the sanitizers too: every
 * handle made and released, the error paths (bad files, options, calls),
 * cancel from a callback and from another thread, incremental passes,
 * statistics, layers and image functions.
 * Usage: test_api CORNELL.obj BAD.pbrt (a file whose line 6 is wrong). */
#include <candela/candela.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
#define CHECK(cond, ...)                                                                                          \
    do {                                                                                                          \
        if (!(cond)) {                                                                                            \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                                           \
            printf(__VA_ARGS__);                                                                                  \
            printf("\n");                                                                                         \
            failures++;                                                                                           \
        }                                                                                                         \
    } while (0)

static cdl_settings *box_settings(const char *integ, const char *spp)
{
    cdl_settings *s = cdl_settings_create();
    cdl_error err;
    const char *kv[][2] = {{"integrator", integ}, {"res", "24x24"}, {"spp", spp}, {"threads", "1"},
                           {"lookat", "0,1,3.9,0,1,0,0,1,0"}, {"fov", "39.3077"}};
    for (size_t i = 0; i < sizeof kv / sizeof *kv; i++)
        CHECK(!cdl_settings_set(s, kv[i][0], kv[i][1], &err), "set %s: %s", kv[i][0], err.msg);
    return s;
}

static int stop_at_two(void *user, const cdl_progress *p)
{
    *(uint32_t *)user = p->passes;
    return p->passes >= 2;
}

static atomic_int started, cancelled_at;

static int note_pass(void *user, const cdl_progress *p)
{
    (void)user;
    atomic_store(&started, (int)p->passes);
    return 0;
}

static void *cancel_when_started(void *r)
{
    while (atomic_load(&started) < 1)
        sched_yield();
    cdl_renderer_cancel(r);
    atomic_store(&cancelled_at, atomic_load(&started));
    return NULL;
}

static double mean(cdl_image *img)
{
    const float *p = cdl_image_pixels(img);
    size_t n = 3 * (size_t)cdl_image_width(img) * (size_t)cdl_image_height(img);
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += p[i];
    return s / (double)n;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: test_api CORNELL.obj BAD.pbrt\n");
        return 2;
    }
    cdl_error err;
    char buf[2048];

    /* options: checked when set, a failed set changes nothing */
    cdl_settings *s = cdl_settings_create();
    CHECK(cdl_settings_set(s, "no-such-option", "1", &err) == CDL_ERR_USAGE && !strcmp(err.file, "no-such-option"),
          "unknown option: %d %s", err.code, err.file);
    CHECK(cdl_settings_set(s, "--spp", "-5", &err) == CDL_ERR_USAGE && strstr(err.msg, "[1, 1000000]"),
          "spp -5: %s", err.msg);
    CHECK(cdl_settings_set(s, "res", "0x5", &err) == CDL_ERR_USAGE, "res 0x5 accepted");
    CHECK(cdl_settings_set(s, "photons", NULL, &err) == CDL_ERR_USAGE && strstr(err.msg, "expects a value"),
          "photons without a value: %s", err.msg);
    CHECK(cdl_settings_set(s, "integrator", "nope", &err) == CDL_ERR_USAGE, "unknown integrator accepted");
    CHECK(!cdl_settings_set(s, "max_radius", "0.5", &err), "max_radius (underscore): %s", err.msg);
    CHECK(!cdl_settings_set(s, "importance", NULL, &err) && !cdl_settings_set(s, "importance", "off", &err),
          "flag on/off: %s", err.msg);
    CHECK(cdl_settings_set(s, "importance", "maybe", &err) == CDL_ERR_USAGE, "flag 'maybe' accepted");
    CHECK(!cdl_settings_set(s, "spp", "4", &err) && !cdl_settings_set(s, "time", "1", &err) &&
              cdl_settings_check(s, &err) == CDL_ERR_USAGE && strstr(err.msg, "either spp or time"),
          "spp and time together pass the check");
    cdl_settings_release(s);
    cdl_settings_release(NULL);

    /* a parameter the method does not read is refused: when set once the
     * method is known, else by the check */
    s = cdl_settings_create();
    CHECK(!cdl_settings_set(s, "knn", "50", &err) && !cdl_settings_check(s, &err), "knn before the method: %s",
          err.msg);
    CHECK(!cdl_settings_set(s, "integrator", "path", &err) && cdl_settings_check(s, &err) == CDL_ERR_USAGE &&
              !strcmp(err.file, "knn") && strstr(err.msg, "path"),
          "path with knn passes the check: %s %s", err.file, err.msg);
    cdl_settings_release(s);
    s = cdl_settings_create();
    CHECK(!cdl_settings_set(s, "integrator", "splat", &err) && cdl_settings_set(s, "knn", "5", &err) == CDL_ERR_USAGE &&
              !strcmp(err.file, "knn") && strstr(err.msg, "splat"),
          "splat took knn: %s", err.msg);
    CHECK(!cdl_settings_set(s, "gather", "2", &err) && !cdl_settings_set(s, "direct", "sample", &err) &&
              cdl_settings_set(s, "direct", "lcon", &err) == CDL_ERR_USAGE,
          "splat's own gather and direct: %s", err.msg);
    cdl_settings_release(s);

    /* discovery */
    int found = 0;
    for (int i = 0; i < cdl_option_count(); i++) {
        const cdl_option_info *o = cdl_option_get(i);
        CHECK(o->name[0] && o->help[0] && o->section[0], "option %d incomplete", i);
        found += !strcmp(o->name, "photons") && !strcmp(o->integrators, "pm,splat,sppm") && !strcmp(o->default_value, "200000");
    }
    CHECK(found == 1 && !cdl_option_get(-1) && !cdl_option_get(cdl_option_count()), "option table");
    CHECK(cdl_integrator_count() == 9 && !strcmp(cdl_integrator_name(0), "path") && !cdl_integrator_name(9),
          "integrators: %d", cdl_integrator_count());

    /* scenes: errors name the file and the line */
    cdl_scene *scene = NULL;
    CHECK(cdl_scene_open(argv[2], NULL, &scene, &err) == CDL_ERR_INPUT && err.line == 6 && !scene,
          "bad pbrt: %d %s:%d", err.code, err.file, err.line);
    cdl_error_format(&err, buf, sizeof buf);
    CHECK(strstr(buf, ":6: ") != NULL, "formatted: %s", buf);
    CHECK(cdl_scene_open("/nonexistent.obj", NULL, &scene, &err) != 0 && !scene, "missing file opened");
    cdl_settings *pl = cdl_settings_create();
    CHECK(!cdl_settings_set(pl, "point-light", "0,1.5,0,1,1,1", &err), "point-light: %s", err.msg);
    CHECK(!cdl_scene_open(argv[1], pl, &scene, &err), "open: %s", err.msg);
    cdl_settings_release(pl);
    cdl_scene_info info;
    cdl_scene_get_info(scene, &info);
    CHECK(info.triangles > 30 && info.lights >= 2 && info.bounds_max[1] > 1.9f, "info: %u tris %u lights",
          info.triangles, info.lights);

    /* a render stopped by its callback after two passes equals a 2-pass render */
    cdl_settings *s2 = box_settings("path", "2"), *s100 = box_settings("path", "100");
    cdl_renderer *r = NULL, *r2 = NULL;
    uint32_t seen = 0;
    CHECK(!cdl_renderer_create(scene, s100, &r, &err) && !cdl_renderer_render(r, stop_at_two, &seen, &err),
          "render: %s", err.msg);
    CHECK(cdl_renderer_cancelled(r) && cdl_renderer_passes(r) == 2 && seen == 2, "stopped at %u",
          cdl_renderer_passes(r));
    CHECK(!cdl_renderer_create(scene, s2, &r2, &err) && !cdl_renderer_render(r2, NULL, NULL, &err),
          "render: %s", err.msg);
    cdl_image *a = NULL, *b = NULL, *c = NULL;
    CHECK(!cdl_renderer_image(r, NULL, &a, &err) && !cdl_renderer_image(r2, NULL, &b, &err), "image: %s", err.msg);
    CHECK(!memcmp(cdl_image_pixels(a), cdl_image_pixels(b), sizeof(float) * 3 * 24 * 24) && mean(a) > 0.01,
          "cancelled render differs from the 2-pass one");
    /* two more passes in one call: 4 in all */
    CHECK(!cdl_renderer_render_passes(r, 2, NULL, NULL, &err) && cdl_renderer_passes(r) == 4 &&
              !cdl_renderer_cancelled(r),
          "render_passes: %u", cdl_renderer_passes(r));
    CHECK(cdl_renderer_stat_value(r, "passes") == 4.0 && cdl_renderer_stat_value(r, "rays") > 4 * 24 * 24 &&
              isnan(cdl_renderer_stat_value(r, "nothing")),
          "stats");
    const char *name;
    double v;
    CHECK(!cdl_renderer_stat(r, 0, &name, &v) && cdl_renderer_stat(r, 1000, &name, &v) == CDL_ERR_USAGE,
          "stat index");
    CHECK(cdl_renderer_image(r, "pathlength", &c, &err) == CDL_ERR_USAGE && !c, "missing layer given");
    /* a cancel before the render starts is cleared by it; one from another thread stops it */
    pthread_t th;
    cdl_renderer_cancel(r);
    CHECK(!cdl_renderer_render_passes(r, 1, NULL, NULL, &err) && cdl_renderer_passes(r) == 5, "stale cancel");
    cdl_renderer *rt = NULL;
    cdl_settings *big = box_settings("path", "100000");
    CHECK(!cdl_renderer_create(scene, big, &rt, &err), "create: %s", err.msg);
    pthread_create(&th, NULL, cancel_when_started, rt);
    CHECK(!cdl_renderer_render(rt, note_pass, NULL, &err), "render: %s", err.msg);
    pthread_join(th, NULL);
    /* at most the pass under way when the cancel came ends (a pass cut short does not count) */
    CHECK(cdl_renderer_cancelled(rt) && cdl_renderer_passes(rt) <= (uint32_t)atomic_load(&cancelled_at) + 1,
          "cancel from another thread: %u passes, cancelled after %d", cdl_renderer_passes(rt),
          atomic_load(&cancelled_at));
    cdl_renderer_release(rt);
    cdl_settings_release(big);

    /* image functions */
    cdl_image *d = NULL, *e = NULL;
    cdl_diff m;
    CHECK(!cdl_image_diff(a, b, &m, &err) && m.relmse == 0.0 && fabs(m.mean_ratio - 1.0) < 1e-12, "self diff");
    CHECK(!cdl_image_crop(a, 4, 4, 12, 20, &d, &err) && cdl_image_width(d) == 8 && cdl_image_height(d) == 16,
          "crop: %s", err.msg);
    CHECK(cdl_image_crop(a, 4, 4, 40, 20, &e, &err) == CDL_ERR_USAGE && !e, "crop outside accepted");
    CHECK(cdl_image_diff(a, d, &m, &err) != 0, "diff of different sizes");
    CHECK(cdl_image_create(0, 5, &e, &err) == CDL_ERR_USAGE && !e, "0x5 image made");
    CHECK(cdl_image_save(a, "/nonexistent/dir/x.exr", 0.0f, &err) != 0, "save into a missing directory");
    CHECK(cdl_image_load(argv[1], &e, &err) == CDL_ERR_INPUT && !e, "an OBJ read as an image");

    cdl_image_release(a);
    cdl_image_release(b);
    cdl_image_release(d);
    cdl_image_release(NULL);
    cdl_renderer_release(r);
    cdl_renderer_release(r2);
    cdl_renderer_release(NULL);
    cdl_settings_release(s2);
    cdl_settings_release(s100);
    cdl_scene_release(scene);
    cdl_scene_release(NULL);
    CHECK(cdl_renderer_create(NULL, NULL, &r, &err) == CDL_ERR_USAGE && !r, "renderer without a scene");
    if (failures)
        printf("%d checks failed\n", failures);
    else
        printf("ok: public API checks passed\n");
    return failures != 0;
}
