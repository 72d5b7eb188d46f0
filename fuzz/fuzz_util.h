/* Shared by the fuzz targets: each run writes its input to files in a
 * private directory (the readers take paths, as users give them) and opens
 * them through the public API only. */
#ifndef FUZZ_UTIL_H
#define FUZZ_UTIL_H

#define _POSIX_C_SOURCE 200809L
#include <candela/candela.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char fuzz_dir[256];

static void fuzz_init_dir(void)
{
    if (fuzz_dir[0])
        return;
    const char *base = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(fuzz_dir, sizeof fuzz_dir, "%s/candela-fuzz-XXXXXX", base);
    if (!mkdtemp(fuzz_dir))
        abort();
}

/* fuzz_dir/name with n bytes of data; returns the path (static buffer per slot). */
static const char *fuzz_file(int slot, const char *name, const uint8_t *data, size_t n)
{
    static char paths[4][512];
    fuzz_init_dir();
    snprintf(paths[slot], sizeof paths[slot], "%s/%s", fuzz_dir, name);
    FILE *f = fopen(paths[slot], "wb");
    if (!f)
        abort();
    if (n && fwrite(data, 1, n, f) != n)
        abort();
    fclose(f);
    return paths[slot];
}

/* Splits data at the first occurrence of sep: [0, *n1) and the rest. */
static const uint8_t *fuzz_split(const uint8_t *data, size_t n, const char *sep, size_t *n1, size_t *n2)
{
    size_t k = strlen(sep);
    for (size_t i = 0; i + k <= n; i++)
        if (!memcmp(data + i, sep, k)) {
            *n1 = i;
            *n2 = n - i - k;
            return data + i + k;
        }
    *n1 = n;
    *n2 = 0;
    return data + n;
}

/* Opens path as a scene quietly; a scene that loads is also rendered for
 * one pass at 8x8, so what the readers accept reaches the renderer. */
static void fuzz_scene(const char *path)
{
    cdl_settings *s = cdl_settings_create();
    cdl_error err;
    cdl_scene *scene = NULL;
    cdl_renderer *r = NULL;
    if (!s)
        abort();
    cdl_settings_set(s, "quiet", "on", &err);
    cdl_settings_set(s, "res", "8x8", &err);
    cdl_settings_set(s, "spp", "1", &err);
    cdl_settings_set(s, "maxdepth", "3", &err);
    cdl_settings_set(s, "threads", "1", &err);
    cdl_settings_set(s, "integrator", "path", &err);
    if (!cdl_scene_open(path, s, &scene, &err) && !cdl_renderer_create(scene, s, &r, &err))
        cdl_renderer_render(r, NULL, NULL, &err);
    cdl_renderer_release(r);
    cdl_scene_release(scene);
    cdl_settings_release(s);
}

#endif
