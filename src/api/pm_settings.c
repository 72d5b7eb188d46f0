#include "api/method_settings.h"

#include <string.h>

#include "api/parse.h"
#include "spatial/photon_map.h"
#include "transport/light_select.h"

static const char *valued[] = {"--photons",        "--knn",           "--max-radius", "--kernel",
                               "--gather",         "--importons",     "--importance-eps",
                               "--caustic-ratio",  "--caustic-select", "--direct",    "--lcon-radius",
                               "--photon-paths-max", "--precompute", "--visibility"};
static const char *flags[] = {"--importance", "--importance-discard"};

int cdl_pm_arg_kind(const char *o)
{
    for (size_t i = 0; i < sizeof valued / sizeof *valued; i++)
        if (!strcmp(o, valued[i]))
            return 1;
    for (size_t i = 0; i < sizeof flags / sizeof *flags; i++)
        if (!strcmp(o, flags[i]))
            return 2;
    return 0;
}

int cdl_pm_arg(const char *o, const char *v, cdl_pm_options *pm, cdl_error *err)
{
    long l;
    double d;
    int rc = 0;
    if (!strcmp(o, "--importance")) {
        pm->importance = 1;
    } else if (!strcmp(o, "--importance-discard")) {
        pm->discard = 1;
    } else if (!strcmp(o, "--photons")) {
        rc = cdl_arg_int(o, v, 1, 500000000L, &l, err);
        pm->photons = (uint32_t)l;
    } else if (!strcmp(o, "--knn")) {
        rc = cdl_arg_int(o, v, 1, 4096, &l, err);
        pm->k = (uint32_t)l;
    } else if (!strcmp(o, "--max-radius")) {
        rc = cdl_arg_float(o, v, 1e-9, 1e9, &d, err);
        pm->max_radius = (float)d;
    } else if (!strcmp(o, "--lcon-radius")) {
        rc = cdl_arg_float(o, v, 1e-9, 1e9, &d, err);
        pm->lcon_radius = (float)d;
    } else if (!strcmp(o, "--gather")) {
        rc = cdl_arg_int(o, v, 0, 65536, &l, err);
        pm->gather = (uint32_t)l;
    } else if (!strcmp(o, "--precompute")) {
        rc = cdl_arg_int(o, v, 0, 1000000, &l, err);
        pm->precompute = (uint32_t)l;
    } else if (!strcmp(o, "--importons")) {
        rc = cdl_arg_int(o, v, 1, 100000000L, &l, err);
        pm->importons = (uint64_t)l;
    } else if (!strcmp(o, "--importance-eps")) {
        rc = cdl_arg_float(o, v, 0.0, 1.0, &d, err);
        /* p = 0 would drop photons where no importon landed: bias */
        if (!rc && !(d > 0.0))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                 "must be in (0, 1]: a zero bound drops photons no importon saw (biased), got '%s'",
                                 v);
        pm->eps = (float)d;
    } else if (!strcmp(o, "--caustic-ratio")) {
        rc = cdl_arg_float(o, v, 0.0, 1.0, &d, err);
        if (!rc && !(d > 0.0))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "must be in (0, 1], got '%s'", v);
        pm->caustic_ratio = (float)d;
    } else if (!strcmp(o, "--photon-paths-max")) {
        rc = cdl_arg_int(o, v, 1, 2147483647L, &l, err);
        pm->max_paths = (uint64_t)l;
    } else if (!strcmp(o, "--kernel")) {
        if (!strcmp(v, "box"))
            pm->kernel = CDL_KERNEL_BOX;
        else if (!strcmp(v, "cone"))
            pm->kernel = CDL_KERNEL_CONE;
        else if (!strcmp(v, "epanechnikov"))
            pm->kernel = CDL_KERNEL_EPANECHNIKOV;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected box, cone or epanechnikov, got '%s'", v);
    } else if (!strcmp(o, "--caustic-select")) {
        if (!strcmp(v, "prefix"))
            pm->caustic_random = 0;
        else if (!strcmp(v, "random"))
            pm->caustic_random = 1;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected prefix or random, got '%s'", v);
    } else if (!strcmp(o, "--visibility")) {
        if (!strcmp(v, "gather"))
            pm->visibility = CDL_PM_VIS_GATHER;
        else if (!strcmp(v, "all"))
            pm->visibility = CDL_PM_VIS_ALL;
        else if (!strcmp(v, "off"))
            pm->visibility = CDL_PM_VIS_OFF;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected gather, all or off, got '%s'", v);
    } else if (!strcmp(o, "--direct")) {
        if (!strcmp(v, "power") || !strcmp(v, "sample")) /* sample: splat's name for it */
            pm->direct = CDL_DIRECT_POWER;
        else if (!strcmp(v, "lcon"))
            pm->direct = CDL_DIRECT_LCON;
        else if (!strcmp(v, "lcon-biased"))
            pm->direct = CDL_DIRECT_LCON_BIASED;
        else if (!strcmp(v, "photons"))
            pm->direct_photons = 1;
        else if (!strcmp(v, "none"))
            pm->direct = CDL_DIRECT_NONE;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected power (or sample), lcon, lcon-biased, photons or none, got '%s'",
                                 v);
        if (strcmp(v, "photons"))
            pm->direct_photons = 0;
    }
    return rc;
}

int cdl_pm_args_check(const cdl_pm_options *pm, cdl_error *err)
{
    if (pm->discard && !pm->importance)
        return cdl_error_set(err, CDL_ERR_USAGE, "--importance-discard", 0, "needs --importance");
    return 0;
}
