/* candela photons SCENE [render options] -o top.png: the stored photons
 * (and, with --importance, the importons in TOP.importons.png) seen from
 * above, as in Keller & Wald's Figures 1, 2 and 4. */
#include <string.h>

#include "cli.h"

static void sibling(const char *out, const char *tag, char *buf, size_t n)
{
    const char *dot = strrchr(out, '.');
    int len = dot ? (int)(dot - out) : (int)strlen(out);
    snprintf(buf, n, "%.*s.%s%s", len, out, tag, dot ? dot : ".png");
}

int cli_photons(int argc, char **argv)
{
    cdl_error err;
    cli_args a;
    cdl_settings *s;
    int rc;
    if (cli_begin(argc, argv, &s, &a, &rc))
        return rc;
    cdl_scene *scene = NULL;
    cdl_image *ph = NULL, *imp = NULL;
    char summary[512], out[1024], path[1100];
    rc = cdl_scene_open(a.scene, s, &scene, &err);
    if (!rc)
        rc = cdl_photon_plot(scene, s, 800, &ph, &imp, summary, sizeof summary, &err);
    if (!rc) {
        if (a.nout) {
            snprintf(out, sizeof out, "%s", a.out[0]);
        } else { /* SCENE.photons.png in the current directory */
            const char *base = strrchr(a.scene, '/');
            base = base ? base + 1 : a.scene;
            const char *dot = strrchr(base, '.');
            snprintf(out, sizeof out, "%.*s.photons.png", dot ? (int)(dot - base) : (int)strlen(base), base);
        }
        rc = cdl_image_save(ph, out, 0.0f, &err);
    }
    if (!rc && imp) {
        sibling(out, "importons", path, sizeof path);
        rc = cdl_image_save(imp, path, 0.0f, &err);
    }
    if (!rc)
        printf("%s: %s -> %s%s%s\n", a.scene, summary, out, imp ? ", " : "", imp ? path : "");
    int status = rc ? cli_report(&err) : 0;
    cdl_image_release(ph);
    cdl_image_release(imp);
    cdl_scene_release(scene);
    cdl_settings_release(s);
    return status;
}
