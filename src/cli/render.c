/* candela render SCENE [options]: load, render progressive passes until
 * the sample or time budget is met (or Ctrl-C), write the images. */
#define _POSIX_C_SOURCE 200809L
#include <signal.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static cdl_renderer *volatile interrupted_render;

static void on_sigint(int sig)
{
    (void)sig;
    cdl_renderer_cancel(interrupted_render); /* async-signal-safe: an atomic store */
    signal(SIGINT, SIG_DFL);                 /* a second Ctrl-C ends at once */
}

static int on_progress(void *user, const cdl_progress *p)
{
    char label[64];
    snprintf(label, sizeof label, "%u spp", p->passes);
    cli_bar_update(user, p->fraction, p->seconds, label);
    return 0;
}

void cli_default_output(const char *scene_path, const cdl_scene *scene, char *buf, size_t n)
{
    cdl_scene_info info;
    cdl_scene_get_info(scene, &info);
    if (info.output[0] &&
        (cli_has_ext(info.output, ".exr") || cli_has_ext(info.output, ".png") || cli_has_ext(info.output, ".pfm"))) {
        const char *b = strrchr(info.output, '/');
        snprintf(buf, n, "%s", b ? b + 1 : info.output);
        return;
    }
    const char *base = strrchr(scene_path, '/');
    base = base ? base + 1 : scene_path;
    const char *dot = strrchr(base, '.');
    int len = dot ? (int)(dot - base) : (int)strlen(base);
    snprintf(buf, n, "%.*s.exr", len, base);
}

void cli_command_line(int argc, char **argv, char *buf, size_t n)
{
    snprintf(buf, n, "candela");
    for (int i = 0; i < argc; i++) {
        size_t len = strlen(buf);
        snprintf(buf + len, n - len, " %s", argv[i]);
    }
}

int cli_render(int argc, char **argv)
{
#ifdef CDL_HAVE_MPI
    if (cli_mpi_size() > 1) {
        char line[4096];
        cli_command_line(argc, argv, line, sizeof line);
        return cli_render_mpi(argc, argv, line);
    }
#endif
    cdl_error err;
    cli_args a;
    cdl_settings *s;
    int rc;
    if (cli_begin(argc, argv, &s, &a, &rc))
        return rc;
    double t_load = cli_now();
    cdl_scene *scene = NULL;
    cdl_renderer *r = NULL;
    rc = cdl_scene_open(a.scene, s, &scene, &err);
    t_load = cli_now() - t_load;
    if (!rc)
        rc = cdl_renderer_create(scene, s, &r, &err);
    cdl_settings_release(s);
    char defout[1024];
    if (!rc && a.nout == 0) {
        cli_default_output(a.scene, scene, defout, sizeof defout);
        a.out[a.nout++] = defout;
    }
    if (rc) {
        int status = cli_report(&err);
        cdl_scene_release(scene);
        return status;
    }

    interrupted_render = r;
    signal(SIGINT, on_sigint);
    cli_bar bar;
    cli_bar_begin(&bar, a.quiet);
    int pass_failed = 0;
    if (cdl_renderer_render(r, on_progress, &bar, &err)) {
        cli_bar_end(&bar);
        pass_failed = cli_report(&err); /* the passes done so far are still written */
    }
    cli_bar_end(&bar);
    signal(SIGINT, SIG_DFL);
    interrupted_render = NULL;
    uint32_t passes = cdl_renderer_passes(r);
    if (pass_failed && passes == 0) { /* nothing rendered: no image to write */
        cdl_renderer_release(r);
        cdl_scene_release(scene);
        return pass_failed;
    }

    char cmdline[4096];
    cli_command_line(argc, argv, cmdline, sizeof cmdline);
    rc = 0;
    for (int i = 0; !rc && i < a.nout; i++)
        rc = cdl_renderer_write(r, a.out[i], cmdline, &err);
    int status = rc ? cli_report(&err) : 0;
    if (!rc) {
        printf("%s: %s %dx%d, %u spp in %.2f s (load %.2f s), %.2f Mrays/s, %.0f threads, "
               "%.0f non-finite samples%s -> %s%s\n",
               a.scene, cdl_renderer_integrator(r), cdl_renderer_width(r), cdl_renderer_height(r), passes,
               cdl_renderer_stat_value(r, "seconds"), t_load, cdl_renderer_stat_value(r, "mrays_per_s"),
               cdl_renderer_stat_value(r, "threads"), cdl_renderer_stat_value(r, "nonfinite"),
               cdl_renderer_cancelled(r) ? " (interrupted)" : "", a.out[0], a.nout > 1 ? " ..." : "");
        if (!a.quiet)
            fputs(cdl_renderer_report(r), stdout);
    }
    double nonfinite = cdl_renderer_stat_value(r, "nonfinite");
    if (nonfinite > 0.0 && !a.quiet)
        fprintf(stderr, "candela: warning: %s: %.0f samples were NaN or infinite and counted as black\n", a.scene,
                nonfinite);
    int cancelled = cdl_renderer_cancelled(r);
    cdl_renderer_release(r);
    cdl_scene_release(scene);
    if (!status && pass_failed)
        status = pass_failed;
    if (!status && cancelled)
        return 130;
    return status;
}
