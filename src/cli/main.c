/* candela command-line driver: parses options and calls the library. */
#include <string.h>

#include "cli.h"

int cli_report(const cdl_error *err)
{
    /* a parameter the library names (max_radius) as the command line spells it */
    cdl_error e = *err;
    for (int i = 0; !e.line && i < cdl_option_count(); i++)
        if (!strcmp(cdl_option_get(i)->name, e.file)) {
            char flag[64];
            cli_flag_name(e.file, flag, sizeof flag);
            snprintf(e.file, sizeof e.file, "%s", flag);
            break;
        }
    char buf[2048];
    cdl_error_format(&e, buf, sizeof buf);
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

static int run(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return 2;
    }
    if (!strcmp(argv[1], "render"))
        return cli_render(argc - 1, argv + 1);
    if (!strcmp(argv[1], "photons"))
        return cli_photons(argc - 1, argv + 1);
    if (!strcmp(argv[1], "diff"))
        return cli_diff(argc - 1, argv + 1);
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
#ifdef CDL_HAVE_MPI
        printf("candela %s (MPI)\n", cdl_version());
#else
        printf("candela %s\n", cdl_version());
#endif
        return 0;
    }
    cdl_error err = {CDL_ERR_USAGE, 0, "", "unknown command (try candela --help)"};
    snprintf(err.file, sizeof err.file, "%s", argv[1]);
    return cli_report(&err);
}

int main(int argc, char **argv)
{
#ifdef CDL_HAVE_MPI
    cli_mpi_init(&argc, &argv);
    int status = run(argc, argv);
    cli_mpi_finalize();
    return status;
#else
    return run(argc, argv);
#endif
}
