#include "core/common_params.h"

#include <string.h>

#define AT(f) CDL_PARAM_AT(cdl_common_params, f)

static const char *nonneg_intensity(const double *v, int n)
{
    return n == 6 && (v[3] < 0.0 || v[4] < 0.0 || v[5] < 0.0) ? "intensity must not be negative" : NULL;
}

/* NAME=VALUE with a Mitsuba parameter name (letters, digits, _) */
static const char *define_text(const char *v)
{
    const char *eq = strchr(v, '=');
    if (!eq || eq == v)
        return "expected NAME=VALUE";
    for (const char *p = v; p < eq; p++)
        if (!(*p == '_' || (*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z')))
            return "a parameter name has letters, digits and _ only";
    return NULL;
}

static const cdl_param rows[] = {
    {"integrator", CDL_PARAM_NAME, "NAME", "path", "light transport method (path, bdpt, ir, rigi, pm, gkde, splat, vcm)",
     .count = sizeof(((cdl_common_params *)0)->integrator), .at = offsetof(cdl_common_params, integrator)},
    {"spp", CDL_PARAM_INT, "N", "64", "samples per pixel, one per pass (a pbrt scene's sampler may set it)", 1, 1e6,
     AT(spp)},
    {"time", CDL_PARAM_FLOAT, "SEC", "", "render whole passes until SEC seconds are spent (instead of spp)", 1e-3, 1e7,
     .unit = "s", AT(time)},
    {"res", CDL_PARAM_RES, "WxH", "512x512", "image size (a pbrt scene's film may set it)", 1, 16384, .count = 2,
     AT(res)},
    {"lookat", CDL_PARAM_FLOATS, "ex,ey,ez,tx,ty,tz,ux,uy,uz", "",
     "camera position, target and up vector (default: the scene file's camera, else one that frames the scene's "
     "bounds)",
     -1e20, 1e20, .count = 9, AT(lookat)},
    {"fov", CDL_PARAM_FLOAT, "DEG", "40",
     "vertical field of view; without lookat the camera frames the scene's bounds", 1e-3, 179.999, .unit = "deg",
     AT(fov)},
    {"maxdepth", CDL_PARAM_INT, "N", "64", "maximum bounces (1 = direct light only)", 0, 1024, AT(maxdepth)},
    {"seed", CDL_PARAM_INT, "N", "1", "random seed; same seed, same image", 0, 2147483647.0, AT(seed)},
    {"sampler", CDL_PARAM_CHOICE, "NAME", "sobol", "sobol (Owen-scrambled) or independent",
     .choices = "sobol|independent", AT(sampler)},
    {"pixel_filter", CDL_PARAM_CHOICE, "NAME", "file",
     "pixel filter: the scene file's (Mitsuba's rfilter, pbrt's PixelFilter; else the one-pixel box) or box",
     .choices = "file|box", AT(filter)},
    {"threads", CDL_PARAM_INT, "N", "", "worker threads (default: all cores)", 1, 1024, AT(threads)},
    {"point_light", CDL_PARAM_FLOATS, "x,y,z,r,g,b", "",
     "add a point light of intensity (r,g,b) W/sr; repeatable", -1e20, 1e20, .check = nonneg_intensity,
     .flags = CDL_PARAM_REPEAT, .count = 6, .repeat = CDL_MAX_POINT_LIGHTS,
     .at = offsetof(cdl_common_params, lights), .store = CDL_STORE_FLOAT,
     .count_at = offsetof(cdl_common_params, nlights)},
    {"define", CDL_PARAM_NAME, "NAME=VALUE", "",
     "set a Mitsuba scene's parameter (its <default name>, $NAME in the file), as mitsuba -D; repeatable",
     .check_text = define_text, .flags = CDL_PARAM_REPEAT, .count = CDL_DEFINE_LEN, .repeat = CDL_MAX_DEFINES,
     .at = offsetof(cdl_common_params, defines), .count_at = offsetof(cdl_common_params, ndefines)},
    {"exposure", CDL_PARAM_FLOAT, "EV", "0", "PNG exposure in stops", -100, 100, AT(exposure)},
    {"quiet", CDL_PARAM_BOOL, "", "off", "no warnings (and, in the command, no progress bar)",
     .flags = CDL_PARAM_FLAG, AT(quiet)},
};

const cdl_param_table cdl_common_table = CDL_PARAM_TABLE("General", rows);

void cdl_common_default(cdl_common_params *c)
{
    memset(c, 0, sizeof *c);
    cdl_param_defaults(&cdl_common_table, c);
}
