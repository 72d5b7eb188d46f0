#include "cli/pm_args.h"

#include <stdio.h>
#include <string.h>

#include "cli/args.h"
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

void cdl_pm_args_help(void)
{
    printf("Photon mapping (pm; Jensen 1996 with Keller & Wald 2000):\n"
           "      --photons N         global photons stored per pass (default 100000); paths\n"
           "                          are traced until the map holds N\n"
           "      --knn K             photons per radiance estimate (default 50)\n"
           "      --max-radius R      largest estimate radius (default 5 %% of the diagonal)\n"
           "      --kernel KIND       box, cone (default) or epanechnikov\n"
           "      --gather N          final gathering rays per pixel sample (default 8);\n"
           "                          0 shows the global map directly\n"
           "      --precompute M      gather rays landing on Lambertian surfaces read the\n"
           "                          irradiance precomputed at 1 in M photons from the\n"
           "                          others (Christensen 1999; default 4, 0 = a full\n"
           "                          estimate; M >= 2)\n"
           "      --visibility V      which estimates leave out photons hidden from the query\n"
           "                          point (a shadow ray each): gather (default: those at\n"
           "                          final-gather hits, incl. the precomputed irradiance),\n"
           "                          all (also --gather 0 and caustics at the camera's\n"
           "                          point) or off (Jensen's: leaks through thin walls)\n"
           "      --caustic-ratio q   only a fraction q of the paths fills the global map,\n"
           "                          all fill the caustic map (default 1)\n"
           "      --caustic-select S  prefix (the first q N paths, default) or random (a\n"
           "                          test against q per photon)\n"
           "      --importance        store photons with probability p = min(1, f I(x)) from\n"
           "                          importons traced from the camera (power L / p)\n"
           "      --importons N       importon paths (default 131072)\n"
           "      --importance-eps e  lower bound of p, in (0, 1] (default 0.01; unbiased)\n"
           "      --importance-discard  drop photons with p < e instead (biased)\n"
           "      --direct KIND       power (default: lights in proportion to power), lcon\n"
           "                          (S rays to the lights of nearby primary photons, one to\n"
           "                          the rest), lcon-biased (none to the rest) or photons\n"
           "                          (read from the photon map: its primary photons seen\n"
           "                          directly; needs --gather 0) or none (indirect light\n"
           "                          alone, for comparisons)\n"
           "      --shadow-rays S     direct-light shadow rays per shading point (default 4)\n"
           "      --lcon-radius R     radius of the L_con query (default: --max-radius)\n"
           "      --photon-paths-max N  give up when N paths per pass have not stored\n"
           "                          --photons photons (default 1000 per photon, at\n"
           "                          least 2^20)\n"
           "\n");
}
