#ifndef CDL_SPLAT_MASK_H
#define CDL_SPLAT_MASK_H

#include "integrators/splat/state.h"

/* The visibility mask (§8.1, mask.c): a batch of rays at a time, build
 * traverses each ray once (flags: the splat traversal's), masks and
 * filters its feasible splats and keeps the survivors (0 or
 * CDL_ERR_SYSTEM); replay hands part `part` its kept splats ray by ray in
 * order, as batches of 16 lanes like a traversal's (cdl_skd_visit), the
 * ray's index first. */
#define SPLAT_MASK_BATCH 8192u
/* Rays a batch takes: SPLAT_MASK_BATCH, half of it where the kept splats
 * hold 1 / z too (about the same memory: 70 MiB on the Cornell box). */
uint32_t splat_mask_batch(const splat_state *s);
typedef struct splat_mask splat_mask;
int splat_mask_alloc(splat_state *s, cdl_error *err);
void splat_mask_free(splat_state *s);
size_t splat_mask_bytes(const splat_state *s);
int splat_mask_prepare(splat_state *s);
int splat_mask_build(splat_state *s, uint32_t first, uint32_t n, int flags);
typedef void (*splat_mask_fn)(void *ctx, uint32_t ray, uint32_t first, uint32_t mask, const float *w, const float *iz);
void splat_mask_replay(const splat_state *s, uint32_t part, splat_mask_fn fn, void *ctx);

#endif
