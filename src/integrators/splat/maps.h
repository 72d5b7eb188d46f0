/* Radiance maps (maps.c): what a splat adds to an eye sample, and each
 * sample's reflected radiance at the end. */
#ifndef CDL_SPLAT_MAPS_H
#define CDL_SPLAT_MAPS_H

#include "integrators/splat/state.h"

/* What one ray adds per unit of kernel weight to a glossy sample's map,
 * computed on first use: RGB per SH coefficient, or the ray's stratum. */
typedef struct splat_terms {
    const cdl_photon_ray *r;
    float sh[CDL_SH_N * 3];
    int stratum, ready;
    cdl_vec3 wi; /* towards the light */
} splat_terms;
void splat_terms_of(splat_terms *t, const splat_state *s, const cdl_photon_ray *r);
/* One splat of the ray in t onto sample q: weight w (kernel times
 * cosine), iz one over its distance along the ray. */
void splat_maps_add(splat_state *s, splat_terms *t, uint32_t q, float w, float iz);
/* Zeroes the maps for a pass. */
void splat_maps_clear(splat_state *s);

/* Radiance-map setup of the mode (strata, SH tables); 0 or an error. */
int splat_maps_init(splat_state *s, cdl_error *err);
/* Sizes the maps for this pass's eye samples (after the tree is built). */
int splat_maps_alloc(splat_state *s, cdl_error *err);
size_t splat_maps_bytes(const splat_state *s);
/* Splats every photon ray into the maps, part by part on all threads;
 * 0 or CDL_ERR_SYSTEM (no memory for the visibility masks). */
int splat_maps_splat(splat_state *s);
/* Each eye sample's reflected radiance, weighted, into s->pix. */
void splat_maps_resolve(splat_state *s);

#endif
