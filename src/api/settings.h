/* The settings object of the public API: every option of `candela render`
 * parsed and checked, plus what was given explicitly (the scene file
 * decides the rest). */
#ifndef CDL_SETTINGS_H
#define CDL_SETTINGS_H

#include "core/log.h"
#include "integrators/integrator.h"

#define CDL_MAX_POINT_LIGHTS 64

/* The option table's entry called name ("photons", "C"; no dashes), or NULL. */
const cdl_option_info *cdl_option_find(const char *name);

struct cdl_settings {
    char integrator[32];
    long spp;
    double time;
    int width, height;
    int has_lookat;
    float lookat[9];
    double fov;
    long maxdepth, threads;
    unsigned long long seed;
    float lights[CDL_MAX_POINT_LIGHTS][6];
    int nlights;
    double exposure;
    cdl_sampler_kind sampler;
    cdl_mis_kind mis;
    long light_paths, interleave;
    double threshold, clamp;
    int strata_distance, single_shadow_rays;
    int progressive; /* pm, gkde, splat: bandwidths shrink with the pass index */
    double alpha;    /* their schedule's alpha (Knaus & Zwicker 2011) */
    int aov_pathlength, aov_strata, aov_bandwidth, aov_records;
    cdl_pm_options pm;
    cdl_gkde_options gkde;
    cdl_splat_options splat;
    int photons_given, direct_given, gather_given; /* shared with pm: splat takes them only if given */
    /* given explicitly (else the scene file or the default decides) */
    int has_integrator, has_res, has_fov, has_maxdepth;
    cdl_log_sink sink; /* warnings of loads and renders with these settings */
};

#endif
