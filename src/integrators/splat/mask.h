#ifndef CDL_SPLAT_MASK_H
#define CDL_SPLAT_MASK_H

#include "integrators/splat/mask_ray.h"

/* The visibility mask (§8.1, mask.c): prepare finds the pass's occluders
 * (after the rays are traced); then a batch of rays at a time, build
 * rasterizes the occluders in each ray's frustum into its buffer (0 or
 * CDL_ERR_SYSTEM), and the splats of ray `ray` of the batch go through
 * splat_mask_filter with the mask_ray splat_mask_ray sets up (it returns 0
 * for a ray without a buffer: nothing hides its splats). */
#define SPLAT_MASK_BATCH 8192u
uint32_t splat_mask_batch(const splat_state *s);
typedef struct splat_mask splat_mask;
int splat_mask_alloc(splat_state *s, cdl_error *err);
void splat_mask_free(splat_state *s);
size_t splat_mask_bytes(const splat_state *s);
int splat_mask_prepare(splat_state *s);
int splat_mask_build(splat_state *s, uint32_t first, uint32_t n);
int splat_mask_ray(const splat_state *s, uint32_t ray, mask_ray *x);
/* Whether ray `ray` of the batch has a buffer. */
int splat_mask_has(const splat_state *s, uint32_t ray);
/* The eye samples that may hide others this pass. */
uint32_t splat_mask_occluders(const splat_state *s);

#endif
