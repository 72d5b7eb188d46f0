/* The option parser: input lines "name=value" (or "name" alone: a flag or
 * a missing value) set on one settings object, which is then checked and
 * used to set up (not run) a render of a small scene; the resolution is
 * kept small afterwards so that a fuzzed --res does not allocate gigabytes. */
#include "fuzz_util.h"

static cdl_scene *scene;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    static const char obj[] = "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nv -1 -1 1\nf 1 2 3\nf 1 3 4\n";
    cdl_settings *s = cdl_settings_create();
    cdl_error err;
    cdl_settings_set(s, "point-light", "0,0,3,5,5,5", &err);
    if (cdl_scene_open(fuzz_file(0, "s.obj", (const uint8_t *)obj, sizeof obj - 1), s, &scene, &err))
        abort();
    cdl_settings_release(s);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    if (n > 4096)
        return 0;
    char *text = malloc(n + 1);
    memcpy(text, data, n);
    text[n] = 0;
    cdl_settings *s = cdl_settings_create();
    cdl_error err;
    char *save = NULL;
    for (char *line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char *eq = strchr(line, '=');
        if (eq)
            *eq = 0;
        cdl_settings_set(s, line, eq ? eq + 1 : NULL, &err);
    }
    cdl_settings_set(s, "res", "8x8", &err);
    cdl_settings_set(s, "quiet", "on", &err);
    cdl_renderer *r = NULL;
    if (!cdl_settings_check(s, &err) && !cdl_renderer_create(scene, s, &r, &err))
        cdl_renderer_release(r);
    cdl_settings_release(s);
    free(text);
    return 0;
}
