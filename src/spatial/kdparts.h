/* A kd-tree's points split into parts that threads own: the subtrees
 * some levels down, each with the node points above it whose right
 * subtree starts there, and its bounding box. Each point is in exactly
 * one part, and the split does not change which points a ball finds, so
 * results do not depend on the number of parts (gkde's stages 3 to 5). */
#ifndef CDL_KDPARTS_H
#define CDL_KDPARTS_H

#include "spatial/pointkd.h"

#define CDL_KD_PART_MAX_DEPTH 10 /* at most 2^10 parts */

typedef struct cdl_kd_part {
    uint32_t lo, hi; /* the subtree's points in tree order */
    uint32_t extra[CDL_KD_PART_MAX_DEPTH], nextra;
    float bmin[3], bmax[3];
} cdl_kd_part;

/* The parts of the n points of kd (its points in tree order, as
 * cdl_kd_make_identity leaves them) down to depth <= CDL_KD_PART_MAX_DEPTH
 * levels, into parts (room for 2^depth); returns their number. */
uint32_t cdl_kd_parts(const cdl_kdtree *kd, uint32_t n, int depth, cdl_kd_part *parts);

/* The points of part g within distance sqrt(r2) of c, subtree first;
 * whole cells inside the ball come as ranges. */
void cdl_kd_part_ball(const cdl_kdtree *kd, const cdl_kd_part *g, cdl_vec3 c, float r2, cdl_kd_visit fn,
                      cdl_kd_visit_range fr, void *ctx);

/* Whether the sphere (c, r) meets part g's box. */
int cdl_kd_part_meets(const cdl_kd_part *g, cdl_vec3 c, float r);

#endif
