/* The public settings object: options by name, each checked when set
 * (the command line's parser: `candela render` passes its arguments here). */
#include "api/settings.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/method_settings.h"
#include "api/parse.h"

static void defaults(cdl_settings *a)
{
    memset(a, 0, sizeof *a);
    cdl_options o;
    cdl_options_default(&o);
    a->pm = o.pm;
    a->gkde = o.gkde;
    a->splat = o.splat;
    snprintf(a->integrator, sizeof a->integrator, "path");
    a->width = 512;
    a->height = 512;
    a->fov = 40.0;
    a->maxdepth = 64;
    a->seed = 1;
    a->mis = CDL_MIS_POWER;
    a->interleave = 1;
    a->progressive = 1;
    a->alpha = 2.0 / 3.0;
}

cdl_settings *cdl_settings_create(void)
{
    cdl_settings *s = malloc(sizeof *s);
    if (s)
        defaults(s);
    return s;
}

void cdl_settings_release(cdl_settings *s)
{
    free(s);
}

void cdl_settings_set_message_fn(cdl_settings *s, cdl_message_fn fn, void *user)
{
    s->sink.fn = fn;
    s->sink.user = user;
}

/* "on"/"1"/"true"/NULL -> 1, "off"/"0"/"false" -> 0, else -1. */
static int flag_value(const char *v)
{
    if (!v || !strcmp(v, "on") || !strcmp(v, "1") || !strcmp(v, "true") || !strcmp(v, "True") || !v[0])
        return 1;
    if (!strcmp(v, "off") || !strcmp(v, "0") || !strcmp(v, "false") || !strcmp(v, "False"))
        return 0;
    return -1;
}

/* The command line's spelling of name: "max_radius" -> "--max-radius", "C" -> "-C". */
static int option_name(const char *name, char *o, size_t n, cdl_error *err)
{
    const char *p = name;
    while (*p == '-')
        p++;
    size_t len = strlen(p);
    if (!len || len + 3 > n)
        return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "unknown option (see candela render --help)");
    if (len == 1 && (*p == 'C' || *p == 'S' || *p == 'R')) {
        snprintf(o, n, "-%c", *p);
        return 0;
    }
    if (len == 1 && *p == 'i') {
        snprintf(o, n, "--integrator");
        return 0;
    }
    if (len == 1 && *p == 'q') {
        snprintf(o, n, "--quiet");
        return 0;
    }
    snprintf(o, n, "--%s", p);
    for (char *q = o + 2; *q; q++) {
        if (*q == '_')
            *q = '-';
        if (!(islower((unsigned char)*q) || isdigit((unsigned char)*q) || *q == '-'))
            return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "unknown option (see candela render --help)");
    }
    return 0;
}

static int set(cdl_settings *a, const char *o, const char *v, cdl_error *err)
{
    if (!strcmp(o, "--quiet")) {
        int f = flag_value(v);
        if (f < 0)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
        a->sink.quiet = f;
        return 0;
    }
    if (!strcmp(o, "--progressive")) {
        int f = flag_value(v);
        if (f < 0)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
        a->progressive = f;
        return 0;
    }
    int pk = cdl_pm_arg_kind(o);
    if (pk == 2) {
        int f = flag_value(v);
        if (f < 0)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected on or off, got '%s'", v);
        if (f)
            return cdl_pm_arg(o, NULL, &a->pm, err);
        if (!strcmp(o, "--importance"))
            a->pm.importance = 0;
        else
            a->pm.discard = 0;
        return 0;
    }
    if (!cdl_option_find(o + (o[1] == '-' ? 2 : 1))) /* the table --help lists */
        return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "unknown option (see candela render --help)");
    if (!v)
        return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expects a value");
    if (cdl_splat_arg_kind(o))
        return cdl_splat_arg(o, v, &a->splat, err);
    if (!strcmp(o, "--photons"))
        a->photons_given = 1;
    if (!strcmp(o, "--direct"))
        a->direct_given = 1;
    if (!strcmp(o, "--gather"))
        a->gather_given = 1;
    if (cdl_gkde_arg_kind(o))
        return cdl_gkde_arg(o, v, &a->gkde, err);
    if (pk == 1)
        return cdl_pm_arg(o, v, &a->pm, err);
    long l;
    double d;
    int rc = 0;
    if (!strcmp(o, "--integrator")) {
        if (!cdl_integrator_find(v))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "unknown integrator '%s' (see --help)", v);
        snprintf(a->integrator, sizeof a->integrator, "%s", v);
        a->has_integrator = 1;
    } else if (!strcmp(o, "--spp")) {
        rc = cdl_arg_int(o, v, 1, 1000000, &a->spp, err);
    } else if (!strcmp(o, "--time")) {
        rc = cdl_arg_float(o, v, 1e-3, 1e7, &a->time, err);
    } else if (!strcmp(o, "--res")) {
        rc = cdl_arg_res(o, v, 16384, &a->width, &a->height, err);
        a->has_res = 1;
    } else if (!strcmp(o, "--lookat")) {
        rc = cdl_arg_floats(o, v, 9, a->lookat, err);
        a->has_lookat = 1;
    } else if (!strcmp(o, "--fov")) {
        rc = cdl_arg_float(o, v, 1e-3, 179.999, &a->fov, err);
        a->has_fov = 1;
    } else if (!strcmp(o, "--maxdepth")) {
        rc = cdl_arg_int(o, v, 0, 1024, &a->maxdepth, err);
        a->has_maxdepth = 1;
    } else if (!strcmp(o, "--seed")) {
        rc = cdl_arg_int(o, v, 0, 2147483647L, &l, err);
        a->seed = (unsigned long long)l;
    } else if (!strcmp(o, "--threads")) {
        rc = cdl_arg_int(o, v, 1, 1024, &a->threads, err);
    } else if (!strcmp(o, "--point-light")) {
        if (a->nlights == CDL_MAX_POINT_LIGHTS)
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "at most %d point lights", CDL_MAX_POINT_LIGHTS);
        float *pl = a->lights[a->nlights++];
        rc = cdl_arg_floats(o, v, 6, pl, err);
        if (!rc && (pl[3] < 0.0f || pl[4] < 0.0f || pl[5] < 0.0f))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "intensity must not be negative, got '%s'", v);
    } else if (!strcmp(o, "--sampler")) {
        if (!strcmp(v, "sobol"))
            a->sampler = CDL_SAMPLER_SOBOL;
        else if (!strcmp(v, "independent"))
            a->sampler = CDL_SAMPLER_INDEPENDENT;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected sobol or independent, got '%s'", v);
    } else if (!strcmp(o, "--mis")) {
        if (!strcmp(v, "balance"))
            a->mis = CDL_MIS_BALANCE;
        else if (!strcmp(v, "power"))
            a->mis = CDL_MIS_POWER;
        else if (!strcmp(v, "stratified"))
            a->mis = CDL_MIS_STRATIFIED;
        else if (!strcmp(v, "light"))
            a->mis = CDL_MIS_LIGHT_TRACING;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                 "expected balance, power, stratified or light, got '%s'", v);
    } else if (!strcmp(o, "--light-paths")) {
        /* "sample": an independent light path per pixel sample (-1) */
        if (!strcmp(v, "sample"))
            a->light_paths = -1;
        else
            rc = cdl_arg_int(o, v, 1, 100000000L, &a->light_paths, err);
    } else if (!strcmp(o, "--interleave")) {
        rc = cdl_arg_int(o, v, 1, 64, &a->interleave, err);
    } else if (!strcmp(o, "--threshold")) {
        rc = cdl_arg_float(o, v, 1e-12, 1e12, &a->threshold, err);
    } else if (!strcmp(o, "--clamp")) {
        rc = cdl_arg_float(o, v, 1e-12, 1e12, &a->clamp, err);
    } else if (!strcmp(o, "--strata")) {
        if (!strcmp(v, "geometry"))
            a->strata_distance = 0;
        else if (!strcmp(v, "distance"))
            a->strata_distance = 1;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected geometry or distance, got '%s'", v);
    } else if (!strcmp(o, "--aov")) {
        if (!strcmp(v, "pathlength"))
            a->aov_pathlength = 1;
        else if (!strcmp(v, "strata"))
            a->aov_strata = 1;
        else if (!strcmp(v, "bandwidth"))
            a->aov_bandwidth = 1;
        else if (!strcmp(v, "records"))
            a->aov_records = 1;
        else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                 "expected pathlength, strata, bandwidth or records, got '%s'", v);
    } else if (!strcmp(o, "--shadow-rays")) {
        if (!strcmp(v, "bundle"))
            a->single_shadow_rays = 0;
        else if (!strcmp(v, "single"))
            a->single_shadow_rays = 1;
        else if (v[0] >= '0' && v[0] <= '9') { /* pm: rays per shading point */
            rc = cdl_arg_int(o, v, 1, 4096, &l, err);
            a->pm.shadow_rays = (uint32_t)l;
        } else
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0, "expected bundle, single or a ray count, got '%s'", v);
    } else if (!strcmp(o, "--alpha")) {
        rc = cdl_arg_float(o, v, 0.0, 1.0, &d, err);
        if (!rc && !(d > 0.0 && d < 1.0))
            return cdl_error_set(err, CDL_ERR_USAGE, o, 0,
                                 "must be in (0, 1): 1 keeps the bandwidths fixed, 0 lets the noise grow, got '%s'", v);
        a->alpha = d;
    } else if (!strcmp(o, "--exposure")) {
        rc = cdl_arg_float(o, v, -100.0, 100.0, &d, err);
        a->exposure = d;
    }
    return rc;
}

int cdl_settings_set(cdl_settings *s, const char *name, const char *value, cdl_error *err)
{
    char o[64];
    if (!s || !name)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_settings_set: no settings or no name");
    if (option_name(name, o, sizeof o, err))
        return err ? err->code : CDL_ERR_USAGE;
    cdl_settings t = *s; /* a failed set leaves s as it was */
    int rc = set(&t, o, value, err);
    if (!rc)
        *s = t;
    else if (err && !strcmp(err->file, o))
        snprintf(err->file, sizeof err->file, "%s", name); /* named as the caller spelled it */
    return rc;
}

int cdl_settings_check(const cdl_settings *a, cdl_error *err)
{
    if (a->interleave > 1 && a->light_paths <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, "--interleave", 0, "needs --light-paths K (the paths to interleave)");
    if (a->light_paths > 0 && a->light_paths < a->interleave * a->interleave)
        return cdl_error_set(err, CDL_ERR_USAGE, "--light-paths", 0,
                             "%ld paths cannot fill %ld x %ld interleaved sets", a->light_paths,
                             a->interleave, a->interleave);
    if (a->spp && a->time > 0.0)
        return cdl_error_set(err, CDL_ERR_USAGE, "--time", 0, "give either --spp or --time, not both");
    return cdl_pm_args_check(&a->pm, err);
}
