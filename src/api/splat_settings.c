#include "api/method_settings.h"

#include <string.h>

#include "api/parse.h"

static const char *valued[] = {"--fractions", "-C", "-S", "-R", "--mode", "--eye-samples", "--cull-nodes", "--cap",
                               "--traversal", "--filter", "--filter-normal", "--filter-depth", "--filter-max",
                               "--cache", "--cache-min", "--cache-weight", "--cache-spacing", "--visibility-mask", "--occlusion"};

int cdl_splat_arg_kind(const char *o)
{
    for (size_t i = 0; i < sizeof valued / sizeof *valued; i++)
        if (!strcmp(o, valued[i]))
            return 1;
    return 0;
}

int cdl_splat_arg(const char *o, const char *v, cdl_splat_options *sp, cdl_error *err)
{
    long l;
    double d;
    int rc = 0;
    if (!strcmp(o, "--fractions")) {
        float f[3];
        rc = cdl_arg_floats(o, v, 3, f, err);
        if (!rc && (!(f[0] >= 0.0f && f[1] >= 0.0f && f[2] >= 0.0f) || !(f[0] + f[1] + f[2] > 0.0f)))
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                               "expected three shares d,i,c, none negative, not all zero, got '%s'", v);
        if (!rc)
            memcpy(sp->fractions, f, sizeof f);
    } else if (!strcmp(o, "-C")) {
        rc = cdl_arg_float(o, v, 1e-4, 1e3, &d, err);
        sp->C = (float)d;
    } else if (!strcmp(o, "-S")) {
        rc = cdl_arg_float(o, v, 0.0, 1.0, &d, err);
        sp->S = (float)d;
    } else if (!strcmp(o, "-R")) {
        rc = cdl_arg_float(o, v, 1e-3, 1.0, &d, err);
        sp->R = (float)d;
    } else if (!strcmp(o, "--mode")) {
        if (!strcmp(v, "direct"))
            sp->mode = CDL_SPLAT_DIRECT;
        else if (!strcmp(v, "histogram"))
            sp->mode = CDL_SPLAT_HISTOGRAM;
        else if (!strcmp(v, "sh"))
            sp->mode = CDL_SPLAT_SH;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected direct, histogram or sh, got '%s'", v);
    } else if (!strcmp(o, "--eye-samples")) {
        rc = cdl_arg_int(o, v, 1, 1024, &l, err);
        sp->eye_samples = (uint32_t)l;
    } else if (!strcmp(o, "--cap")) {
        if (!strcmp(v, "hemisphere"))
            sp->cap = 0.0f;
        else if (!strcmp(v, "plane"))
            sp->cap = 4.0f;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected plane or hemisphere, got '%s'", v);
    } else if (!strcmp(o, "--filter")) {
        rc = cdl_arg_float(o, v, 0.0, 1e12, &d, err);
        sp->filter = (float)d;
    } else if (!strcmp(o, "--filter-normal")) {
        rc = cdl_arg_float(o, v, 0.0, 180.0, &d, err);
        sp->filter_normal = (float)d;
    } else if (!strcmp(o, "--filter-depth")) {
        rc = cdl_arg_float(o, v, 0.0, 1e3, &d, err);
        sp->filter_depth = (float)d;
    } else if (!strcmp(o, "--filter-max")) {
        rc = cdl_arg_int(o, v, 0, 255, &l, err);
        sp->filter_max = (int)l;
    } else if (!strcmp(o, "--cache")) {
        rc = cdl_arg_float(o, v, 0.0, 100.0, &d, err);
        sp->cache = (float)d;
    } else if (!strcmp(o, "--cache-min")) {
        rc = cdl_arg_int(o, v, 1, 1000, &l, err);
        sp->cache_min = (uint32_t)l;
    } else if (!strcmp(o, "--cache-weight")) {
        if (!strcmp(v, "report"))
            sp->cache_ward = 0;
        else if (!strcmp(v, "ward"))
            sp->cache_ward = 1;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected report or ward, got '%s'", v);
    } else if (!strcmp(o, "--cache-spacing")) {
        if (!strcmp(v, "gradient"))
            sp->cache_geometric = 0;
        else if (!strcmp(v, "geometric"))
            sp->cache_geometric = 1;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected gradient or geometric, got '%s'", v);
    } else if (!strcmp(o, "--visibility-mask")) {
        if (!strcmp(v, "on"))
            sp->visibility_mask = 1;
        else if (!strcmp(v, "off"))
            sp->visibility_mask = 0;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
    } else if (!strcmp(o, "--occlusion")) {
        if (!strcmp(v, "on"))
            sp->occlusion = 1;
        else if (!strcmp(v, "off"))
            sp->occlusion = 0;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
    } else if (!strcmp(o, "--traversal")) {
        if (!strcmp(v, "sphere"))
            sp->slabs = 0;
        else if (!strcmp(v, "slabs"))
            sp->slabs = 1;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected sphere or slabs, got '%s'", v);
    } else if (!strcmp(o, "--cull-nodes")) {
        if (!strcmp(v, "on"))
            sp->cull = 1;
        else if (!strcmp(v, "off"))
            sp->cull = 0;
        else
            rc = cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
    }
    return rc;
}
