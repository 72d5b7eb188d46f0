/* The eye-sample kd-tree's build (Herzog et al. 2007, §5.1); its queries
 * are in splatkd_query.c. */
#include "spatial/splatkd.h"

#include "core/grow.h"
#include "core/octahedral.h"
#include "spatial/splatkd_node.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define MAX_INDEX (1u << 28) /* samples, and nodes a right-child offset can reach */

void cdl_skd_params_default(cdl_skd_params *p, float scene_diag)
{
    p->leaf_size = 16;
    p->min_diag = 1e-5f * scene_diag;
    p->cull_deg = 15.0f;
    p->part_depth = 6;
}

typedef struct builder {
    const cdl_skd_params *prm;
    uint32_t *idx; /* caller's indices, permuted in place */
    const cdl_vec3 *p, *n;
    const uint8_t *flags;
    uint32_t cull_below; /* subtrees smaller than this may get a culling node */
    float cos_cull;
} builder;

/* What the build of a subtree produces: its nodes (right children
 * indexed from its first), parts and counts. The two halves of a large
 * split are built as tasks into their own and appended in depth-first
 * order, so the tree is the serial build's whatever the threads. */
typedef struct sub {
    cdl_skd_node *nodes;
    uint32_t n, cap;
    cdl_skd_part *parts;
    uint32_t nparts, pcap;
    uint32_t leaves, culls, empties, depth;
    int fail;
} sub;

/* Halves at least this large are built as tasks. */
#define TASK_MIN 32768u

static uint32_t push(sub *o, uint32_t a, uint32_t w)
{
    if (o->n == o->cap) {
        uint32_t cap = o->cap ? 2 * o->cap : 1024;
        cdl_skd_node *nn = cap < MAX_INDEX ? realloc(o->nodes, sizeof *nn * cap) : NULL;
        if (!nn) {
            o->fail = 1;
            return 0;
        }
        o->nodes = nn;
        o->cap = cap;
    }
    o->nodes[o->n] = (cdl_skd_node){a, w};
    return o->n++;
}

static void add_part(sub *o, uint32_t node, uint32_t lo, uint32_t hi, const float *mn, const float *mx)
{
    if (cdl_grow((void **)&o->parts, &o->pcap, o->nparts + 1, sizeof *o->parts)) {
        o->fail = 1;
        return;
    }
    cdl_skd_part *p = &o->parts[o->nparts++];
    p->node = node;
    p->lo = lo;
    p->hi = hi;
    memcpy(p->bmin, mn, sizeof p->bmin);
    memcpy(p->bmax, mx, sizeof p->bmax);
}

/* src after dst's nodes (its right-child and part indices moved along);
 * src is freed. */
static void append(sub *dst, sub *src)
{
    uint32_t base = dst->n;
    dst->fail |= src->fail;
    if (!dst->fail && (uint64_t)base + src->n >= MAX_INDEX)
        dst->fail = 1;
    for (uint32_t i = 0; i < src->n && !dst->fail; i++) {
        cdl_skd_node nd = src->nodes[i];
        push(dst, nd.a, (nd.b & 3) == 3 ? nd.b : nd.b + (base << 2));
    }
    for (uint32_t i = 0; i < src->nparts && !dst->fail; i++) {
        const cdl_skd_part *p = &src->parts[i];
        add_part(dst, base + p->node, p->lo, p->hi, p->bmin, p->bmax);
    }
    dst->leaves += src->leaves;
    dst->culls += src->culls;
    dst->empties += src->empties;
    dst->depth = src->depth > dst->depth ? src->depth : dst->depth;
    free(src->nodes);
    free(src->parts);
}

static float pc(const builder *b, uint32_t i, int a)
{
    const float *v = &b->p[i].x;
    return v[a];
}

/* A culling node over idx[lo, hi) if every normal lies within the cone
 * limit of their mean; returns 1 if one was pushed. */
static int try_cull(const builder *b, sub *o, uint32_t lo, uint32_t hi)
{
    cdl_vec3 m = cdl_v3(0.0f, 0.0f, 0.0f);
    for (uint32_t i = lo; i < hi; i++) {
        if (b->flags && (b->flags[b->idx[i]] & CDL_SKD_TWO_SIDED))
            return 0;
        m = cdl_add(m, b->n[b->idx[i]]);
    }
    float len = cdl_length(m);
    if (!(len > 0.0f))
        return 0;
    uint32_t code = cdl_oct_encode_bits(cdl_scale(m, 1.0f / len), 16);
    cdl_vec3 r = cdl_oct_decode_bits(code, 16); /* the deviation is measured from what the node holds */
    float cmin = 1.0f;
    for (uint32_t i = lo; i < hi; i++) {
        float c = cdl_dot(r, b->n[b->idx[i]]);
        cmin = c < cmin ? c : cmin;
    }
    if (!(cmin >= b->cos_cull))
        return 0;
    /* C_max = sin(D_theta), a little larger for rounding, quantized upwards */
    double s = sqrt(fmax(0.0, 1.0 - (double)cmin * cmin)) + 1e-4;
    uint32_t q = (uint32_t)ceil((s < 1.0 ? s : 1.0) * 65535.0);
    push(o, code, 3u | (uint32_t)KIND_CULL << 2 | q << 16);
    return 1;
}

static void build(const builder *b, sub *o, uint32_t lo, uint32_t hi, float *mn, float *mx, int culled,
                  uint32_t depth, int in_part);

/* One half of a split as a task of its own (mn, mx copied: the caller
 * goes on with its own). */
static void build_task(const builder *b, sub *o, uint32_t lo, uint32_t hi, const float *mn, const float *mx,
                       int culled, uint32_t depth, int in_part)
{
    float cmn[3] = {mn[0], mn[1], mn[2]}, cmx[3] = {mx[0], mx[1], mx[2]};
    build(b, o, lo, hi, cmn, cmx, culled, depth, in_part);
}

/* The subtree over idx[lo, hi) in the cell [mn, mx], `depth` splits below
 * the root. A part is the subtree at depth part_depth, or a shallower one
 * that does not split (a leaf, an empty node) or starts with a culling
 * node; in_part: an ancestor is one. */
static void build(const builder *b, sub *o, uint32_t lo, uint32_t hi, float *mn, float *mx, int culled,
                  uint32_t depth, int in_part)
{
    if (o->fail)
        return;
    if (depth > o->depth)
        o->depth = depth;
    uint32_t first = o->n;
    if (lo == hi) {
        if (!in_part)
            add_part(o, first, lo, hi, mn, mx);
        push(o, 0, 3u | (uint32_t)KIND_EMPTY << 2);
        o->empties++;
        return;
    }
    if (!culled && b->cos_cull > -2.0f && hi - lo < b->cull_below && try_cull(b, o, lo, hi)) {
        culled = 1;
        o->culls++;
        if (!in_part) {
            add_part(o, first, lo, hi, mn, mx);
            in_part = 1;
        }
    }
    float d[3] = {mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]};
    float diag = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    uint32_t mid = lo;
    int axis = -1;
    float split = 0.0f;
    if (hi - lo > b->prm->leaf_size && diag >= b->prm->min_diag) {
        /* axes by cell extent, widest first; the first that separates */
        int order[3] = {0, 1, 2};
        for (int i = 0; i < 3; i++)
            for (int j = i + 1; j < 3; j++)
                if (d[order[j]] > d[order[i]]) {
                    int tmp = order[i];
                    order[i] = order[j];
                    order[j] = tmp;
                }
        for (int k = 0; k < 3 && axis < 0; k++) {
            int a = order[k];
            float sp = 0.5f * (mn[a] + mx[a]), lo_c = INFINITY, hi_c = -INFINITY;
            uint32_t left = 0;
            for (uint32_t i = lo; i < hi; i++) {
                float c = pc(b, b->idx[i], a);
                left += c < sp;
                lo_c = c < lo_c ? c : lo_c;
                hi_c = c > hi_c ? c : hi_c;
            }
            if (!(hi_c > lo_c))
                continue; /* every sample at the same coordinate */
            /* a half with no sample: the plane moves to the sample nearest
             * the median, and the empty side becomes an empty node */
            int le = 0; /* left: c < sp, or c <= sp */
            if (left == 0) {
                sp = lo_c;
            } else if (left == hi - lo) {
                sp = hi_c;
                le = 1;
            }
            uint32_t i = lo, j = hi;
            while (i < j) {
                float c = pc(b, b->idx[i], a);
                if (le ? c <= sp : c < sp) {
                    i++;
                } else {
                    uint32_t tmp = b->idx[i];
                    b->idx[i] = b->idx[--j];
                    b->idx[j] = tmp;
                }
            }
            axis = a;
            split = sp;
            mid = i;
        }
    }
    if (!in_part && (axis < 0 || depth == b->prm->part_depth)) {
        add_part(o, first, lo, hi, mn, mx);
        in_part = 1;
    }
    if (axis < 0) {
        push(o, hi - lo, 3u | (uint32_t)KIND_LEAF << 2 | lo << 4);
        o->leaves++;
        return;
    }
    uint32_t node = push(o, fbits(split), (uint32_t)axis);
    float lmx[3] = {mx[0], mx[1], mx[2]}, rmn[3] = {mn[0], mn[1], mn[2]};
    lmx[axis] = split;
    rmn[axis] = split;
    if (mid - lo >= TASK_MIN && hi - mid >= TASK_MIN) {
        sub l = {0}, r = {0};
#pragma omp task default(shared)
        build_task(b, &l, lo, mid, mn, lmx, culled, depth + 1, in_part);
        build_task(b, &r, mid, hi, rmn, mx, culled, depth + 1, in_part);
#pragma omp taskwait
        append(o, &l);
        if (!o->fail)
            o->nodes[node].b |= o->n << 2;
        append(o, &r);
        return;
    }
    build(b, o, lo, mid, mn, lmx, culled, depth + 1, in_part);
    if (o->fail)
        return;
    if (o->n >= MAX_INDEX) {
        o->fail = 1;
        return;
    }
    o->nodes[node].b |= o->n << 2;
    build(b, o, mid, hi, rmn, mx, culled, depth + 1, in_part);
}

/* The bounding sphere of every node below `node` (lsph: centre and
 * radius; an empty subtree gets radius -1), the box of its samples into
 * lo, hi (empty: lo > hi). Returns the node after the subtree. */
static uint32_t spheres(cdl_skd *t, uint32_t node, float *lo, float *hi)
{
    cdl_skd_node nd = t->nodes[node];
    float *sp = t->lsph + 4 * (size_t)node;
    cdl_skd_range *rg = &t->range[node];
    uint32_t next;
    for (int a = 0; a < 3; a++) {
        lo[a] = INFINITY;
        hi[a] = -INFINITY;
    }
    if ((nd.b & 3) == 3 && ((nd.b >> 2) & 3) == KIND_LEAF) {
        uint32_t l = nd.b >> 4, h = l + nd.a;
        rg->lo = l;
        rg->hi = h;
        for (int a = 0; a < 3; a++)
            for (uint32_t i = l; i < h; i++) {
                lo[a] = t->p[a][i] < lo[a] ? t->p[a][i] : lo[a];
                hi[a] = t->p[a][i] > hi[a] ? t->p[a][i] : hi[a];
            }
        next = node + 1;
    } else if ((nd.b & 3) == 3 && ((nd.b >> 2) & 3) == KIND_EMPTY) {
        rg->lo = rg->hi = 0;
        next = node + 1;
    } else if ((nd.b & 3) == 3) { /* culling node: its child's samples */
        next = spheres(t, node + 1, lo, hi);
        *rg = t->range[node + 1];
    } else {
        float l2[3], h2[3];
        spheres(t, node + 1, lo, hi);
        next = spheres(t, nd.b >> 2, l2, h2);
        /* a subtree's samples are contiguous; an empty child has none */
        cdl_skd_range a = t->range[node + 1], b = t->range[nd.b >> 2];
        rg->lo = a.lo < a.hi ? a.lo : b.lo;
        rg->hi = b.lo < b.hi ? b.hi : a.hi;
        for (int a = 0; a < 3; a++) {
            lo[a] = l2[a] < lo[a] ? l2[a] : lo[a];
            hi[a] = h2[a] > hi[a] ? h2[a] : hi[a];
        }
    }
    if (!(lo[0] <= hi[0])) {
        sp[0] = sp[1] = sp[2] = 0.0f;
        sp[3] = -1.0f;
        return next;
    }
    float r2 = 0.0f;
    for (int a = 0; a < 3; a++) {
        sp[a] = 0.5f * (lo[a] + hi[a]);
        r2 += 0.25f * (hi[a] - lo[a]) * (hi[a] - lo[a]);
    }
    /* a little larger: the samples' distances are computed in float too */
    sp[3] = sqrtf(r2) * 1.0001f + 1e-6f * (fabsf(sp[0]) + fabsf(sp[1]) + fabsf(sp[2]));
    return next;
}

int cdl_skd_build(cdl_skd *t, const cdl_vec3 *p, const cdl_vec3 *n, const uint8_t *flags, uint32_t n_samples,
                  const cdl_skd_params *prm, cdl_error *err)
{
    memset(t, 0, sizeof *t);
    if (n_samples >= MAX_INDEX)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "splat kd-tree: %u eye samples, at most %u", n_samples,
                             MAX_INDEX - 1);
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n_samples; i++) {
        const float *v = &p[i].x;
        if (!cdl_is_finite3(p[i]) || !cdl_is_finite3(n[i]))
            return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "splat kd-tree: eye sample %u is not finite", i);
        for (int a = 0; a < 3; a++) {
            mn[a] = v[a] < mn[a] ? v[a] : mn[a];
            mx[a] = v[a] > mx[a] ? v[a] : mx[a];
        }
    }
    if (!n_samples)
        for (int a = 0; a < 3; a++)
            mn[a] = mx[a] = 0.0f;
    memcpy(t->bmin, mn, sizeof mn);
    memcpy(t->bmax, mx, sizeof mx);
    size_t m = n_samples ? n_samples : 1;
    t->order = malloc(sizeof(uint32_t) * m);
    t->two = calloc(m + 16, sizeof(float));
    for (int a = 0; a < 3; a++) { /* 16 floats of room: the leaf test reads 16 lanes */
        t->p[a] = calloc(m + 16, sizeof(float));
        t->nrm[a] = calloc(m + 16, sizeof(float));
    }
    int ok = t->order && t->two;
    for (int a = 0; a < 3; a++)
        ok = ok && t->p[a] && t->nrm[a];
    if (!ok) {
        cdl_skd_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for the splat kd-tree");
    }
    t->n = n_samples;
    for (uint32_t i = 0; i < n_samples; i++)
        t->order[i] = i;
    builder b = {prm, t->order, p, n, flags, 0, -3.0f};
    if (prm->cull_deg >= 0.0f) {
        b.cos_cull = cosf(prm->cull_deg * (float)(CDL_PI / 180.0));
        b.cull_below = (uint32_t)ceil(sqrt((double)n_samples)); /* 2^(0.5 log2 N) */
    }
    float bmn[3], bmx[3];
    memcpy(bmn, mn, sizeof bmn);
    memcpy(bmx, mx, sizeof bmx);
    sub o = {0};
#pragma omp parallel if (n_samples >= 2 * TASK_MIN)
#pragma omp single
    build(&b, &o, 0, n_samples, bmn, bmx, 0, 0, 0);
    free(t->parts);
    t->nodes = o.nodes;
    t->nnodes = o.n;
    t->cap = o.cap;
    t->parts = o.parts;
    t->nparts = o.nparts;
    t->leaves = o.leaves;
    t->culls = o.culls;
    t->empties = o.empties;
    t->depth = o.depth;
    if (o.fail || !t->parts) {
        cdl_skd_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for the splat kd-tree");
    }
#pragma omp parallel for schedule(static) if (n_samples >= 2 * TASK_MIN)
    for (uint32_t i = 0; i < n_samples; i++) {
        uint32_t s = t->order[i];
        const float *v = &p[s].x, *w = &n[s].x;
        for (int a = 0; a < 3; a++) {
            t->p[a][i] = v[a];
            t->nrm[a][i] = w[a];
        }
        t->two[i] = flags && (flags[s] & CDL_SKD_TWO_SIDED) ? 1.0f : 0.0f;
    }
    /* every node's bounding sphere */
    t->lsph = malloc(sizeof(float) * 4 * (t->nnodes ? t->nnodes : 1));
    t->range = malloc(sizeof(cdl_skd_range) * (t->nnodes ? t->nnodes : 1));
    if (!t->lsph || !t->range) {
        cdl_skd_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for the splat kd-tree");
    }
    if (t->nnodes) {
        float bl[3], bh[3];
        spheres(t, 0, bl, bh);
    }
    if (cdl_skd_build_wide(t)) {
        cdl_skd_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for the splat kd-tree");
    }
    return 0;
}

void cdl_skd_free(cdl_skd *t)
{
    free(t->nodes);
    free(t->order);
    free(t->two);
    for (int a = 0; a < 3; a++) {
        free(t->p[a]);
        free(t->nrm[a]);
    }
    free(t->parts);
    free(t->lsph);
    free(t->range);
    free(t->wide);
    free(t->wcull);
    free(t->wpart);
    memset(t, 0, sizeof *t);
}

size_t cdl_skd_bytes(const cdl_skd *t)
{
    return (size_t)t->cap * sizeof(cdl_skd_node) + (size_t)t->nnodes * (4 * sizeof(float) + sizeof(cdl_skd_range)) + (size_t)t->n * (4 + 7 * sizeof(float)) +
           (size_t)t->nparts * (sizeof(cdl_skd_part) + sizeof(cdl_skd_went)) + (size_t)t->capwide * sizeof(cdl_skd_wnode) +
           (size_t)t->capwcull * sizeof(cdl_skd_wcull);
}
