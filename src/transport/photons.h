/* Photon tracing for the photon map (Jensen 1996) with the deposition
 * control of Keller & Wald 2000: photons are the vertices of light
 * subpaths from the shared tracer, stored in a caustic map (last bounce
 * specular) or the global map, each with a probability:
 *
 *   caustic photon:   stored with p(x),      flux L / p(x)
 *   other photons:    stored with q p(x),    flux L / (q p(x))      (random)
 *                     or, for the first floor(q N) paths only, with p(x)  (prefix)
 *
 * p(x) = min(1, f I(x)) from the importon map (1 without one); bounded
 * below by eps (unbiased) or, with discard, photons below eps are dropped
 * (biased). Paths are traced until the global map holds `target`
 * photons; then, in prefix mode, paths floor(q N) + 1 .. N fill the
 * caustic map only (§2.3). Deterministic per (seed, pass) on any number
 * of threads: paths are seeded by their index and kept in index order. */
#ifndef CDL_PHOTONS_H
#define CDL_PHOTONS_H

#include "spatial/photon_map.h"
#include "transport/importance.h"
#include "transport/subpath.h"

typedef struct cdl_photon_params {
    uint32_t target;            /* global photons to store */
    float q;                    /* caustic ratio, (0, 1] */
    int caustic_random;         /* per-photon test against q instead of the path prefix */
    const cdl_importance *imp;  /* NULL: p = 1 */
    float eps;                  /* lower bound of p */
    int discard;                /* drop photons with p < eps instead (biased) */
    uint64_t max_paths;         /* give up beyond this many paths */
} cdl_photon_params;

typedef struct cdl_photon_stats {
    uint64_t paths;         /* light paths traced in all */
    uint64_t paths_global;  /* of which filled the global map */
    uint64_t candidates;    /* non-specular surface hits (photons before deposition) */
    uint64_t rays;
} cdl_photon_stats;

/* Fills both maps (cleared first) and builds their kd-trees. */
int cdl_photons_trace(const cdl_scene *s, const cdl_walk *walk, const cdl_photon_params *pp,
                      cdl_sampler_kind kind, uint64_t seed, uint32_t pass, cdl_photon_map *global,
                      cdl_photon_map *caustic, cdl_photon_stats *st, cdl_error *err);

/* The cdl_vis tests of photon estimates (ctx: the cdl_scene): x moved two
 * ray offsets back along wx, then lifted along nx by `lift` or half way
 * to what lies nearer; 0 if a surface blocks the segment from o to p moved
 * two ray offsets back along wp. */
cdl_vec3 cdl_photon_vis_origin(const void *scene, cdl_vec3 x, cdl_vec3 nx, cdl_vec3 wx, float lift);
int cdl_photon_visible(const void *scene, cdl_vec3 o, cdl_vec3 p, cdl_vec3 wp);

/* The path limit when none is given: 1000 per photon, at least 2^20. */
static inline uint64_t cdl_photons_default_max_paths(uint32_t photons)
{
    uint64_t m = (uint64_t)photons * 1000u;
    return m > (1u << 20) ? m : (1u << 20);
}

#endif
