#ifndef CDL_SPLAT_MASK_H
#define CDL_SPLAT_MASK_H

#include "integrators/splat/mask_ray.h"

/* The visibility mask (§8.1, mask.c): prepare finds the pass's occluders
 * (after the rays are traced); begin readies the threads' buffers; then
 * batches of SPLAT_MASK_BATCH rays in turn (aligned to it), two alive at
 * once: build rasterizes the occluders in the frustum of rays [lo, hi)
 * into buffers of the calling thread, and the splats of ray k go through
 * splat_mask_filter with the mask_ray splat_mask_ray sets up (it returns
 * 0 for a ray without a buffer: nothing hides its splats). Once a batch's
 * splats are done each thread recycles its buffers of that batch (any ray
 * k of it), so that the batch after next may take them; end tells out of
 * memory (CDL_ERR_SYSTEM) and adds the statistics. */
#define SPLAT_MASK_BATCH 1024u
typedef struct splat_mask splat_mask;
int splat_mask_alloc(splat_state *s, cdl_error *err);
void splat_mask_free(splat_state *s);
size_t splat_mask_bytes(const splat_state *s);
int splat_mask_prepare(splat_state *s);
int splat_mask_begin(splat_state *s);
void splat_mask_build(splat_state *s, uint32_t lo, uint32_t hi);
void splat_mask_recycle(splat_state *s, uint32_t k);
int splat_mask_end(splat_state *s);
int splat_mask_ray(const splat_state *s, uint32_t k, mask_ray *x);
/* Whether ray k has a buffer. */
int splat_mask_has(const splat_state *s, uint32_t k);
/* The eye samples that may hide others this pass. */
uint32_t splat_mask_occluders(const splat_state *s);

#endif
