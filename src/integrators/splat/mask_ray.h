/* The visibility mask's work on one photon ray (mask_ray.c): the
 * rasterization of its occluders (mask.c) and the filter of its splats
 * (maps.c). */
#ifndef CDL_SPLAT_MASK_RAY_H
#define CDL_SPLAT_MASK_RAY_H

#include "integrators/splat/state.h"

#define MASK_G 32
/* A ray whose occluders lie on at most this many planes keeps a plane per
 * cell instead of a sample (the filter then reads one word a lane). */
#define MASK_PLANES 32

/* A traversal batch of occluders (tests). */
typedef struct mask_held {
    uint32_t first, mask;
    float z[16];
    uint32_t back;   /* the lanes whose plane has the ray's origin behind it */
    uint8_t pid[16]; /* each lane's plane (MASK_PLANES or fewer planes) */
} mask_held;

typedef struct mask_ray {
    const cdl_skd *t;            /* the occluders' tree */
    const cdl_photon_ray *r;
    const float *pw, *const *ax; /* per occluder: footprint, patch semi-axes (mask.c) */
    float U[3], V[3];            /* the kernel plane's axes */
    float eps;                   /* rounding margin of plane offsets (scene units) */
    int g;                       /* the buffer's side in cells */
    int32_t reach;               /* the largest z - pw of a feasible sample, as bits: no sample
                                  * as far along the ray can hide one */
    uint64_t *grid;              /* g x g cells: distance bits << 32 | sample; UINT64_MAX empty */
    uint32_t *grid32;            /* or, with planes, as cz below */
    int plain;                   /* rasterize one cell at a time (tests: the windows' reference) */
    const uint32_t *id;          /* per occluder its index in ft (the keys'), NULL: the same */
    const uint8_t *side;         /* per occluder the sides an origin may hide from (bit 0 in front of its
                                  * plane, bit 1 behind), NULL: both */
    const cdl_skd *ft;           /* the feasible samples' tree, */
    const float *fpw;            /* their footprints */
    const uint32_t *zg, *ig;     /* the filter's grid: the keys' distance bits (INT32_MAX empty), samples */
    /* or, with planes: per cell the distance bits with the plane in the
     * low 5 (INT32_MAX empty), which cells are filled (a bit each), the
     * planes turned to the hiding side (MASK_PLANES each of n x, y, z and
     * offset: a sample p is hidden when p . n - offset exceeds its
     * footprint) */
    const uint32_t *cz, *occ;
    const float *tab;
} mask_ray;

/* One held batch into x->grid; returns the samples it rasterized. */
uint32_t splat_mask_rasterize(const mask_ray *x, const mask_held *hb);
/* The same for occluders [first, first + 16) in lanes with distances z;
 * returns the lanes it rasterized. */
uint32_t splat_mask_rasterize_z(const mask_ray *x, uint32_t first, uint32_t lanes, const float *z);
/* The same into x->grid32, each cell keeping the front one's distance
 * bits with its plane pid[lane] in the low bits (the cz a filter with
 * planes reads; empty cells INT32_MAX), for lanes that may hide something
 * (collect's: not tested again). */
uint32_t splat_mask_rasterize_planes(const mask_ray *x, uint32_t first, uint32_t lanes, const float *z,
                                     const uint8_t *pid);
/* The lanes in mask of feasible samples [first, first + 16) the buffer
 * does not hide. */
uint32_t splat_mask_filter(const mask_ray *x, uint32_t first, uint32_t mask);

#endif
