#include "api/method_settings.h"

#include <string.h>

#include "api/parse.h"

static const char *valued[] = {"--eye-paths", "--links", "--bandwidth", "--path-memory", "--footprint-cap", "--overlaps"};

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
    } else if (!strcmp(o, "--overlaps")) {
        rc = cdl_arg_float(o, v, 1.0, 1e4, &d, err);
        if (!rc && !(d >= 2.0))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                 "must be at least 2: a point a footprint reaches lies in one at least, so "
                                 "fewer cannot be calibrated to, got '%s'", v);
        g->overlaps = (float)d;
    } else if (!strcmp(o, "--path-memory")) {
        rc = cdl_arg_int(o, v, 1, 1048576, &l, err);
        g->max_mib = (uint32_t)l;
    }
    return rc;
}
