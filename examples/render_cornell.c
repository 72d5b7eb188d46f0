/* Renders a scene through the public API alone and, given a reference
 * image, prints how far it is from it:
 *
 *     render_cornell SCENE OUT.exr [REF.exr]
 *
 * Build against an installed candela with
 *     cc render_cornell.c $(pkg-config --cflags --libs candela)
 */
#include <candela/candela.h>
#include <stdio.h>

static int fail(const cdl_error *err)
{
    char buf[2048];
    cdl_error_format(err, buf, sizeof buf);
    fprintf(stderr, "render_cornell: %s\n", buf);
    return 1;
}

static int progress(void *user, const cdl_progress *p)
{
    (void)user;
    fprintf(stderr, "\r%u passes, %.2f s", p->passes, p->seconds);
    return 0; /* non-zero would stop the render after this pass */
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: render_cornell SCENE OUT.exr [REF.exr]\n");
        return 2;
    }
    cdl_error err;
    cdl_scene *scene = NULL;
    cdl_renderer *r = NULL;
    cdl_image *img = NULL, *ref = NULL;
    cdl_settings *s = cdl_settings_create();
    if (!s)
        return 1;
    /* the options of `candela render`, by name */
    const char *opts[][2] = {{"integrator", "path"}, {"res", "256x256"}, {"spp", "16"},
                             {"lookat", "0,1,3.9,0,1,0,0,1,0"}, {"fov", "39.3077"}};
    int rc = 0;
    for (size_t i = 0; !rc && i < sizeof opts / sizeof *opts; i++)
        rc = cdl_settings_set(s, opts[i][0], opts[i][1], &err);
    if (!rc)
        rc = cdl_scene_open(argv[1], s, &scene, &err);
    if (!rc)
        rc = cdl_renderer_create(scene, s, &r, &err);
    if (!rc)
        rc = cdl_renderer_render(r, progress, NULL, &err);
    fprintf(stderr, "\n");
    if (!rc)
        rc = cdl_renderer_write(r, argv[2], NULL, &err);
    if (!rc)
        printf("%s: %u passes in %.2f s, %.1f Mrays/s\n", cdl_renderer_integrator(r), cdl_renderer_passes(r),
               cdl_renderer_stat_value(r, "seconds"), cdl_renderer_stat_value(r, "mrays_per_s"));
    if (!rc && argc > 3) {
        cdl_diff d;
        rc = cdl_renderer_image(r, NULL, &img, &err);
        if (!rc)
            rc = cdl_image_load(argv[3], &ref, &err);
        if (!rc)
            rc = cdl_image_diff(img, ref, &d, &err);
        if (!rc)
            printf("relmse %.4g mean_ratio %.4f\n", d.relmse, d.mean_ratio);
    }
    int status = rc ? fail(&err) : 0;
    cdl_image_release(img);
    cdl_image_release(ref);
    cdl_renderer_release(r);
    cdl_scene_release(scene);
    cdl_settings_release(s);
    return status;
}
