#include "cli/gkde_args.h"

#include <stdio.h>
#include <string.h>

#include "cli/args.h"

static const char *valued[] = {"--eye-paths", "--links", "--bandwidth", "--path-memory", "--footprint-cap"};

int cdl_gkde_arg_kind(const char *o)
{
    for (size_t i = 0; i < sizeof valued / sizeof *valued; i++)
        if (!strcmp(o, valued[i]))
            return 1;
    return 0;
}

int cdl_gkde_arg(const char *o, const char *v, cdl_gkde_options *g, cdl_error *err)
{
    long l;
    double d;
    int rc = 0;
    if (!strcmp(o, "--eye-paths")) {
        rc = cdl_arg_int(o, v, 1, 1024, &l, err);
        g->eye_paths = (uint32_t)l;
    } else if (!strcmp(o, "--links")) {
        rc = cdl_arg_int(o, v, 1, 100000, &l, err);
        g->links = (uint32_t)l;
    } else if (!strcmp(o, "--bandwidth")) {
        rc = cdl_arg_float(o, v, 1e-9, 1e3, &d, err);
        g->bandwidth = (float)d;
    } else if (!strcmp(o, "--footprint-cap")) {
        rc = cdl_arg_float(o, v, 0.0, 1e6, &d, err);
        g->footprint_cap = (float)d;
    } else if (!strcmp(o, "--path-memory")) {
        rc = cdl_arg_int(o, v, 1, 1048576, &l, err);
        g->max_mib = (uint32_t)l;
    }
    return rc;
}

void cdl_gkde_args_help(void)
{
    printf("Generalized kernel density estimation (gkde; Bekaert et al. 2003):\n"
           "      --light-paths N     light paths per step (default 100000)\n"
           "      --eye-paths N       eye paths per pixel and step (default 1)\n"
           "      --links M           unoccluded links wanted per eye vertex (default 10)\n"
           "      --bandwidth h       footprint bandwidth of eq. 7 (default: calibrated in\n"
           "                          the first step so that an eye vertex lies in about M\n"
           "                          first-bounce footprints)\n"
           "      --footprint-cap F   footprint radii at most F times the median\n"
           "                          first-bounce one (default 2; 0: eq. 7 unbounded)\n"
           "      --path-memory MiB   cap on the stored light and eye vertices (default 4096)\n"
           "\n");
}
