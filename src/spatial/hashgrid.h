/* A hashed uniform grid over points for fixed-radius queries (vcm's
 * merges; SmallVCM's structure): cells twice the query radius, so a ball
 * touches at most 2 x 2 x 2 of them; points sorted by bucket with a
 * counting sort, O(n) to build. Which bucket a cell hashes to is a
 * function of the cell alone, so the order of the points (and of a
 * query's visits) does not depend on the threads. */
#ifndef CDL_HASHGRID_H
#define CDL_HASHGRID_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"
#include "spatial/pointkd.h"

typedef struct cdl_hashgrid {
    float cell, inv_cell;
    float bmin[3];
    uint32_t n, mask;   /* points; buckets - 1 (a power of two minus one) */
    uint32_t *start;    /* buckets + 1 offsets into order */
    uint32_t *order;    /* point indices, bucket after bucket */
    uint32_t cap_n, cap_b;
    int identity;       /* order[i] == i: the caller stored its points in bucket order */
    const float *pts;   /* point i at pts[i * stride .. + 2] (not owned) */
    uint32_t stride;
} cdl_hashgrid;

void cdl_hashgrid_init(cdl_hashgrid *g);
void cdl_hashgrid_free(cdl_hashgrid *g);
/* (Re)builds over n points for queries of radius at most `radius`; keeps
 * the memory of earlier builds. Non-finite points are an error. */
int cdl_hashgrid_build(cdl_hashgrid *g, const float *pts, uint32_t stride, uint32_t n, float radius,
                       cdl_error *err);
/* For a caller that has moved point order[i] to position i (pts must then
 * point at the moved points). */
void cdl_hashgrid_make_identity(cdl_hashgrid *g, const float *pts);
/* Calls fn for every point with squared distance <= r2 from q (each once;
 * r2 may exceed the build radius's square, at the cost of more cells);
 * returns the count. */
uint32_t cdl_hashgrid_ball(const cdl_hashgrid *g, cdl_vec3 q, float r2, cdl_kd_visit fn, void *ctx);
static inline size_t cdl_hashgrid_bytes(const cdl_hashgrid *g)
{
    return ((size_t)g->cap_n + (size_t)g->cap_b + 1) * sizeof(uint32_t);
}

#endif
