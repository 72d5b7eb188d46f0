/* candela command-line driver: parses options and calls the library. */
#include <stdio.h>
#include <string.h>

#include "cli/commands.h"
#include "core/error.h"
#include "integrators/integrator.h"

int cdl_report(const cdl_error *err)
{
    char buf[2048];
    cdl_error_format(err, buf, sizeof buf);
    fflush(stdout);
    fprintf(stderr, "candela: error: %s\n", buf);
    return err->code == CDL_ERR_USAGE ? 2 : 1;
}

static void usage(FILE *f)
{
    fprintf(f,
            "usage: candela render SCENE [options]    render a scene\n"
            "       candela photons SCENE [options]   the photon map (and importons) from above\n"
            "       candela diff TEST REF [--heatmap OUT.png] [--region X0,Y0,X1,Y1]\n"
            "                                         compare two images (or one region)\n"
            "       candela --help | --version\n"
            "\n"
            "`candela render --help` lists the render options and integrators.\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "render"))
        return cdl_cmd_render(argc - 1, argv + 1);
    if (!strcmp(argv[1], "photons"))
        return cdl_cmd_photons(argc - 1, argv + 1);
    if (!strcmp(argv[1], "diff"))
        return cdl_cmd_diff(argc - 1, argv + 1);
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("candela 0.1\n");
        return 0;
    }
    cdl_error err;
    cdl_error_set(&err, CDL_ERR_USAGE, argv[1], 0, "unknown command (try candela --help)");
    return cdl_report(&err);
}
