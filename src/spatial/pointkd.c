#include "spatial/pointkd.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

static float coord(const cdl_kdtree *t, uint32_t i, int a) { return t->pts[(size_t)i * t->stride + (size_t)a]; }

/* The build sorts compact copies of the points (position and index, 16
 * bytes) rather than indices into the caller's records, which may be wide:
 * every pass over a subtree then reads contiguous memory. The comparisons
 * and swaps are the same, so is the tree. */
typedef struct kd_rec {
    float p[3];
    uint32_t i;
} kd_rec;
_Static_assert(sizeof(kd_rec) == 16, "a record is one 16-byte vector");

/* Quickselect with a three-way partition (robust to equal coordinates):
 * afterwards r[k] holds the k-th smallest coordinate of r[lo..hi), with
 * nothing larger before it and nothing smaller after it. Each partition
 * is two branch-free passes, the smaller coordinates to the front and then
 * the equal ones after them: every record is swapped, and the front only
 * grows by the comparison's result (a branch per record mispredicts about
 * half the time on coordinates in no order: the build of gkde's eye
 * vertices took 15 % of Figure 6). The halves hold the same sets as
 * with any partition; only equal coordinates may land in another order. */
static uint32_t front_of(kd_rec *r, uint32_t lo, uint32_t hi, int a, float pivot, int le)
{
    uint32_t j = lo;
    for (uint32_t i = lo; i < hi; i++) {
        const kd_rec tmp = r[i];
        const float c = tmp.p[a];
        r[i] = r[j];
        r[j] = tmp;
        j += le ? c <= pivot : c < pivot;
    }
    return j;
}

static void select_kth(kd_rec *r, uint32_t lo, uint32_t hi, uint32_t k, int a)
{
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        float x = r[lo].p[a], y = r[mid].p[a], z = r[hi - 1].p[a];
        float pivot = x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
        const uint32_t lt = front_of(r, lo, hi, a, pivot, 0);
        if (k < lt) {
            hi = lt;
            continue;
        }
        const uint32_t gt = front_of(r, lt, hi, a, pivot, 1);
        if (k >= gt)
            lo = gt;
        else
            return;
    }
}

/* The box of r[lo..hi) (a record a vector: its index lane is ignored). */
static void bounds(const kd_rec *r, uint32_t lo, uint32_t hi, float *mn, float *mx)
{
#if defined(__SSE__)
    __m128 l = _mm_set1_ps(INFINITY), h = _mm_set1_ps(-INFINITY);
    for (uint32_t i = lo; i < hi; i++) {
        const __m128 v = _mm_loadu_ps((const float *)(const void *)&r[i]); /* p[3] and i */
        l = _mm_min_ps(l, v), h = _mm_max_ps(h, v);
    }
    float lv[4], hv[4];
    _mm_storeu_ps(lv, l), _mm_storeu_ps(hv, h);
    memcpy(mn, lv, 3 * sizeof(float)), memcpy(mx, hv, 3 * sizeof(float));
#else
    for (int a = 0; a < 3; a++)
        mn[a] = INFINITY, mx[a] = -INFINITY;
    for (uint32_t i = lo; i < hi; i++)
        for (int a = 0; a < 3; a++) {
            float c = r[i].p[a];
            mn[a] = c < mn[a] ? c : mn[a];
            mx[a] = c > mx[a] ? c : mx[a];
        }
#endif
}

#define TASK_MIN 32768 /* subtrees this big are built as tasks of their own */

/* tasks: inside a parallel region whose tasks may take subtrees */
static void build(cdl_kdtree *t, kd_rec *r, uint32_t lo, uint32_t hi, int tasks)
{
    while (hi - lo > 1) {
        float mn[3], mx[3];
        bounds(r, lo, hi, mn, mx);
        int a = 0;
        for (int b = 1; b < 3; b++)
            if (mx[b] - mn[b] > mx[a] - mn[a])
                a = b;
        uint32_t mid = lo + (hi - lo) / 2;
        select_kth(r, lo, hi, mid, a);
        t->axis[mid] = (uint8_t)a;
        if (tasks && mid - lo >= TASK_MIN) {
#pragma omp task firstprivate(lo, mid)
            build(t, r, lo, mid, 1);
        } else {
            build(t, r, lo, mid, 0); /* recursion depth is log2(n) */
        }
        lo = mid + 1;
    }
    if (hi - lo == 1)
        t->axis[lo] = 0;
}

int cdl_kd_build(cdl_kdtree *t, const float *pts, uint32_t stride, uint32_t n, cdl_error *err)
{
    memset(t, 0, sizeof *t);
    t->pts = pts;
    t->stride = stride < 3 ? 3 : stride;
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++)
            if (!isfinite(pts[(size_t)i * t->stride + (size_t)a]))
                return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "kd-tree: point %u is not finite", i);
    t->idx = malloc(sizeof(uint32_t) * (n ? n : 1));
    t->axis = malloc(n ? n : 1);
    kd_rec *r = malloc(sizeof *r * (n ? n : 1));
    if (!t->idx || !t->axis || !r) {
        free(r);
        cdl_kd_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a kd-tree of %u points", n);
    }
    for (uint32_t i = 0; i < n; i++) {
        const float *q = pts + (size_t)i * t->stride;
        r[i] = (kd_rec){{q[0], q[1], q[2]}, i};
    }
    t->n = n;
    if (n >= 2 * TASK_MIN && !omp_in_parallel()) {
        /* the subtrees are disjoint: the same tree whatever the threads */
#pragma omp parallel
#pragma omp single
        build(t, r, 0, n, 1);
    } else {
        build(t, r, 0, n, 0);
    }
    for (uint32_t i = 0; i < n; i++)
        t->idx[i] = r[i].i;
    free(r);
    return 0;
}

void cdl_kd_make_identity(cdl_kdtree *t)
{
    for (uint32_t i = 0; i < t->n; i++)
        t->idx[i] = i;
    t->identity = 1;
}

void cdl_kd_free(cdl_kdtree *t)
{
    free(t->idx);
    free(t->axis);
    t->idx = NULL;
    t->axis = NULL;
    t->n = 0;
}

static float dist2(const cdl_kdtree *t, uint32_t i, cdl_vec3 q)
{
    const float *p = t->pts + (size_t)i * t->stride;
    float dx = p[0] - q.x, dy = p[1] - q.y, dz = p[2] - q.z;
    return dx * dx + dy * dy + dz * dz;
}

/* k-NN state: a max-heap on distance of the best candidates so far. */
typedef struct knn {
    uint32_t k, n;
    uint32_t *idx;
    float *d2;
    float r2; /* current search radius^2: max_d2, or the heap's top when full */
} knn;

/* Puts (i, d) at the root of the first h->n entries and sifts it down. */
static void sift_down(knn *h, uint32_t i, float d)
{
    uint32_t c = 0;
    for (;;) {
        uint32_t l = 2 * c + 1, r = l + 1, m = c;
        float dm = d;
        if (l < h->n && h->d2[l] > dm) {
            m = l;
            dm = h->d2[l];
        }
        if (r < h->n && h->d2[r] > dm)
            m = r;
        if (m == c)
            break;
        h->d2[c] = h->d2[m];
        h->idx[c] = h->idx[m];
        c = m;
    }
    h->d2[c] = d;
    h->idx[c] = i;
}

static void heap_push(knn *h, uint32_t i, float d)
{
    if (h->n < h->k) {
        uint32_t c = h->n++;
        while (c > 0) {
            uint32_t p = (c - 1) / 2;
            if (h->d2[p] >= d)
                break;
            h->d2[c] = h->d2[p];
            h->idx[c] = h->idx[p];
            c = p;
        }
        h->d2[c] = d;
        h->idx[c] = i;
    } else {
        sift_down(h, i, d); /* replaces the farthest */
    }
    if (h->n == h->k)
        h->r2 = h->d2[0];
}

static void knn_search(const cdl_kdtree *t, uint32_t lo, uint32_t hi, cdl_vec3 q, knn *h)
{
    while (lo < hi) {
        /* a small subtree is a contiguous range: scanning it beats descending */
        if (hi - lo <= 16) {
            for (uint32_t i = lo; i < hi; i++) {
                uint32_t p = t->identity ? i : t->idx[i];
                float d = dist2(t, p, q);
                if (d <= h->r2)
                    heap_push(h, p, d);
            }
            return;
        }
        uint32_t mid = lo + (hi - lo) / 2, p = t->identity ? mid : t->idx[mid];
        float d = dist2(t, p, q);
        if (d <= h->r2)
            heap_push(h, p, d);
        int a = t->axis[mid];
        float delta = (a == 0 ? q.x : a == 1 ? q.y : q.z) - coord(t, p, a);
        /* nearer half first; the farther one only if the plane is in range */
        uint32_t nlo = delta < 0.0f ? lo : mid + 1, nhi = delta < 0.0f ? mid : hi;
        uint32_t flo = delta < 0.0f ? mid + 1 : lo, fhi = delta < 0.0f ? hi : mid;
        knn_search(t, nlo, nhi, q, h);
        if (delta * delta > h->r2)
            return;
        lo = flo;
        hi = fhi;
    }
}

uint32_t cdl_kd_knn_heap(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, uint32_t *out, float *d2)
{
    if (k == 0 || t->n == 0)
        return 0;
    knn h = {k, 0, out, d2, max_d2};
    knn_search(t, 0, t->n, q, &h);
    return h.n;
}

uint32_t cdl_kd_knn(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, uint32_t *out, float *d2)
{
    if (k == 0 || t->n == 0)
        return 0;
    knn h = {k, 0, out, d2, max_d2};
    knn_search(t, 0, t->n, q, &h);
    /* heap sort into ascending distance */
    uint32_t n = h.n;
    for (uint32_t end = n; end > 1; end--) {
        float dl = h.d2[end - 1];
        uint32_t il = h.idx[end - 1];
        h.d2[end - 1] = h.d2[0];
        h.idx[end - 1] = h.idx[0];
        h.n = end - 1;
        sift_down(&h, il, dl);
    }
    return n;
}

static uint32_t ball_search(const cdl_kdtree *t, uint32_t lo, uint32_t hi, cdl_vec3 q, float r2,
                            cdl_kd_visit fn, void *ctx)
{
    uint32_t count = 0;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2, p = t->identity ? mid : t->idx[mid];
        float d = dist2(t, p, q);
        if (d <= r2) {
            fn(ctx, p, d);
            count++;
        }
        int a = t->axis[mid];
        float delta = (a == 0 ? q.x : a == 1 ? q.y : q.z) - coord(t, p, a);
        /* left half holds coordinates <= the split, right half >= */
        int go_left = delta <= 0.0f || delta * delta <= r2;
        int go_right = delta >= 0.0f || delta * delta <= r2;
        if (go_left && go_right) {
            count += ball_search(t, lo, mid, q, r2, fn, ctx);
            lo = mid + 1;
        } else if (go_left) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    return count;
}

/* Every point within r2 into (idx, d2) while at most cap fit; 0, or -1
 * when they did not. */
typedef struct collect {
    uint32_t n, cap;
    uint32_t *idx;
    float *d2;
} collect;

/* Point p at squared distance d kept if within r2; -1 when c is full. */
static int keep(collect *c, uint32_t p, float d, float r2)
{
    if (d > r2)
        return 0;
    if (c->n == c->cap)
        return -1;
    c->idx[c->n] = p;
    c->d2[c->n++] = d;
    return 0;
}

static int collect_ball(const cdl_kdtree *t, uint32_t lo, uint32_t hi, cdl_vec3 q, float r2, collect *c)
{
    while (lo < hi) {
        if (hi - lo <= 16) {
            if (c->n + (hi - lo) > c->cap) { /* near full: one at a time */
                for (uint32_t i = lo; i < hi; i++) {
                    uint32_t p = t->identity ? i : t->idx[i];
                    if (keep(c, p, dist2(t, p, q), r2))
                        return -1;
                }
                return 0;
            }
            /* written always, kept by the count: no branch to mispredict */
            for (uint32_t i = lo; i < hi; i++) {
                uint32_t p = t->identity ? i : t->idx[i];
                float d = dist2(t, p, q);
                c->idx[c->n] = p;
                c->d2[c->n] = d;
                c->n += d <= r2;
            }
            return 0;
        }
        uint32_t mid = lo + (hi - lo) / 2, p = t->identity ? mid : t->idx[mid];
        if (keep(c, p, dist2(t, p, q), r2))
            return -1;
        int a = t->axis[mid];
        float delta = (a == 0 ? q.x : a == 1 ? q.y : q.z) - coord(t, p, a);
        int go_left = delta <= 0.0f || delta * delta <= r2;
        int go_right = delta >= 0.0f || delta * delta <= r2;
        if (go_left && go_right) {
            if (collect_ball(t, lo, mid, q, r2, c))
                return -1;
            lo = mid + 1;
        } else if (go_left) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    return 0;
}

/* The k-th smallest (1 <= k <= n) of d2[0, n), all in [0, hi], without
 * moving them: a histogram of 256 bins over [lo, hi] finds the bin
 * holding it, whose values (a contiguous range, the binning being
 * monotone) are few enough to sort, or the next range to bin. */
static float kth_smallest(const float *d2, uint32_t n, uint32_t k, float hi)
{
    enum { BINS = 256, FEW = 32 };
    uint32_t hist[BINS];
    float lo = 0.0f, few[FEW];
    for (;;) {
        if (!(hi > lo))
            return lo; /* every candidate left is equal */
        float scale = (float)BINS / (hi - lo);
        memset(hist, 0, sizeof hist);
        for (uint32_t i = 0; i < n; i++) {
            float v = d2[i];
            if (v >= lo && v <= hi) {
                int b = (int)((v - lo) * scale);
                hist[b < BINS - 1 ? b : BINS - 1]++;
            }
        }
        int bin = 0;
        while (k > hist[bin])
            k -= hist[bin++];
        /* the bin's values: their range, and the values while few */
        float bmin = INFINITY, bmax = -INFINITY;
        uint32_t m = 0;
        for (uint32_t i = 0; i < n; i++) {
            float v = d2[i];
            if (v >= lo && v <= hi) {
                int b = (int)((v - lo) * scale);
                if ((b < BINS - 1 ? b : BINS - 1) == bin) {
                    bmin = v < bmin ? v : bmin;
                    bmax = v > bmax ? v : bmax;
                    if (m < FEW)
                        few[m] = v;
                    m++;
                }
            }
        }
        if (m <= FEW) {
            for (uint32_t i = 1; i < m; i++) { /* insertion sort */
                float v = few[i];
                uint32_t j = i;
                for (; j > 0 && few[j - 1] > v; j--)
                    few[j] = few[j - 1];
                few[j] = v;
            }
            return few[k - 1];
        }
        lo = bmin;
        hi = bmax;
    }
}

uint32_t cdl_kd_knn_guess(const cdl_kdtree *t, cdl_vec3 q, uint32_t k, float max_d2, float *guess, uint32_t cap,
                          uint32_t *out, float *d2, float *kth)
{
    *kth = -1.0f;
    if (k == 0 || t->n == 0)
        return 0;
    float r2 = guess && *guess > 0.0f ? *guess : 0.0f;
    for (int tries = 0; cap > k && r2 > 0.0f && tries < 3; tries++) {
        if (r2 > max_d2)
            r2 = max_d2;
        collect c = {0, cap, out, d2};
        if (collect_ball(t, 0, t->n, q, r2, &c)) {
            r2 *= 0.5f; /* the points near q are denser than the guess's */
            continue;
        }
        if (c.n < k && r2 < max_d2) {
            /* on a surface the count grows with r^2 */
            r2 *= c.n ? 1.3f * (float)k / (float)c.n : 4.0f;
            continue;
        }
        if (c.n >= k) {
            *kth = kth_smallest(d2, c.n, k, r2);
            *guess = *kth * 1.05f; /* the next query's, a little wider */
        }
        return c.n;
    }
    uint32_t n = cdl_kd_knn_heap(t, q, k, max_d2, out, d2);
    if (n == k) {
        *kth = d2[0];
        if (guess)
            *guess = d2[0] * 1.05f;
    }
    return n;
}

uint32_t cdl_kd_ball(const cdl_kdtree *t, cdl_vec3 q, float r2, cdl_kd_visit fn, void *ctx)
{
    return t->n ? ball_search(t, 0, t->n, q, r2, fn, ctx) : 0;
}

typedef struct cell_query {
    const cdl_kdtree *t;
    float q[3], r2;
    cdl_kd_visit fn;
    cdl_kd_visit_range fr;
    void *ctx;
    uint32_t count;
} cell_query;

#define CELL_LEAF 8 /* ranges this small are tested point by point */

static void cells(cell_query *c, uint32_t lo, uint32_t hi, const float *box_min, const float *box_max)
{
    const cdl_kdtree *t = c->t;
    float bmin[3] = {box_min[0], box_min[1], box_min[2]}, bmax[3] = {box_max[0], box_max[1], box_max[2]};
    while (lo < hi) {
        float near = 0.0f, far = 0.0f;
        for (int a = 0; a < 3; a++) {
            float dl = c->q[a] - bmin[a], dh = bmax[a] - c->q[a];
            float out = dl < 0.0f ? -dl : dh < 0.0f ? -dh : 0.0f, f = dl > dh ? dl : dh;
            near += out * out;
            far += f * f;
        }
        if (near > c->r2)
            return;
        if (far <= c->r2) {
            c->fr(c->ctx, lo, hi);
            c->count += hi - lo;
            return;
        }
        if (hi - lo <= CELL_LEAF) {
            for (uint32_t i = lo; i < hi; i++) {
                float d = dist2(t, i, (cdl_vec3){c->q[0], c->q[1], c->q[2]});
                if (d <= c->r2) {
                    c->fn(c->ctx, i, d);
                    c->count++;
                }
            }
            return;
        }
        uint32_t mid = lo + (hi - lo) / 2;
        int a = t->axis[mid];
        float s = coord(t, mid, a), d = dist2(t, mid, (cdl_vec3){c->q[0], c->q[1], c->q[2]});
        float lmax[3] = {bmax[0], bmax[1], bmax[2]};
        lmax[a] = s;
        cells(c, lo, mid, bmin, lmax); /* recursion depth is log2(n) */
        if (d <= c->r2) {
            c->fn(c->ctx, mid, d);
            c->count++;
        }
        bmin[a] = s;
        lo = mid + 1;
    }
}

uint32_t cdl_kd_ball_cells(const cdl_kdtree *t, uint32_t lo, uint32_t hi, const float bmin[3],
                           const float bmax[3], cdl_vec3 q, float r2, cdl_kd_visit fn, cdl_kd_visit_range fr,
                           void *ctx)
{
    if (!(lo < hi && hi <= t->n) || !t->identity)
        return 0;
    cell_query c = {t, {q.x, q.y, q.z}, r2, fn, fr, ctx, 0};
    cells(&c, lo, hi, bmin, bmax);
    return c.count;
}
