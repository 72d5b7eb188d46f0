/* The visibility mask's work on one photon ray (mask_ray.c), private to
 * mask.c: the tests that spare a ray its buffer, the rasterization and
 * the filter. */
#ifndef CDL_SPLAT_MASK_RAY_H
#define CDL_SPLAT_MASK_RAY_H

#include "integrators/splat/state.h"

#define MASK_G 32

/* A traversal batch held until the ray's buffer is known: the frustum's
 * lanes with their z, or the feasible ones with w and 1 / z. */
typedef struct mask_held {
    uint32_t first, mask, hide; /* hide: the lanes that may hide a feasible sample (splat_mask_hiders) */
    float z[16];
} mask_held;
typedef struct mask_feas {
    uint32_t first, mask;
    float w[16], iz[16];
} mask_feas;

typedef struct mask_ray {
    const cdl_skd *t;
    const cdl_photon_ray *r;
    const float *pw, *const *ax; /* per sample: footprint, patch semi-axes (mask.c) */
    float U[3], V[3];            /* the kernel plane's axes */
    float eps;                   /* rounding margin of plane offsets (scene units) */
    int g;                       /* the buffer's side in cells */
    int32_t reach;               /* the largest z - pw of a feasible sample, as bits: no sample
                                  * as far along the ray can hide one */
    uint64_t *grid;              /* g x g cells: distance bits << 32 | sample; UINT64_MAX empty */
    int plain;                   /* rasterize one cell at a time (tests: the windows' reference) */
} mask_ray;

/* Whether the held samples that can hide anything lie on one plane. */
int splat_mask_one_plane(const mask_ray *x, const mask_held *h, uint32_t nh);
/* Sets x->reach from the feasible batches. */
void splat_mask_reach(mask_ray *x, const mask_feas *f, uint32_t nf);
/* Sets each held batch's hide: its lanes that may hide some feasible
 * sample whatever the buffer (needs x->reach); returns whether any may. */
int splat_mask_hiders(const mask_ray *x, mask_held *h, uint32_t nh, const mask_feas *f, uint32_t nf);
/* One held batch into x->grid; returns the samples it rasterized. */
uint32_t splat_mask_rasterize(const mask_ray *x, const mask_held *hb);
/* The same for its lanes in lanes only. */
uint32_t splat_mask_rasterize_lanes(const mask_ray *x, const mask_held *hb, uint32_t lanes);
/* The feasible lanes of fb the buffer does not hide; *front rises to the
 * largest distance bits (unsigned) of the front samples that hide one. */
uint32_t splat_mask_filter(const mask_ray *x, const mask_feas *fb, uint32_t *front);

#endif
