#include "spatial/kdparts.h"

#include <math.h>

#define PART_MIN 256 /* points below which a subtree is not split further */

static void grow_box(cdl_kd_part *g, const float *p)
{
    for (int a = 0; a < 3; a++) {
        g->bmin[a] = p[a] < g->bmin[a] ? p[a] : g->bmin[a];
        g->bmax[a] = p[a] > g->bmax[a] ? p[a] : g->bmax[a];
    }
}

static void add_part(const cdl_kdtree *kd, cdl_kd_part *parts, uint32_t *np, uint32_t lo, uint32_t hi,
                     const uint32_t *extra, uint32_t nextra)
{
    cdl_kd_part *g = &parts[(*np)++];
    g->lo = lo;
    g->hi = hi;
    g->nextra = nextra;
    for (int a = 0; a < 3; a++) {
        g->bmin[a] = INFINITY;
        g->bmax[a] = -INFINITY;
    }
    for (uint32_t q = lo; q < hi; q++)
        grow_box(g, &kd->pts[(size_t)q * kd->stride]);
    for (uint32_t i = 0; i < nextra; i++) {
        g->extra[i] = extra[i];
        grow_box(g, &kd->pts[(size_t)extra[i] * kd->stride]);
    }
}

/* Subtrees of [lo, hi) down to `depth` levels; the node points above
 * them join the first subtree after them (pend: those waiting). */
static void split(const cdl_kdtree *kd, cdl_kd_part *parts, uint32_t *np, uint32_t lo, uint32_t hi, int depth,
                  const uint32_t *pend, uint32_t npend)
{
    if (lo >= hi)
        return;
    if (hi - lo <= PART_MIN || depth == 0) {
        add_part(kd, parts, np, lo, hi, pend, npend);
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    split(kd, parts, np, lo, mid, depth - 1, pend, npend);
    split(kd, parts, np, mid + 1, hi, depth - 1, &mid, 1);
}

uint32_t cdl_kd_parts(const cdl_kdtree *kd, uint32_t n, int depth, cdl_kd_part *parts)
{
    uint32_t np = 0;
    split(kd, parts, &np, 0, n, depth < CDL_KD_PART_MAX_DEPTH ? depth : CDL_KD_PART_MAX_DEPTH, NULL, 0);
    return np;
}

void cdl_kd_part_ball(const cdl_kdtree *kd, const cdl_kd_part *g, cdl_vec3 c, float r2, cdl_kd_visit fn,
                      cdl_kd_visit_range fr, void *ctx)
{
    cdl_kd_ball_cells(kd, g->lo, g->hi, g->bmin, g->bmax, c, r2, fn, fr, ctx);
    for (uint32_t i = 0; i < g->nextra; i++) {
        const float *p = &kd->pts[(size_t)g->extra[i] * kd->stride];
        float dx = p[0] - c.x, dy = p[1] - c.y, dz = p[2] - c.z, d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= r2)
            fn(ctx, g->extra[i], d2);
    }
}

int cdl_kd_part_meets(const cdl_kd_part *g, cdl_vec3 c, float r)
{
    float p[3] = {c.x, c.y, c.z}, d2 = 0.0f;
    for (int a = 0; a < 3; a++) {
        float d = p[a] < g->bmin[a] ? g->bmin[a] - p[a] : p[a] > g->bmax[a] ? p[a] - g->bmax[a] : 0.0f;
        d2 += d * d;
    }
    return d2 <= r * r;
}
