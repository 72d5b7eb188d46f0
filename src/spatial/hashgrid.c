#include "spatial/hashgrid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void cdl_hashgrid_init(cdl_hashgrid *g) { memset(g, 0, sizeof *g); }

void cdl_hashgrid_free(cdl_hashgrid *g)
{
    free(g->start);
    free(g->order);
    cdl_hashgrid_init(g);
}

/* Cell coordinate along one axis, clamped so that far points cannot
 * overflow (they share the border cells, which costs only speed). */
static int32_t coord(const cdl_hashgrid *g, float x, int a)
{
    float c = floorf((x - g->bmin[a]) * g->inv_cell);
    c = c < -1073741824.0f ? -1073741824.0f : c > 1073741824.0f ? 1073741824.0f : c;
    return (int32_t)c;
}

/* Teschner et al. 2003's spatial hash (SmallVCM's too) */
static uint32_t bucket(const cdl_hashgrid *g, int32_t x, int32_t y, int32_t z)
{
    return (((uint32_t)x * 73856093u) ^ ((uint32_t)y * 19349663u) ^ ((uint32_t)z * 83492791u)) & g->mask;
}

static const float *point(const cdl_hashgrid *g, uint32_t i) { return g->pts + (size_t)i * g->stride; }

int cdl_hashgrid_build(cdl_hashgrid *g, const float *pts, uint32_t stride, uint32_t n, float radius,
                       cdl_error *err)
{
    g->pts = pts;
    g->stride = stride < 3 ? 3 : stride;
    g->n = n;
    g->identity = 0;
    if (!(radius > 0.0f) || !isfinite(radius))
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "hash grid: radius %g", (double)radius);
    g->cell = 2.0f * radius;
    g->inv_cell = 1.0f / g->cell;
    uint32_t nb = 1;
    while (nb < n && nb < (1u << 30))
        nb <<= 1;
    g->mask = nb - 1;
    if (n > g->cap_n) {
        free(g->order);
        g->order = malloc(sizeof(uint32_t) * n);
        g->cap_n = g->order ? n : 0;
    }
    if (nb > g->cap_b) {
        free(g->start);
        g->start = malloc(sizeof(uint32_t) * ((size_t)nb + 1));
        g->cap_b = g->start ? nb : 0;
    }
    if ((n && !g->order) || !g->start)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a hash grid of %u points", n);
    for (int a = 0; a < 3; a++)
        g->bmin[a] = n ? INFINITY : 0.0f;
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            float x = point(g, i)[a];
            if (!isfinite(x))
                return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "hash grid: point %u is not finite", i);
            g->bmin[a] = x < g->bmin[a] ? x : g->bmin[a];
        }
    /* counting sort by bucket; order[] first holds each point's bucket */
    memset(g->start, 0, sizeof(uint32_t) * ((size_t)nb + 1));
    for (uint32_t i = 0; i < n; i++) {
        const float *p = point(g, i);
        uint32_t b = bucket(g, coord(g, p[0], 0), coord(g, p[1], 1), coord(g, p[2], 2));
        g->order[i] = b;
        g->start[b + 1]++;
    }
    for (uint32_t b = 0; b < nb; b++)
        g->start[b + 1] += g->start[b];
    /* place each point at its bucket's next free slot, walking the points
     * backwards and filling buckets from their ends: stable, in place */
    uint32_t *fill = malloc(sizeof(uint32_t) * ((size_t)nb + 1));
    if (!fill)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a hash grid of %u points", n);
    memcpy(fill, g->start + 1, sizeof(uint32_t) * nb);
    uint32_t *bk = malloc(sizeof(uint32_t) * (n ? n : 1));
    if (!bk) {
        free(fill);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a hash grid of %u points", n);
    }
    memcpy(bk, g->order, sizeof(uint32_t) * n);
    for (uint32_t i = n; i-- > 0;)
        g->order[--fill[bk[i]]] = i;
    free(bk);
    free(fill);
    return 0;
}

void cdl_hashgrid_make_identity(cdl_hashgrid *g, const float *pts)
{
    for (uint32_t i = 0; i < g->n; i++)
        g->order[i] = i;
    g->pts = pts;
    g->identity = 1;
}

uint32_t cdl_hashgrid_ball(const cdl_hashgrid *g, cdl_vec3 q, float r2, cdl_kd_visit fn, void *ctx)
{
    if (!g->n)
        return 0;
    float r = sqrtf(r2), qa[3] = {q.x, q.y, q.z};
    int32_t lo[3], hi[3];
    uint64_t cells = 1;
    for (int a = 0; a < 3; a++) {
        lo[a] = coord(g, qa[a] - r, a);
        hi[a] = coord(g, qa[a] + r, a);
        cells *= (uint64_t)(hi[a] - lo[a] + 1);
    }
    enum { MAXB = 64 };
    uint32_t bs[MAXB], nb = 0, count = 0;
    if (cells > MAXB) { /* a query far wider than the cells: every point */
        for (uint32_t i = 0; i < g->n; i++) {
            const float *p = point(g, i);
            float dx = p[0] - q.x, dy = p[1] - q.y, dz = p[2] - q.z, d2 = dx * dx + dy * dy + dz * dz;
            if (d2 <= r2) {
                fn(ctx, i, d2);
                count++;
            }
        }
        return count;
    }
    /* distinct buckets only: two cells may share one */
    for (int32_t z = lo[2]; z <= hi[2]; z++)
        for (int32_t y = lo[1]; y <= hi[1]; y++)
            for (int32_t x = lo[0]; x <= hi[0]; x++) {
                uint32_t b = bucket(g, x, y, z), k = 0;
                while (k < nb && bs[k] != b)
                    k++;
                if (k == nb)
                    bs[nb++] = b;
            }
    for (uint32_t k = 0; k < nb; k++)
        for (uint32_t j = g->start[bs[k]]; j < g->start[bs[k] + 1]; j++) {
            uint32_t i = g->identity ? j : g->order[j];
            const float *p = point(g, i);
            float dx = p[0] - q.x, dy = p[1] - q.y, dz = p[2] - q.z, d2 = dx * dx + dy * dy + dz * dz;
            if (d2 <= r2) {
                fn(ctx, i, d2);
                count++;
            }
        }
    return count;
}
