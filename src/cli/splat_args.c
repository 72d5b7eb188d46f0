#include "cli/splat_args.h"

#include <stdio.h>
#include <string.h>

#include "cli/args.h"

static const char *valued[] = {"--fractions", "-C", "-S", "-R", "--mode", "--eye-samples", "--cull-nodes", "--cap",
                               "--traversal", "--filter", "--filter-normal", "--filter-depth", "--filter-max",
                               "--cache", "--cache-min", "--cache-weight", "--cache-spacing", "--visibility-mask"};

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

void cdl_splat_args_help(void)
{
    printf("Photon ray splatting (splat; Herzog et al. 2007):\n"
           "      --photons M         photon rays stored per pass, all budgets (default 200000)\n"
           "      --fractions d,i,c   shares of direct, indirect and caustic rays (default\n"
           "                          0.3,0.6,0.1)\n"
           "      -C c                bandwidth smoothness (default 1.0): mean kernel radius\n"
           "                          C * 0.2 * the mean photon ray length at 10^5 photons\n"
           "      -S s                bandwidth sensitivity to the path density, 0..1 (default\n"
           "                          0.4; 0: one bandwidth for all rays)\n"
           "      -R r                bandwidth clamping, 0..1 (default 0.2): radii within\n"
           "                          [r, 1/r] times the mean\n"
           "      --mode KIND         radiance maps: direct (BSDF per splat), histogram (20\n"
           "                          strata), sh (16 coefficients) (default direct)\n"
           "      --direct KIND       photons (direct light splatted, default), sample\n"
           "                          (light sampling at the eye samples) or none (indirect\n"
           "                          light alone)\n"
           "      --eye-samples N     eye samples per pixel and pass (default 1)\n"
           "      --cull-nodes on|off back-face-culling nodes in the eye-sample tree (default on)\n"
           "      --filter N          image-space filtering of the radiance maps (§6.2): each\n"
           "                          pixel averaged over a box of its own surface segment,\n"
           "                          the smallest holding N photon splats (0: off; default)\n"
           "      --filter-normal DEG segments: neighbours' normals within DEG (default 20)\n"
           "      --filter-depth T    segments: second difference of 1/depth within T of it\n"
           "                          (default 0.05)\n"
           "      --filter-max R      largest box: (2R+1)^2 pixels (default 25)\n"
           "      --cache EPS         radiance caching (§6.3) with cache error EPS (0: off;\n"
           "                          default): the maps computed at records only, by\n"
           "                          splatting, and interpolated within radius EPS R (R: the\n"
           "                          harmonic mean distance of the rays, 2 to 50 pixels)\n"
           "      --cache-min N       records each pixel gathers from, N_c (default 5)\n"
           "      --cache-weight KIND report (eq. 6.7; default) or ward (Ward 1988)\n"
           "      --cache-spacing KIND gradient (R shrunk where the splats' irradiance\n"
           "                          gradient is steep, eq. 6.12; default) or geometric\n"
           "      --gather N          final gathering (§6.4): N rays per camera sample by BSDF\n"
           "                          sampling; photon rays splat to where they land (rows\n"
           "                          in bands of at most 2^20 eye samples), light sampled\n"
           "                          at the camera's point (default 0: off)\n"
           "      --visibility-mask on|off  eye samples hidden from a photon ray by other eye\n"
           "                          samples in its frustum get none of its light (§8.1;\n"
           "                          default off; not with --cache)\n"
           "      --traversal KIND    how a photon ray finds its eye samples: sphere (each\n"
           "                          node's bounding sphere against the frustum; default) or\n"
           "                          slabs (the report's Algorithm 1: the same samples, about\n"
           "                          twice as many tested)\n"
           "      --cap KIND          eye samples beyond a photon ray's hit: plane (fed if the\n"
           "                          ray reached their tangent plane, out to 4 h: consistent;\n"
           "                          default) or hemisphere (the report's Algorithm 2: biased\n"
           "                          low at oblique incidence, whatever h)\n"
           "\n");
}
