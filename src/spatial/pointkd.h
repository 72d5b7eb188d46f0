/* A balanced kd-tree over points (photons, importons, light vertices):
 * k nearest neighbours within a maximum radius, and ball queries. Built
 * in place over an index array by median splits on the widest axis: the
 * node of a segment [lo, hi) is its middle element, its children the two
 * halves, so the tree needs no pointers (one index and one axis byte per
 * point). */
#ifndef CDL_POINTKD_H
#define CDL_POINTKD_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_kdtree {
    uint32_t n;
    uint32_t *idx;     /* point index of each tree position */
    uint8_t *axis;     /* split axis of each tree position */
    const float *pts;  /* point i at pts[i * stride .. + 2] (not owned) */
    uint32_t stride;   /* floats between consecutive points */
    int identity;      /* idx[i] == i: points are stored in tree order */
} cdl_kdtree;

/* Builds over n points; pts must outlive the tree. Non-finite points are
 * an error (they would break the ordering). */
int cdl_kd_build(cdl_kdtree *t, const float *pts, uint32_t stride, uint32_t n, cdl_error *err);
void cdl_kd_free(cdl_kdtree *t);

/* The k nearest points with squared distance <= max_d2: their indices in
 * out[] and squared distances in d2[], nearest first. Returns the count. */
uint32_t cdl_kd_knn(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, uint32_t *out,
                    float *d2);

/* The same points unsorted, as a max-heap: d2[0] is the largest (what a
 * density estimate needs, without the cost of sorting). */
uint32_t cdl_kd_knn_heap(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, uint32_t *out,
                         float *d2);

/* For a caller whose queries are coherent (neighbouring pixels) and who
 * weights points by a kernel of the k-th distance: a ball query of the
 * radius^2 *guess, and the k-th smallest distance found by a histogram,
 * which is cheaper than keeping a heap or selecting when k is large. The
 * points come back unsorted, and may be more than k: all those the ball
 * held, which include every point nearer than the k-th. *kth is the k-th
 * smallest squared distance, or -1 when fewer than k points lie within
 * max_d2 (then those are all returned). Falls back to the heap (exactly
 * k points) when the ball holds too few or more than cap points after a
 * few tries. out and d2 hold cap >= k entries. *guess becomes the next
 * query's (the k-th distance, widened a little); 0 to start. */
uint32_t cdl_kd_knn_guess(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, float *guess, uint32_t cap,
                          uint32_t *out, float *d2, float *kth);

/* For a caller that has moved point idx[i] to position i (tree order):
 * the indirection becomes the identity, and traversal cache-friendly. */
void cdl_kd_make_identity(cdl_kdtree *t);

/* Calls fn for every point with squared distance <= r2; returns the count. */
typedef void (*cdl_kd_visit)(void *ctx, uint32_t point, float d2);
uint32_t cdl_kd_ball(const cdl_kdtree *t, cdl_vec3 q, float r2, cdl_kd_visit fn, void *ctx);

/* A ball query that reports whole subtrees inside the ball at once: for
 * a tree in tree order (cdl_kd_make_identity), over the positions [lo, hi)
 * of a subtree (a range of the form [0, n) and, recursively, [lo, mid) and
 * [mid + 1, hi) around mid = lo + (hi - lo) / 2, or a single position
 * [mid, mid + 1): disjoint parts threads can own), whose points lie in the box
 * [bmin, bmax]. Every point within sqrt(r2) of q is reported once, either
 * alone through fn or inside a range [a, b) through fr whose points all
 * lie in the ball (a subtree whose bounding cell does). Big balls cost
 * a few cell tests instead of a test per point. Returns the count. */
typedef void (*cdl_kd_visit_range)(void *ctx, uint32_t a, uint32_t b);
uint32_t cdl_kd_ball_cells(const cdl_kdtree *t, uint32_t lo, uint32_t hi, const float bmin[3],
                           const float bmax[3], cdl_vec3 q, float r2, cdl_kd_visit fn, cdl_kd_visit_range fr,
                           void *ctx);

/* Bytes held by the tree (not the points). */
static inline size_t cdl_kd_bytes(const cdl_kdtree *t) { return (size_t)t->n * 5u; }

#endif
