/* The eye-sample kd-tree's node encoding and bit helpers, shared by its
 * build (splatkd.c) and its queries (splatkd_query.c); private to them. */
#ifndef CDL_SPATIAL_SPLATKD_NODE_H
#define CDL_SPATIAL_SPLATKD_NODE_H

#include <stdint.h>
#include <string.h>

/* Node encoding (8 bytes): b & 3 < 3: interior, split axis b & 3, a the
 * split coordinate's bits, right child at b >> 2 (the left one follows the
 * node). b & 3 == 3: kind (b >> 2) & 3: leaf (a samples from b >> 4),
 * empty, or culling node (a: octahedral mean normal, 16 bits per
 * coordinate; b >> 16: C_max in 16 bits, rounded up; its child follows). */
enum { KIND_LEAF = 0, KIND_EMPTY = 1, KIND_CULL = 2 };

static inline uint32_t fbits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static inline float bitsf(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

#endif
