/* A block's samplers started together: the pixels of a 4x4 block in one
 * pass (path's camera packets). Their first numbers (the camera's 2D
 * request and the first vertex's cdl_vertex_numbers) are drawn in vector
 * lanes, bit for bit the numbers the one-at-a-time calls give. */
#ifndef CDL_SAMPLER_BLOCK_H
#define CDL_SAMPLER_BLOCK_H

#include "core/sampler.h"

enum { CDL_SAMPLER_BLOCK = 16, CDL_AHEAD_MAX = 4 };

/* Vertex numbers drawn ahead for a block, lane by lane (the vectors'
 * layout): [j][i] is lane i's at dimension 1 + 4 j, i.e. at the (j + 1)-th
 * vertex of a path whose vertices all drew theirs. */
typedef struct cdl_numbers_ahead {
    float u0[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK], u2[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK],
        u3[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK], u5[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK],
        u6[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK];
    uint32_t x0[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK], s2[CDL_AHEAD_MAX][CDL_SAMPLER_BLOCK];
    int nv; /* vertices drawn ahead (0: none) */
} cdl_numbers_ahead;

/* Starts smp[i] on stream[i] (i < n <= 16) in pass index as
 * cdl_sampler_start does and draws its first 2D request into (jx[i],
 * jy[i]): smp[i] is then at dimension 1. With a Sobol sampler, the
 * numbers of the first nv <= CDL_AHEAD_MAX vertices are drawn ahead too
 * (cdl_numbers_ahead_take hands them out); the independent sampler's
 * depend on the order they are drawn in: none (ahead->nv = 0). */
void cdl_sampler_block_start(cdl_sampler *smp, int n, cdl_sampler_kind kind, uint64_t seed, const uint64_t *stream,
                             uint32_t index, float *jx, float *jy, cdl_numbers_ahead *ahead, int nv);

/* If lane's numbers at s's dimension were drawn ahead: *v =
 * cdl_vertex_numbers_draw(s), bit for bit, without the hashes; returns
 * 0 otherwise. A Sobol number depends on its dimension alone, so any
 * history that leaves s at dimension 1 + 4 j may take vertex j's. */
static inline int cdl_numbers_ahead_take(const cdl_numbers_ahead *a, int lane, cdl_sampler *s,
                                         cdl_vertex_numbers *v)
{
    uint32_t j = (s->dim - 1) / 4;
    if ((s->dim - 1) % 4 != 0 || j >= (uint32_t)a->nv)
        return 0;
    v->sobol = 1;
    v->key = s->key;
    v->rindex = s->rindex;
    v->dim = s->dim;
    v->x0 = a->x0[j][lane];
    v->s2 = a->s2[j][lane];
    v->u[0] = a->u0[j][lane];
    v->u[1] = v->u[4] = 0.0f; /* never read: cdl_vertex_number_late */
    v->u[2] = a->u2[j][lane];
    v->u[3] = a->u3[j][lane];
    v->u[5] = a->u5[j][lane];
    v->u[6] = a->u6[j][lane];
    s->dim += 4;
    return 1;
}

#endif
