#ifndef CDL_SPLAT_CACHE_H
#define CDL_SPLAT_CACHE_H

#include "integrators/splat/state.h"

/* Radiance caching (§6.3, cache.c): the maps computed at a sparse
 * set of eye samples (cache records) by splatting, then interpolated to
 * every sample. Replaces splat_maps_splat; times T_solve and T_cache. */
int splat_cache_solve(splat_state *s, cdl_error *err);
void splat_cache_free(splat_state *s);
void splat_cache_report(const splat_state *s, cdl_stats *out);
/* aov records for sample q: 1 at a record, records gathered, |grad E|; 0 without a cache. */
int splat_cache_aov(const splat_state *s, uint32_t q, float out[3]);

#endif
