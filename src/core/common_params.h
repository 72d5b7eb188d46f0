/* The parameters every method reads (budget, image, camera, depth, seed,
 * threads, lights given on the command line): one table, one struct. */
#ifndef CDL_COMMON_PARAMS_H
#define CDL_COMMON_PARAMS_H

#include "core/params.h"

#define CDL_MAX_POINT_LIGHTS 64
#define CDL_MAX_DEFINES 32
#define CDL_DEFINE_LEN 256

typedef struct cdl_common_params {
    char integrator[32];
    long spp;   /* 0: the scene file's, else 64 (resolve.c) */
    double time; /* seconds; 0: none */
    int res[2];
    float lookat[9];
    double fov;
    long maxdepth, threads;
    long seed;
    int sampler; /* cdl_sampler_kind */
    int filter;  /* 0: the scene file's pixel filter, 1: the one-pixel box */
    float lights[CDL_MAX_POINT_LIGHTS][6];
    int nlights;
    char defines[CDL_MAX_DEFINES][CDL_DEFINE_LEN]; /* "name=value" for a Mitsuba file's <default>s */
    int ndefines;
    double exposure;
    int quiet;
} cdl_common_params;

extern const cdl_param_table cdl_common_table;

/* the common parameters' defaults */
void cdl_common_default(cdl_common_params *c);

#endif
