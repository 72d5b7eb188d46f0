#ifndef CDL_SPLAT_OCCLUSION_H
#define CDL_SPLAT_OCCLUSION_H

#include "integrators/splat/state.h"

/* The occlusion test (occlusion.c): each pass's eye samples get
 * their clearance (prepare, after the tree is built); seen: whether sample
 * q (tree order) sees the point of ray r it stands for (iz: one over its
 * distance along the ray; a shadow ray counted in *rays when needed);
 * filter: the lanes of a batch that do. */
void splat_occl_free(splat_state *s);
size_t splat_occl_bytes(const splat_state *s);
int splat_occl_prepare(splat_state *s, cdl_error *err);
int splat_occl_seen(const splat_state *s, const cdl_photon_ray *r, uint32_t q, float iz, uint64_t *rays);
uint32_t splat_occl_filter(const splat_state *s, const cdl_photon_ray *r, uint32_t first, uint32_t mask,
                           const float *iz, uint64_t *rays);

#endif
