#ifndef CDL_SPLAT_MASK_H
#define CDL_SPLAT_MASK_H

#include "integrators/splat/state.h"

/* The visibility mask (§8.1, mask.c): the rays' occlusion buffers
 * built a batch at a time; filter drops from a batch's mask the samples
 * ray `ray`'s buffer hides (iz: one over their distance along it). */
#define SPLAT_MASK_BATCH 8192u
typedef struct splat_mask splat_mask;
int splat_mask_alloc(splat_state *s, cdl_error *err);
void splat_mask_free(splat_state *s);
size_t splat_mask_bytes(const splat_state *s);
int splat_mask_prepare(splat_state *s);
int splat_mask_build(splat_state *s, uint32_t first, uint32_t n);
uint32_t splat_mask_filter(const splat_state *s, uint32_t ray, uint32_t first, uint32_t mask, const float *iz);

#endif
