#include "film/segments.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static int has_surface(const float *depth, int p) { return depth[p] > 0.0f && isfinite(depth[p]); }

/* Whether q, the neighbour of p in direction (dx, dy), continues p's
 * surface (segment k): on a plane 1/depth is affine in the image, so its
 * second difference across p (with the pixel behind p, if it is in k;
 * else across q with the pixel beyond it) measures the change of slope;
 * without either, the first difference. */
static int continuous(const cdl_segments *sg, const float *depth, const cdl_vec3 *nrm, float cos_max, float tol,
                      int32_t k, int x, int y, int dx, int dy)
{
    int w = sg->w, p = y * w + x, q = (y + dy) * w + (x + dx);
    if (!has_surface(depth, q) || cdl_dot(nrm[p], nrm[q]) < cos_max)
        return 0;
    int bx = x - dx, by = y - dy;
    float ip = 1.0f / depth[p], iq = 1.0f / depth[q];
    if (bx >= 0 && by >= 0 && bx < w && by < sg->h && sg->id[by * w + bx] == k) {
        float ib = 1.0f / depth[by * w + bx];
        return fabsf(iq - 2.0f * ip + ib) <= tol * ip;
    }
    /* p starts the segment here: the pixel beyond q instead (p, q and it
     * on one plane), if it shows a surface like q's */
    int cx = x + 2 * dx, cy = y + 2 * dy;
    if (cx >= 0 && cy >= 0 && cx < w && cy < sg->h && has_surface(depth, cy * w + cx) &&
        cdl_dot(nrm[q], nrm[cy * w + cx]) >= cos_max) {
        float ic = 1.0f / depth[cy * w + cx];
        return fabsf(ic - 2.0f * iq + ip) <= tol * iq;
    }
    return fabsf(iq - ip) <= 4.0f * tol * ip;
}

int cdl_segment(cdl_segments *sg, int w, int h, const float *depth, const cdl_vec3 *normal, float cos_max,
                float depth_tol, cdl_error *err)
{
    memset(sg, 0, sizeof *sg);
    size_t np = (size_t)w * (size_t)h;
    sg->w = w;
    sg->h = h;
    sg->id = malloc(sizeof(int32_t) * (np ? np : 1));
    int *queue = malloc(sizeof(int) * (np ? np : 1));
    uint32_t cap = 64;
    sg->rect = malloc(sizeof(cdl_seg_rect) * cap);
    if (!sg->id || !queue || !sg->rect) {
        free(queue);
        cdl_segments_free(sg);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "segments", 0, "out of memory for %dx%d pixels", w, h);
    }
    for (size_t p = 0; p < np; p++)
        sg->id[p] = -1;
    static const int dirs[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
    for (int seed = 0; seed < (int)np; seed++) {
        if (sg->id[seed] >= 0 || !has_surface(depth, seed))
            continue;
        if (sg->n == cap) {
            cap *= 2;
            cdl_seg_rect *r = realloc(sg->rect, sizeof *r * cap);
            if (!r) {
                free(queue);
                cdl_segments_free(sg);
                return cdl_error_set(err, CDL_ERR_SYSTEM, "segments", 0, "out of memory for segments");
            }
            sg->rect = r;
        }
        int32_t k = (int32_t)sg->n++;
        cdl_seg_rect rc = {seed % w, seed / w, seed % w + 1, seed / w + 1};
        size_t head = 0, tail = 0;
        queue[tail++] = seed;
        sg->id[seed] = k;
        while (head < tail) {
            int p = queue[head++], x = p % w, y = p / w;
            rc.x0 = x < rc.x0 ? x : rc.x0;
            rc.y0 = y < rc.y0 ? y : rc.y0;
            rc.x1 = x + 1 > rc.x1 ? x + 1 : rc.x1;
            rc.y1 = y + 1 > rc.y1 ? y + 1 : rc.y1;
            for (int d = 0; d < 4; d++) {
                int nx = x + dirs[d][0], ny = y + dirs[d][1];
                if (nx < 0 || ny < 0 || nx >= w || ny >= h || sg->id[ny * w + nx] >= 0)
                    continue;
                if (continuous(sg, depth, normal, cos_max, depth_tol, k, x, y, dirs[d][0], dirs[d][1])) {
                    sg->id[ny * w + nx] = k;
                    queue[tail++] = ny * w + nx;
                }
            }
        }
        sg->rect[k] = rc;
    }
    free(queue);
    return 0;
}

void cdl_segments_free(cdl_segments *sg)
{
    free(sg->id);
    free(sg->rect);
    memset(sg, 0, sizeof *sg);
}

/* The summed-area table over a segment's rectangle of v(q) for its pixels
 * (0 elsewhere): sat[(y - y0 + 1) * (rw + 1) + (x - x0 + 1)] is the sum over
 * [x0, x] x [y0, y]; in double, as large sums of small terms lose float. */
typedef struct sat {
    cdl_seg_rect r;
    int rw;
    double *s;
} sat;

static double box_sum(const sat *t, int x, int y, int rad)
{
    int xa = x - rad < t->r.x0 ? t->r.x0 : x - rad, xb = x + rad + 1 > t->r.x1 ? t->r.x1 : x + rad + 1;
    int ya = y - rad < t->r.y0 ? t->r.y0 : y - rad, yb = y + rad + 1 > t->r.y1 ? t->r.y1 : y + rad + 1;
    xa -= t->r.x0, xb -= t->r.x0, ya -= t->r.y0, yb -= t->r.y0;
    const double *s = t->s;
    int W = t->rw + 1;
    return s[yb * W + xb] - s[ya * W + xb] - s[yb * W + xa] + s[ya * W + xa];
}

/* Builds t over segment k: value[q * stride] where mask(q). */
static void sat_build(sat *t, const cdl_segments *sg, int32_t k, const float *value, int stride, const uint8_t *use)
{
    const cdl_seg_rect r = t->r;
    int W = t->rw + 1;
    memset(t->s, 0, sizeof(double) * (size_t)W);
    for (int y = r.y0; y < r.y1; y++) {
        double row = 0.0;
        double *dst = t->s + (size_t)(y - r.y0 + 1) * W, *above = dst - W;
        dst[0] = 0.0;
        for (int x = r.x0; x < r.x1; x++) {
            int q = y * sg->w + x;
            if (sg->id[q] == k && (!use || use[q]))
                row += value ? (double)value[(size_t)q * stride] : 1.0;
            dst[x - r.x0 + 1] = above[x - r.x0 + 1] + row;
        }
    }
}

int cdl_segment_support(const cdl_segments *sg, const float *count, double target, int rmax, uint8_t *radius,
                        cdl_error *err)
{
    int fail = 0;
    rmax = rmax < 0 ? 0 : rmax > 255 ? 255 : rmax;
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t k = 0; k < (int64_t)sg->n; k++) {
        sat t = {sg->rect[k], sg->rect[k].x1 - sg->rect[k].x0, NULL};
        t.s = malloc(sizeof(double) * (size_t)(t.rw + 1) * (size_t)(t.r.y1 - t.r.y0 + 1));
        if (!t.s) {
#pragma omp atomic write
            fail = 1;
            continue;
        }
        sat_build(&t, sg, (int32_t)k, count, 1, NULL);
        for (int y = t.r.y0; y < t.r.y1; y++)
            for (int x = t.r.x0; x < t.r.x1; x++) {
                if (sg->id[y * sg->w + x] != (int32_t)k)
                    continue;
                int lo = 0, hi = rmax; /* the smallest r with box_sum >= target lies in [lo, hi] */
                if (box_sum(&t, x, y, hi) < target) {
                    lo = hi;
                } else {
                    while (lo < hi) {
                        int mid = (lo + hi) / 2;
                        if (box_sum(&t, x, y, mid) >= target)
                            hi = mid;
                        else
                            lo = mid + 1;
                    }
                }
                radius[y * sg->w + x] = (uint8_t)lo;
            }
        free(t.s);
    }
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "segments", 0, "out of memory for the filter's tables");
    return 0;
}

int cdl_segment_filter(const cdl_segments *sg, float *img, int nc, const uint8_t *use, const uint8_t *radius,
                       cdl_error *err)
{
    int fail = 0;
#pragma omp parallel for schedule(dynamic, 1)
    for (int64_t k = 0; k < (int64_t)sg->n; k++) {
        sat m = {sg->rect[k], sg->rect[k].x1 - sg->rect[k].x0, NULL}, v = m;
        size_t cells = (size_t)(m.rw + 1) * (size_t)(m.r.y1 - m.r.y0 + 1);
        m.s = malloc(sizeof(double) * cells);
        v.s = malloc(sizeof(double) * cells);
        if (!m.s || !v.s) {
            free(m.s);
            free(v.s);
#pragma omp atomic write
            fail = 1;
            continue;
        }
        sat_build(&m, sg, (int32_t)k, NULL, 1, use);
        /* one channel at a time: its table is built before any of the
         * segment's pixels is overwritten, and no other segment reads them */
        for (int c = 0; c < nc; c++) {
            sat_build(&v, sg, (int32_t)k, img + c, nc, use);
            for (int y = m.r.y0; y < m.r.y1; y++)
                for (int x = m.r.x0; x < m.r.x1; x++) {
                    int q = y * sg->w + x;
                    if (sg->id[q] != (int32_t)k || (use && !use[q]))
                        continue;
                    double wsum = box_sum(&m, x, y, radius[q]);
                    if (wsum > 0.0)
                        img[(size_t)q * nc + c] = (float)(box_sum(&v, x, y, radius[q]) / wsum);
                }
        }
        free(m.s);
        free(v.s);
    }
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "segments", 0, "out of memory for the filter's tables");
    return 0;
}
