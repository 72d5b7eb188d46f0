/* Helpers for tests that build scenes in code and render them. */
#ifndef CDL_TEST_UTIL_H
#define CDL_TEST_UTIL_H

#include <stdio.h>
#include <stdlib.h>

#include "integrators/integrator.h"
#include "io/loader.h"
#include "io/settings.h"
#include "scene/scene.h"

static int test_failures = 0;

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        int ok_ = (cond);                                                                          \
        printf("%s: ", ok_ ? "ok  " : "FAIL");                                                     \
        printf(__VA_ARGS__);                                                                       \
        printf("\n");                                                                              \
        if (!ok_)                                                                                  \
            test_failures++;                                                                       \
    } while (0)

/* Writes n bytes to dir/name (dir NULL: name is the path); exits on failure. */
static inline void test_write(const char *dir, const char *name, const void *data, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s%s%s", dir ? dir : "", dir ? "/" : "", name);
    FILE *f = fopen(path, "wb");
    if (!f || (n && fwrite(data, 1, n, f) != n) || fclose(f)) {
        perror(path);
        exit(2);
    }
}

/* Loads and commits dir/name with the reader its extension names; on
 * failure prints the error (and frees nothing: s is left as the loader
 * left it). Returns the status. */
static inline int test_load(const char *dir, const char *name, cdl_scene *s, cdl_scene_settings *set, cdl_error *err)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    cdl_scene_settings_init(set);
    int rc = cdl_scene_init(s, path, err);
    if (!rc)
        rc = cdl_scene_load(s, path, set, err);
    if (!rc)
        rc = cdl_scene_commit(s, err);
    if (rc) {
        char buf[2048];
        cdl_error_format(err, buf, sizeof buf);
        printf("      load %s: %s\n", name, buf);
    }
    return rc;
}

static inline void die_on(int rc, const cdl_error *err)
{
    if (rc) {
        char buf[2048];
        cdl_error_format(err, buf, sizeof buf);
        fprintf(stderr, "setup failed: %s\n", buf);
        exit(2);
    }
}

/* Renders passes [0, npass) of `integrator` into a new film. */
static inline void render_film(const char *integrator, const cdl_scene *s, const cdl_options *opt,
                        int w, int h, uint32_t npass, cdl_film *film)
{
    cdl_error err;
    cdl_integrator it;
    die_on(cdl_integrator_create(integrator, &it, &err), &err);
    die_on(it.vt->prepare(it.self, s, opt, &err), &err);
    die_on(cdl_film_init(film, w, h, &err), &err);
    for (uint32_t p = 0; p < npass; p++)
        die_on(it.vt->render_pass(it.self, film, p, &err), &err);
    cdl_integrator_destroy(&it);
}

/* As cdl_film_resolve: the pixel's own samples plus light-tracing splats. */
static inline double film_pixel(const cdl_film *f, int x, int y, int c)
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    double v = f->sum[3 * i + c] / f->count[i];
    if (f->splat && f->splat_passes)
        v += f->splat[3 * i + c] / f->splat_passes;
    return v;
}

#endif
