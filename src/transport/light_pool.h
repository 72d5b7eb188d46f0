/* K light subpaths per pass shared by all pixels (instant radiosity's
 * point lights, bdpt with reused light paths), split into N x N
 * interleaved sets so that neighbouring pixels use different paths
 * (Keller & Heidrich 2001). Path i belongs to set i mod N^2. */
#ifndef CDL_LIGHT_POOL_H
#define CDL_LIGHT_POOL_H

#include "transport/subpath.h"

typedef struct cdl_light_pool {
    cdl_vertex_store vs; /* path i occupies [i * stride, i * stride + len[i]) */
    uint32_t k, stride, n_interleave, sets;
    uint32_t *len;
} cdl_light_pool;

int cdl_light_pool_init(cdl_light_pool *lp, uint32_t k, uint32_t interleave, int maxdepth,
                        cdl_error *err);
void cdl_light_pool_free(cdl_light_pool *lp);
/* Traces the pass's K paths on all threads; deterministic per (seed, pass). */
void cdl_light_pool_trace(cdl_light_pool *lp, const cdl_scene *s, const cdl_walk *walk,
                          cdl_sampler_kind kind, uint64_t seed, uint32_t pass, uint64_t *rays);

static inline uint32_t cdl_light_pool_set(const cdl_light_pool *lp, int x, int y)
{
    return (uint32_t)(x % (int)lp->n_interleave) + lp->n_interleave * (uint32_t)(y % (int)lp->n_interleave);
}
/* Number of paths in set `set`. */
static inline uint32_t cdl_light_pool_set_size(const cdl_light_pool *lp, uint32_t set)
{
    return lp->k / lp->sets + (set < lp->k % lp->sets ? 1u : 0u);
}

#endif
