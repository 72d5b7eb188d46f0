/* A block's samplers started together: the pixels of a 4x4 block in one
 * pass (path's camera packets). Their first numbers (the camera's 2D
 * request and the first vertex's cdl_vertex_numbers) are drawn in vector
 * lanes, bit for bit the numbers the one-at-a-time calls give. */
#ifndef CDL_SAMPLER_BLOCK_H
#define CDL_SAMPLER_BLOCK_H

#include <stddef.h>

#include "core/sampler.h"

enum { CDL_SAMPLER_BLOCK = 16 };

/* Starts smp[i] on stream[i] (i < n <= 16) in pass index as
 * cdl_sampler_start does and draws its first 2D request into (jx[i],
 * jy[i]): smp[i] is then at dimension 1. With a Sobol sampler (returns
 * 1) vn[i * nv + j] is also what cdl_vertex_numbers_draw would return at
 * dimension 1 + 4 j, i.e. at the (j + 1)-th vertex of a path whose
 * vertices all drew theirs (cdl_vertex_numbers_at); the sampler does not
 * advance for them (cdl_vertex_numbers_taken does). The independent
 * sampler's numbers depend on the order they are drawn in: it returns 0
 * and leaves vn alone. */
int cdl_sampler_block_start(cdl_sampler *smp, int n, cdl_sampler_kind kind, uint64_t seed, const uint64_t *stream,
                            uint32_t index, float *jx, float *jy, cdl_vertex_numbers *vn, int nv);

/* Of a sampler's nv numbers from cdl_sampler_block_start (vn: its row),
 * those its next cdl_vertex_numbers_draw would return, or NULL. */
static inline const cdl_vertex_numbers *cdl_vertex_numbers_at(const cdl_sampler *s, const cdl_vertex_numbers *vn,
                                                              int nv)
{
    uint32_t j = (s->dim - 1) / 4;
    return vn && (s->dim - 1) % 4 == 0 && j < (uint32_t)nv ? &vn[j] : NULL;
}

/* Advances s past the numbers of a cdl_vertex_numbers from
 * cdl_sampler_block_start. */
static inline void cdl_vertex_numbers_taken(cdl_sampler *s) { s->dim += 4; }

#endif
