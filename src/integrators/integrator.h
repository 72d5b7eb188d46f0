/* The interface every light-transport method implements (DESIGN.md):
 * prepare once, then progressive passes. A pass is deterministic given
 * (seed, pass index) whatever the number of threads. */
#ifndef CDL_INTEGRATOR_H
#define CDL_INTEGRATOR_H

#include <stdatomic.h>
#include <stdint.h>

#include "core/error.h"
#include "core/params.h"
#include "core/stats.h"
#include "core/sampler.h"
#include "transport/mis.h"
#include "film/film.h"
#include "scene/camera.h"
#include "scene/scene.h"

#define CDL_STRATA 8 /* aov strata: eye path lengths 1..7 and 8 or more */

/* pm: Jensen's photon map with the techniques of Keller & Wald 2000 */
typedef struct cdl_pm_options {
    uint32_t k;             /* photons per radiance estimate */
    float max_radius;       /* of an estimate; <= 0: 5 % of the scene's diagonal */
    int kernel;             /* cdl_kernel */
    uint32_t gather;        /* final gathering rays; 0 = direct visualization */
    uint32_t precompute;    /* irradiance at every n-th photon for gather rays; 0 = off */
    int importance;         /* importance-driven deposition (§2.1) */
    uint64_t importons;     /* importon paths */
    float eps;              /* lower bound of the deposition probability */
    int discard;            /* drop photons below eps instead (biased) */
    float caustic_ratio;    /* q (§2.2) */
    int caustic_random;     /* per-photon test against q instead of the path prefix */
    int direct;             /* cdl_direct_kind, or CDL_PM_DIRECT_PHOTONS as given */
    int direct_photons;     /* direct light from the map's primary photons (needs gather 0) */
    uint32_t shadow_rays;   /* S */
    float lcon_radius;      /* L_con query radius; <= 0: the maximum radius */
    uint64_t max_paths;     /* photon paths per pass before giving up; 0: 1000 per photon */
    int visibility;         /* cdl_pm_visibility: which estimates test photon visibility */
} cdl_pm_options;

/* pm's direct = photons: read from the map (pm.direct_photons), not a light selection */
#define CDL_PM_DIRECT_PHOTONS 16

typedef enum {
    CDL_PM_VIS_GATHER, /* estimates at final-gather hits and the precomputed irradiance */
    CDL_PM_VIS_ALL,    /* also at the camera's point (gather 0, caustics) */
    CDL_PM_VIS_OFF     /* none: Jensen's estimate, which leaks through thin walls */
} cdl_pm_visibility;

/* gkde: generalized kernel density estimation (Bekaert et al. 2003) */
typedef struct cdl_gkde_options {
    uint32_t light_paths; /* N: light paths per step */
    uint32_t eye_paths;  /* eye paths per pixel and step */
    uint32_t links;      /* M: unoccluded links wanted per eye vertex (§5); 0: one per 10000 light paths */
    float bandwidth;     /* h of eq. 7; <= 0: calibrated in the first step */
    float footprint_cap; /* footprint radii at most this times the median first-bounce one; 0: none */
    float overlaps;      /* h_0 is calibrated so that an eye vertex in direct light lies in this many
                          * first-bounce footprints (>= 2) */
    uint32_t max_mib;    /* cap on the stored path vertices (MiB) */
} cdl_gkde_options;

/* splat: photon ray splatting (Herzog et al. 2007) */
typedef enum { CDL_SPLAT_DIRECT, CDL_SPLAT_HISTOGRAM, CDL_SPLAT_SH } cdl_splat_mode;

typedef enum { CDL_SPLAT_DIRECT_PHOTONS, CDL_SPLAT_DIRECT_SAMPLE, CDL_SPLAT_DIRECT_NONE } cdl_splat_direct;

typedef struct cdl_splat_options {
    float fractions[3];  /* direct, indirect, caustic shares of the budget */
    float C, S, R;       /* bandwidth smoothness, sensitivity, clamping (§4.2) */
    int mode;            /* cdl_splat_mode: how the radiance maps hold incident light */
    int direct;          /* cdl_splat_direct, as given; prepare derives the two below */
    int direct_sample;   /* direct light by light sampling instead of direct photons */
    int direct_none;     /* no direct light at the camera's points (indirect light alone) */
    uint32_t eye_samples; /* eye samples per pixel and pass */
    int cull;            /* back-face-culling nodes in the eye-sample tree */
    int slabs;           /* the report's 1D slab traversal (Algorithm 1) instead of bounding spheres */
    float filter;        /* image-space filter (§6.2): photon splats a pixel's box gathers; 0: none */
    float filter_normal; /* segments: normals within this many degrees */
    float filter_depth;  /* segments: second difference of 1/depth within this share of it */
    int filter_max;      /* largest box half-width in pixels */
    float cache;         /* radiance caching (§6.3): the cache error epsilon; 0: none */
    uint32_t cache_min;  /* records every pixel gathers from, N_c */
    int cache_ward;      /* Ward's weight instead of the report's (eq. 6.7), for comparison */
    int cache_geometric; /* record spacing from the harmonic mean distance alone (no irradiance gradient) */
    uint32_t gather;     /* §6.4: final-gather rays per camera sample, each an eye sample; 0: none */
    int visibility_mask; /* §8.1: eye samples hidden from a photon ray by others in its frustum get nothing */
    int occlusion;       /* a splat counts only if a free segment joins the sample to the ray (exact) */
    float cap;           /* beyond a ray's hit: 0 the report's hemisphere, c > 0 the tangent-plane
                          * test out to c h (spatial/splatkd.h) */
} cdl_splat_options;

/* sppm: stochastic progressive photon mapping (Hachisuka & Jensen 2009) */
typedef struct cdl_sppm_options {
    float radius;     /* initial radius of every pixel's disc; <= 0: radius_px pixel footprints */
    float radius_px;  /* that default, in pixel footprints at the pixel's first visible point */
    int visibility;   /* leave out photons no free path joins to the visible point (a shadow ray each) */
} cdl_sppm_options;

/* vcm: vertex connection and merging (Georgiev et al. 2012) */
typedef struct cdl_vcm_options {
    float radius;   /* merge radius of the first pass; <= 0: from the pixel footprint */
    int mode;       /* full, connect (bdpt) or merge (merging alone) */
    int visibility; /* merges test visibility with a shadow ray */
    float merge_paths; /* light paths per pass merged with, in multiples of the pixels (>= 1) */
} cdl_vcm_options;

#define CDL_LIGHT_PATHS_PER_SAMPLE UINT32_MAX

/* extra image layers (cdl_options.aov bits) */
enum { CDL_AOV_PATHLENGTH = 1, CDL_AOV_STRATA = 2, CDL_AOV_BANDWIDTH = 4, CDL_AOV_RECORDS = 8, CDL_AOV_MERGE = 16,
       CDL_AOV_MERGECOUNT = 32 };

typedef struct cdl_options {
    cdl_camera camera;
    int maxdepth;   /* bounces, as in pbrt: 1 = direct light only */
    int rr_depth;   /* Russian roulette starts after this many bounces */
    uint64_t seed;
    cdl_sampler_kind sampler; /* Sobol (default) or independent */

    /* bdpt, ir, rigi (Kollig & Keller 2004) */
    cdl_mis_kind mis;      /* bdpt weighting */
    uint32_t light_paths;  /* K light paths per pass shared by all pixels; 0 = the method's default
                            * (bdpt: one per pixel sample; ir/rigi: 256 in 4 x 4 sets; gkde: 100000
                            * per step); CDL_LIGHT_PATHS_PER_SAMPLE:
                            * an independent one per pixel sample in every method */
    uint32_t interleave;   /* N: N x N interleaved sets of the K paths (1 = one set) */
    float threshold;       /* stratification threshold t on G; <= 0: derived from the scene */
    float clamp;           /* ir: clamp G at this value; <= 0: derived from the scene */
    int strata_distance;   /* rigi: threshold the distance instead of G (Figure 2c) */
    int single_shadow_rays; /* rigi/ir: trace shadow rays one by one instead of as bundles */

    /* pm, gkde, splat: consistent by default, their bandwidths shrinking
     * with the pass index (cdl_progressive_r2); off: the reports' fixed ones */
    int progressive;
    float alpha;
    uint32_t photons; /* pm, splat: photons (splat: photon rays, all budgets) stored per pass */
    uint32_t aov;     /* CDL_AOV_* layers asked for (rigi, splat) */

    cdl_pm_options pm;
    cdl_gkde_options gkde;
    cdl_splat_options splat;
    cdl_sppm_options sppm;
    cdl_vcm_options vcm;
} cdl_options;

/* The threshold t actually used: opt->threshold, or one that limits the
 * "cheaper rays" of rigi to 15 % of the scene's diagonal (r <= sqrt(1/t)). */
float cdl_default_threshold(const cdl_scene *s, const cdl_options *opt);

/* Every method's defaults, from their parameter tables. */
void cdl_options_default(cdl_options *o);

/* Rows shared by several methods (each lists the tables it reads):
 * progressive and alpha (pm, gkde, splat, sppm, vcm), photons (pm, splat, sppm), light
 * paths, interleave and threshold (bdpt, ir, rigi), shadow_mode (ir,
 * rigi, gkde). */
extern const cdl_param_table cdl_density_table, cdl_photon_table, cdl_light_path_table, cdl_shadow_table;

/* light_paths and interleave together (bdpt, ir, rigi) */
int cdl_light_paths_check(const cdl_options *opt, cdl_error *err);

/* Progressive radius reduction (Knaus & Zwicker 2011, eq. 20): the squared
 * bandwidth of pass i (0-based) relative to pass 0's,
 *   r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1)   (1-based i),
 * i.e. prod_{j=1..i} (j + alpha) / (j + 1) = Gamma(i + 1 + alpha) /
 * (Gamma(1 + alpha) Gamma(i + 2)), about i^(alpha - 1) / Gamma(1 + alpha).
 * A function of the pass index alone, so that passes stay independent and
 * can be split over processes. 1 when opt->progressive is off. */
float cdl_progressive_r2(const cdl_options *opt, uint32_t pass);

typedef struct cdl_integrator_vtbl {
    const char *name;
    const char *summary; /* one line for help */
    /* Both return 0 or an error code with err filled in (file, problem). */
    int (*prepare)(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err);
    int (*render_pass)(void *self, cdl_film *film, uint32_t pass, cdl_error *err);
    void (*destroy)(void *self);
    void (*report)(const void *self, cdl_stats *out); /* optional: statistics after rendering */
    /* Optional, for methods whose passes adapt to earlier ones (gkde's
     * visibility tallies): the state gathered since the last fold (size,
     * get), the pass index of the next fold, and the fold with the state
     * summed over every process (cdl_renderer_adapt_*). */
    size_t (*adapt_size)(const void *self);
    uint32_t (*adapt_next)(const void *self);
    void (*adapt_get)(const void *self, double *out);
    void (*adapt_fold)(void *self, const double *sum);
    size_t self_size;
    /* the parameter tables the method reads (beyond the common one), NULL-terminated */
    const cdl_param_table *const *params;
} cdl_integrator_vtbl;

typedef struct cdl_integrator {
    const cdl_integrator_vtbl *vt;
    void *self;
} cdl_integrator;

/* A render's cancel flag (film->cancel, set by cdl_renderer_cancel from
 * any thread or a signal handler): passes stop at the next tile. */
static inline int cdl_cancelled(atomic_int *flag)
{
    return flag && atomic_load_explicit(flag, memory_order_relaxed);
}

const cdl_integrator_vtbl *cdl_integrator_find(const char *name);
/* Names of all integrators, NULL-terminated. */
const cdl_integrator_vtbl *const *cdl_integrator_list(void);
int cdl_integrator_create(const char *name, cdl_integrator *out, cdl_error *err);
void cdl_integrator_destroy(cdl_integrator *it);

/* Runs fn(self, x0, y0, x1, y1, rays) over the image in 16x16 tiles on
 * all threads; sums the ray and non-finite counts into the film. The
 * tile callback returns its non-finite sample count. */
typedef uint64_t (*cdl_tile_fn)(void *self, cdl_film *film, int x0, int y0, int x1, int y1,
                                uint32_t pass, uint64_t *rays);
void cdl_render_tiles(void *self, cdl_film *film, uint32_t pass, cdl_tile_fn fn);

#endif
