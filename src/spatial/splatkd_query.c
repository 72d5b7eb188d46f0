/* Queries of the eye-sample kd-tree (Herzog et al. 2007, §5.2): the
 * photon ray's frustum traversal (bounding spheres, or Algorithm 1's 1D
 * slabs), Algorithm 2's leaf test (splatkd_leaf.h) over its ranges, the
 * 16-lane and range visitor and hit-list interfaces, brute force for
 * tests, and the subtree regions and stop lists the radiance cache uses.
 * The build is in splatkd.c. */
#include "spatial/splatkd.h"

#include "core/grow.h"
#include "core/octahedral.h"
#include "spatial/splatkd_leaf.h"
#include "spatial/splatkd_node.h"

#include <math.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif
#include <stdlib.h>
#include <string.h>

static int add_hit(cdl_splat_hits *out, uint32_t s, float w, float iz)
{
    if (cdl_grow((void **)&out->h, &out->cap, out->n + 1, sizeof *out->h)) {
        out->fail = 1;
        return -1;
    }
    out->h[out->n++] = (cdl_splat_hit){s, w, iz};
    return 0;
}

uint32_t cdl_skd_weigh16(const cdl_skd *t, uint32_t b, uint32_t m, const cdl_splat_ray *r, float *w, float *iz)
{
    ray16 L;
    ray16_of(&L, r);
    soa16 a = soa16_of(t);
    return r->cap > 0.0f ? weigh16(&a, b, m, &L, 1, 1, w, iz, NULL) : weigh16(&a, b, m, &L, 0, 1, w, iz, NULL);
}

typedef struct trav {
    const cdl_skd *t;
    const cdl_splat_ray *r;
    float o[3], d[3], inv[3]; /* inv: 1 / |d| per axis (0 where d is 0) */
    float zmax;               /* no sample farther along the ray is fed */
    int cull, slabs, both, iz; /* iz: 1 / z wanted */
    int any_only;              /* both: the frustum's lanes only (CDL_SKD_ANY) */
    cdl_skd_visit fn;          /* 16 lanes a call, or */
    cdl_skd_visit_range fnr;   /* a range a call, or */
    cdl_skd_visit_both fnb;    /* 16 lanes a call, frustum and feasible */
    void *ctx;
    cdl_skd_count *cnt;
    /* cdl_skd_any_behind: the planes (np > 0), the footprints, the answer */
    const cdl_skd_plane *pl;
    int np, found;
    const float *pw;
} trav;

/* test_range for a range visitor: the leaf tests of a chunk into arrays,
 * one call for all of it. mode: 1 + plane + 2 wiz. */
static inline void chunks(const trav *v, uint32_t lo, uint32_t hi, int mode)
{
    float w[CDL_SKD_CHUNK], zz[CDL_SKD_CHUNK];
    uint16_t mask[CDL_SKD_CHUNK / 16];
    ray16 L;
    ray16_of(&L, v->r);
    const soa16 a = soa16_of(v->t);
    for (uint32_t c = lo; c < hi; c += CDL_SKD_CHUNK) {
        uint32_t n = hi - c < CDL_SKD_CHUNK ? hi - c : CDL_SKD_CHUNK, any = 0;
        for (uint32_t j = 0; j * 16 < n; j++) {
            uint32_t b = c + 16 * j, m = n - 16 * j < 16 ? n - 16 * j : 16;
            uint32_t in = weigh16(&a, b, m, &L, (mode - 1) & 1, (mode - 1) >> 1, w + 16 * j, zz + 16 * j, NULL);
            mask[j] = (uint16_t)in;
            any |= in;
        }
        if (any)
            v->fnr(v->ctx, c, n, mask, w, zz);
    }
}

static void test_chunks(const trav *v, uint32_t lo, uint32_t hi)
{
    int plane = v->r->cap > 0.0f;
    if (plane && v->iz)
        chunks(v, lo, hi, 4);
    else if (plane)
        chunks(v, lo, hi, 2);
    else if (v->iz)
        chunks(v, lo, hi, 3);
    else
        chunks(v, lo, hi, 1);
}

/* Samples [lo, hi); culled: under a culling node that prunes them (only
 * the both visit gets there, for the frustum's lanes). */
static void range_behind(trav *v, uint32_t lo, uint32_t hi);

static void test_range(const trav *v, uint32_t lo, uint32_t hi, int culled)
{
    v->cnt->tested += hi - lo;
    v->cnt->weighed += culled ? 0 : hi - lo;
    if (v->fnr) {
        test_chunks(v, lo, hi);
        return;
    }
    ray16 L;
    ray16_of(&L, v->r);
    const soa16 a = soa16_of(v->t);
    if (v->both) {
        for (uint32_t b = lo; b < hi; b += 16) {
            uint32_t m = hi - b < 16 ? hi - b : 16;
            float z[16], w[16], iz[16];
            any16 f = {v->zmax, culled | v->any_only, 0, z};
            uint32_t feas = v->r->cap > 0.0f ? weigh16(&a, b, m, &L, 1, 1, w, iz, &f)
                                             : weigh16(&a, b, m, &L, 0, 1, w, iz, &f);
            if (f.mask | feas)
                v->fnb(v->ctx, b, m, f.mask, z, feas, w, iz);
        }
        return;
    }
    for (uint32_t b = lo; b < hi; b += 16) {
        uint32_t m = hi - b < 16 ? hi - b : 16;
        float w[16], zz[16];
        uint32_t any = v->r->cap > 0.0f ? weigh16(&a, b, m, &L, 1, 1, w, zz, NULL) : weigh16(&a, b, m, &L, 0, 1, w, zz, NULL);
        if (any)
            v->fn(v->ctx, b, m, any, w, zz);
    }
}

/* Radius of the frustum at distance t (the cap keeps the hit's radius). */
static float radius_at(const cdl_splat_ray *r, float t) { return r->h0 + r->dh * (t < r->len ? t : r->len); }

/* Whether the frustum can reach the node's bounding sphere (the default
 * traversal): tighter than the 1D slabs of Algorithm 1, whose boxes reach
 * far past the frustum at oblique incidence (on Table 7.1's Cornell box
 * 1.27 samples tested per splat against 2.45), and cheaper per node. */
static int sphere_reached(const trav *v, uint32_t node)
{
    const float *sp = v->t->lsph + 4 * (size_t)node;
    const cdl_splat_ray *r = v->r;
    float Dx = sp[0] - v->o[0], Dy = sp[1] - v->o[1], Dz = sp[2] - v->o[2], rad = sp[3];
    float z = Dx * v->d[0] + Dy * v->d[1] + Dz * v->d[2];
    if (z + rad < 0.0f || z - rad > v->zmax)
        return 0;
    float ex = Dx - z * v->d[0], ey = Dy - z * v->d[1], ez = Dz - z * v->d[2];
    float R = radius_at(r, z + rad) + rad;
    return ex * ex + ey * ey + ez * ez <= R * R;
}

/* A leaf, empty or culling node: 1 if the traversal goes on to the
 * culling node's child (node + 1); *culled becomes 1 below a culling
 * node that prunes in the both visit. */
static inline int special_node(const trav *v, cdl_skd_node nd, int *culled)
{
    uint32_t kind = (nd.b >> 2) & 3;
    if (kind == KIND_LEAF) {
        uint32_t lo = nd.b >> 4;
        test_range(v, lo, lo + nd.a, *culled);
        return 0;
    }
    if (kind == KIND_EMPTY)
        return 0;
    /* culling node: every sample faces away from the ray? d . n / |n| >=
     * C_max, without normalizing n */
    if (v->cull) {
        float cmax = (float)(nd.b >> 16) / 65535.0f;
        cdl_vec3 n = cdl_oct_decode_raw(nd.a, 16);
        float dv = cdl_dot(v->r->d, n);
        if (dv >= 0.0f && dv * dv >= cmax * cmax * cdl_dot(n, n)) {
            if (!v->both)
                return 0;
            *culled = 1;
        }
    }
    return 1;
}

/* The default traversal: every node whose bounding sphere the frustum
 * reaches (empty nodes have none). */
static void traverse_spheres(const trav *v, uint32_t node, int culled)
{
    const cdl_skd *t = v->t;
    for (;;) {
        v->cnt->nodes++;
        cdl_skd_node nd = t->nodes[node];
        if ((nd.b & 3) == 3) {
            uint32_t kind = (nd.b >> 2) & 3;
            if (kind != KIND_CULL && (kind == KIND_EMPTY || !sphere_reached(v, node)))
                return;
            if (!special_node(v, nd, &culled))
                return;
            node++;
            continue;
        }
        if (!sphere_reached(v, node))
            return;
        traverse_spheres(v, node + 1, culled);
        node = nd.b >> 2;
    }
}

/* The wide tree's children whose spheres the frustum reaches, as a lane
 * mask: sphere_reached on every lane at once. */
static inline uint32_t wide_reached(const trav *v, const cdl_skd_wnode *w)
{
    const cdl_splat_ray *r = v->r;
    const float ox = v->o[0], oy = v->o[1], oz = v->o[2], dx = v->d[0], dy = v->d[1], dz = v->d[2];
    const float zmax = v->zmax, len = r->len, h0 = r->h0, dh = r->dh;
#if defined(__AVX512F__) && defined(__AVX512VL__) && CDL_SKD_WIDTH == 8
    /* the lanes' compares straight into a mask register */
    __m256 Dx = _mm256_sub_ps(_mm256_loadu_ps(w->c[0]), _mm256_set1_ps(ox));
    __m256 Dy = _mm256_sub_ps(_mm256_loadu_ps(w->c[1]), _mm256_set1_ps(oy));
    __m256 Dz = _mm256_sub_ps(_mm256_loadu_ps(w->c[2]), _mm256_set1_ps(oz));
    __m256 rad = _mm256_loadu_ps(w->c[3]), vdx = _mm256_set1_ps(dx), vdy = _mm256_set1_ps(dy), vdz = _mm256_set1_ps(dz);
    __m256 z = _mm256_fmadd_ps(Dz, vdz, _mm256_fmadd_ps(Dy, vdy, _mm256_mul_ps(Dx, vdx)));
    __m256 zr = _mm256_add_ps(z, rad);
    __m256 ex = _mm256_fnmadd_ps(z, vdx, Dx), ey = _mm256_fnmadd_ps(z, vdy, Dy), ez = _mm256_fnmadd_ps(z, vdz, Dz);
    __m256 e2 = _mm256_fmadd_ps(ez, ez, _mm256_fmadd_ps(ey, ey, _mm256_mul_ps(ex, ex)));
    __m256 R = _mm256_add_ps(
        _mm256_fmadd_ps(_mm256_set1_ps(dh), _mm256_min_ps(zr, _mm256_set1_ps(len)), _mm256_set1_ps(h0)), rad);
    __mmask8 ok = _mm256_cmp_ps_mask(zr, _mm256_setzero_ps(), _CMP_GE_OQ);
    ok = _mm256_mask_cmp_ps_mask(ok, _mm256_sub_ps(z, rad), _mm256_set1_ps(zmax), _CMP_LE_OQ);
    ok = _mm256_mask_cmp_ps_mask(ok, e2, _mm256_mul_ps(R, R), _CMP_LE_OQ);
    return ok;
#else
    uint32_t ok[CDL_SKD_WIDTH];
#pragma omp simd
    for (uint32_t i = 0; i < CDL_SKD_WIDTH; i++) {
        float Dx = w->c[0][i] - ox, Dy = w->c[1][i] - oy, Dz = w->c[2][i] - oz, rad = w->c[3][i];
        float z = Dx * dx + Dy * dy + Dz * dz, zr = z + rad;
        float ex = Dx - z * dx, ey = Dy - z * dy, ez = Dz - z * dz;
        float R = h0 + dh * (zr < len ? zr : len) + rad;
        ok[i] = (zr >= 0.0f) & (z - rad <= zmax) & (ex * ex + ey * ey + ez * ez <= R * R);
    }
    uint32_t mask = 0;
    for (uint32_t i = 0; i < CDL_SKD_WIDTH; i++)
        mask |= ok[i] << i;
    return mask;
#endif
}

/* Whether a culling node prunes its subtree: every sample faces away from
 * the ray (d . n / |n| >= C_max, without normalizing n). */
static int culled(const trav *v, const cdl_skd_wcull *c)
{
    float dv = v->d[0] * c->n[0] + v->d[1] * c->n[1] + v->d[2] * c->n[2];
    return dv >= 0.0f && dv * dv >= c->c2;
}

/* The wide node's children whose spheres reach behind some plane of an
 * any_behind walk. */
static inline uint32_t wide_behind(const trav *v, const cdl_skd_wnode *w)
{
    uint32_t mask = 0;
    for (int k = 0; k < v->np; k++) {
        const float *n = v->pl[k].n, c = v->pl[k].c;
        for (uint32_t i = 0; i < CDL_SKD_WIDTH; i++)
            mask |= (uint32_t)(w->c[0][i] * n[0] + w->c[1][i] * n[1] + w->c[2][i] * n[2] - w->c[3][i] < c) << i;
    }
    return mask;
}

#define WIDE_STACK 512

/* The default traversal on the wide tree from entry e (its sphere
 * tested), depth first with a stack: the leaves in the binary
 * traversal's order. */
/* behind: cdl_skd_any_behind's walk (a constant: the plain traversal
 * keeps none of its tests) */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline void wide_walk(const trav *v, cdl_skd_went e, const int behind)
{
    const cdl_skd *t = v->t;
    cdl_skd_went stack[WIDE_STACK];
    /* the both visit: the stack's entries from `cut` up lie under a
     * culling node that prunes (UINT32_MAX: none) */
    uint32_t sp = 0, cut = UINT32_MAX;
    for (;;) {
        v->cnt->nodes++;
        if (e.n == CDL_SKD_WCULL) {
            const cdl_skd_wcull *c = &t->wcull[e.ref];
            if (!(v->cull && culled(v, c)) || v->both) {
                if (v->cull && cut == UINT32_MAX && culled(v, c))
                    cut = sp;
                e = c->next;
                continue;
            }
        } else if (e.n == 0) {
            const cdl_skd_wnode *w = &t->wide[e.ref];
            uint32_t hit = wide_reached(v, w);
            if (behind)
                hit &= wide_behind(v, w);
            if (hit) {
                uint32_t k = (uint32_t)__builtin_ctz(hit);
                hit &= hit - 1;
                while (hit) { /* the rest, last first: the lowest lane pops next */
                    uint32_t j = 31u - (uint32_t)__builtin_clz(hit);
                    hit &= ~(1u << j);
                    stack[sp++] = (cdl_skd_went){w->ref[j], w->n[j]};
                }
                e = (cdl_skd_went){w->ref[k], w->n[k]};
                continue;
            }
        } else if (e.n != CDL_SKD_WEMPTY) {
            if (behind)
                range_behind((trav *)v, e.ref, e.ref + e.n);
            else
                test_range(v, e.ref, e.ref + e.n, cut != UINT32_MAX);
        }
        if (!sp || (behind && v->found))
            return;
        e = stack[--sp];
        if (sp < cut)
            cut = UINT32_MAX;
    }
}

static void traverse_wide(const trav *v, cdl_skd_went e) { wide_walk(v, e, 0); }

static void traverse_behind(trav *v, cdl_skd_went e) { wide_walk(v, e, 1); }

/* Algorithm 1: node over the ray interval [t0, t1]. */
static void traverse(const trav *v, uint32_t node, float t0, float t1, int culled)
{
    const cdl_skd *t = v->t;
    for (;;) {
        v->cnt->nodes++;
        cdl_skd_node nd = t->nodes[node];
        uint32_t ty = nd.b & 3;
        if (ty == 3) {
            if (!special_node(v, nd, &culled))
                return;
            node++;
            continue;
        }
        int a = (int)ty;
        float s = bitsf(nd.a), R1 = radius_at(v->r, t1);
        uint32_t left = node + 1, right = nd.b >> 2;
        if (v->d[a] == 0.0f) {
            int go_l = v->o[a] - R1 <= s, go_r = v->o[a] + R1 >= s;
            if (go_l && go_r) {
                traverse(v, left, t0, t1, culled);
                node = right;
            } else {
                node = go_l ? left : right;
            }
            continue;
        }
        float ia = v->d[a] > 0.0f ? v->inv[a] : -v->inv[a];
        float tp = (s - v->o[a]) * ia, dt = R1 * v->inv[a];
        float ta = tp - dt, tb = tp + dt;
        uint32_t front = v->d[a] > 0.0f ? left : right, back = v->d[a] > 0.0f ? right : left;
        int go_f = t0 <= tb, go_b = t1 >= ta;
        if (go_f && go_b) {
            traverse(v, front, t0, tb < t1 ? tb : t1, culled);
            node = back;
            t0 = ta > t0 ? ta : t0;
        } else if (go_f) {
            node = front;
            t1 = tb < t1 ? tb : t1;
        } else if (go_b) {
            node = back;
            t0 = ta > t0 ? ta : t0;
        } else {
            return;
        }
    }
}

typedef struct region_walk {
    const cdl_skd *t;
    uint32_t max_n, n, cap, part;
    cdl_skd_region *r;
    int fail;
} region_walk;

static void regions_below(region_walk *w, uint32_t node)
{
    const cdl_skd *t = w->t;
    for (;;) {
        cdl_skd_range rg = t->range[node];
        cdl_skd_node nd = t->nodes[node];
        if (rg.hi <= rg.lo)
            return;
        if (rg.hi - rg.lo <= w->max_n || ((nd.b & 3) == 3 && ((nd.b >> 2) & 3) == KIND_LEAF)) {
            if (w->n == w->cap) {
                uint32_t cap = w->cap ? 2 * w->cap : 256;
                cdl_skd_region *r = realloc(w->r, sizeof *r * cap);
                if (!r) {
                    w->fail = 1;
                    return;
                }
                w->r = r;
                w->cap = cap;
            }
            w->r[w->n++] = (cdl_skd_region){node, rg.lo, rg.hi, w->part};
            return;
        }
        if ((nd.b & 3) == 3) { /* culling node */
            node++;
            continue;
        }
        regions_below(w, node + 1);
        node = nd.b >> 2;
    }
}

int cdl_skd_regions(const cdl_skd *t, uint32_t max_n, cdl_skd_region **out, uint32_t *n, cdl_error *err)
{
    region_walk w = {t, max_n ? max_n : 1, 0, 0, 0, NULL, 0};
    for (uint32_t p = 0; p < t->nparts && !w.fail; p++) {
        w.part = p;
        regions_below(&w, t->parts[p].node);
    }
    if (w.fail) {
        free(w.r);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for the cache regions");
    }
    *out = w.r;
    *n = w.n;
    return 0;
}

typedef struct stop_trav {
    trav v;
    const int32_t *stop;
    cdl_skd_visit_stop fn;
    void *ctx;
} stop_trav;

static void traverse_stop(const stop_trav *s, uint32_t node)
{
    const trav *v = &s->v;
    const cdl_skd *t = v->t;
    for (;;) {
        v->cnt->nodes++;
        cdl_skd_node nd = t->nodes[node];
        uint32_t kind = (nd.b >> 2) & 3;
        if ((nd.b & 3) == 3 && kind == KIND_EMPTY)
            return;
        if (!((nd.b & 3) == 3 && kind == KIND_CULL) && !sphere_reached(v, node))
            return;
        if (s->stop[node] >= 0) {
            s->fn(s->ctx, s->stop[node]);
            return;
        }
        if ((nd.b & 3) == 3) {
            int culled = 0;
            if (kind == KIND_LEAF || !special_node(v, nd, &culled))
                return;
            node++;
            continue;
        }
        traverse_stop(s, node + 1);
        node = nd.b >> 2;
    }
}

void cdl_skd_stop_visit(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, const int32_t *stop,
                        cdl_skd_visit_stop fn, void *ctx, cdl_skd_count *cnt)
{
    if (!t->n || part >= t->nparts)
        return;
    float hmax = radius_at(r, r->len);
    stop_trav s = {{t, r, {r->o.x, r->o.y, r->o.z}, {r->d.x, r->d.y, r->d.z}, {0.0f, 0.0f, 0.0f},
                    r->len + (r->cap > 0.0f ? r->cap : 1.0f) * hmax, (flags & CDL_SKD_CULL) != 0, 0, 0, 1, 0, NULL, NULL,
                    NULL, NULL, cnt, NULL, 0, 0, NULL},
                   stop, fn, ctx};
    traverse_stop(&s, t->parts[part].node);
}

static int splat_visit(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, cdl_skd_visit fn,
                       cdl_skd_visit_range fnr, cdl_skd_visit_both fnb, void *ctx, cdl_skd_count *cnt)
{
    if (!t->n)
        return 0;
    uint32_t root = 0;
    const float *mn = t->bmin, *mx = t->bmax;
    if (part != UINT32_MAX) {
        if (part >= t->nparts)
            return 0;
        root = t->parts[part].node;
        mn = t->parts[part].bmin;
        mx = t->parts[part].bmax;
    }
    trav v = {t,
              r,
              {r->o.x, r->o.y, r->o.z},
              {r->d.x, r->d.y, r->d.z},
              {0.0f, 0.0f, 0.0f},
              0.0f,
              (flags & CDL_SKD_CULL) != 0,
              (flags & CDL_SKD_SLABS) && !fnb, /* the slabs go front to back, not in tree order */
              fnb != NULL,
              !(flags & CDL_SKD_NOIZ),
              fnb && (flags & CDL_SKD_ANY),
              fn,
              fnr,
              fnb,
              ctx,
              cnt,
              NULL,
              0,
              0,
              NULL};
    for (int a = 0; a < 3; a++)
        v.inv[a] = v.d[a] != 0.0f ? 1.0f / fabsf(v.d[a]) : 0.0f;
    /* clip [0, len + cap h(len)] by the box grown by the largest radius */
    float hmax = radius_at(r, r->len), t0 = 0.0f, t1 = r->len + (r->cap > 0.0f ? r->cap : 1.0f) * hmax;
    v.zmax = t1;
    for (int a = 0; a < 3; a++) {
        float lo = mn[a] - hmax, hi = mx[a] + hmax;
        if (v.d[a] == 0.0f) {
            if (v.o[a] < lo || v.o[a] > hi)
                return 0;
            continue;
        }
        float inv = 1.0f / v.d[a], ta = (lo - v.o[a]) * inv, tb = (hi - v.o[a]) * inv;
        if (ta > tb) {
            float tmp = ta;
            ta = tb;
            tb = tmp;
        }
        t0 = ta > t0 ? ta : t0;
        t1 = tb < t1 ? tb : t1;
    }
    if (t0 > t1)
        return 0;
    cdl_skd_went e = part != UINT32_MAX ? t->wpart[part] : t->wroot;
    if (v.slabs)
        traverse(&v, root, t0, t1, 0);
    else if ((uint64_t)(CDL_SKD_WIDTH - 1) * (t->depth + 3) >= WIDE_STACK) /* deeper than the stack */
        traverse_spheres(&v, root, 0);
    else if (e.n != CDL_SKD_WEMPTY && sphere_reached(&v, root))
        traverse_wide(&v, e);
    return 0;
}

/* cdl_skd_any_behind's leaves: the samples the frustum feeds, behind a
 * plane by more than their footprint. */
static void range_behind(trav *v, uint32_t lo, uint32_t hi)
{
    const cdl_skd *t = v->t;
    const soa16 a = soa16_of(t);
    ray16 L;
    ray16_of(&L, v->r);
    v->cnt->tested += hi - lo;
    for (uint32_t q = lo; q < hi && !v->found; q += 16) {
        uint32_t m = hi - q < 16 ? hi - q : 16;
        float w[16], iz[16];
        uint32_t feas = v->r->cap > 0.0f ? weigh16(&a, q, m, &L, 1, 0, w, iz, NULL) : weigh16(&a, q, m, &L, 0, 0, w, iz, NULL);
        for (; feas && !v->found; feas &= feas - 1) {
            uint32_t i = q + (uint32_t)__builtin_ctz(feas);
            for (int k = 0; k < v->np; k++)
                if (t->p[0][i] * v->pl[k].n[0] + t->p[1][i] * v->pl[k].n[1] + t->p[2][i] * v->pl[k].n[2] + v->pw[i] <
                    v->pl[k].c) {
                    v->found = 1;
                    break;
                }
        }
    }
}

int cdl_skd_any_behind(const cdl_skd *t, const cdl_splat_ray *r, int flags, const cdl_skd_plane *pl, int np,
                       const float *pw, cdl_skd_count *cnt)
{
    if (!t->n || np <= 0)
        return 0;
    trav v;
    memset(&v, 0, sizeof v);
    v.t = t;
    v.r = r;
    v.o[0] = r->o.x, v.o[1] = r->o.y, v.o[2] = r->o.z;
    v.d[0] = r->d.x, v.d[1] = r->d.y, v.d[2] = r->d.z;
    v.zmax = r->len + (r->cap > 0.0f ? r->cap : 1.0f) * radius_at(r, r->len);
    v.cull = (flags & CDL_SKD_CULL) != 0;
    v.cnt = cnt;
    v.pl = pl, v.np = np, v.pw = pw;
    if ((uint64_t)(CDL_SKD_WIDTH - 1) * (t->depth + 3) >= WIDE_STACK) /* deeper than the stack: every sample */
        range_behind(&v, 0, t->n);
    else if (t->wroot.n != CDL_SKD_WEMPTY && sphere_reached(&v, 0))
        traverse_behind(&v, t->wroot);
    return v.found;
}

int cdl_skd_splat_visit(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, cdl_skd_visit fn,
                        void *ctx, cdl_skd_count *cnt)
{
    return splat_visit(t, part, r, flags, fn, NULL, NULL, ctx, cnt);
}

int cdl_skd_splat_visit_range(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags,
                              cdl_skd_visit_range fn, void *ctx, cdl_skd_count *cnt)
{
    return splat_visit(t, part, r, flags, NULL, fn, NULL, ctx, cnt);
}

int cdl_skd_splat_visit_both(const cdl_skd *t, const cdl_splat_ray *r, int flags, cdl_skd_visit_both fn, void *ctx,
                             cdl_skd_count *cnt)
{
    return splat_visit(t, UINT32_MAX, r, flags, NULL, NULL, fn, ctx, cnt);
}

static void append(void *ctx, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *z)
{
    cdl_splat_hits *out = ctx;
    for (uint32_t i = 0; i < m; i++)
        if ((mask >> i & 1u) && w[i] > 0.0f && !out->fail)
            add_hit(out, first + i, w[i], z[i]);
}

int cdl_skd_splat(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, cdl_splat_hits *out)
{
    cdl_skd_count cnt = {0, 0, 0};
    cdl_skd_splat_visit(t, part, r, flags, append, out, &cnt);
    out->tested += cnt.tested;
    out->nodes += cnt.nodes;
    return out->fail ? -1 : 0;
}

int cdl_skd_splat_brute(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, cdl_splat_hits *out)
{
    uint32_t lo = 0, hi = t->n;
    if (part != UINT32_MAX) {
        if (part >= t->nparts)
            return 0;
        lo = t->parts[part].lo;
        hi = t->parts[part].hi;
    }
    out->tested += hi - lo;
    for (uint32_t i = lo; i < hi; i++) {
        float z;
        float w = cdl_splat_weight(r, cdl_v3(t->p[0][i], t->p[1][i], t->p[2][i]),
                                   cdl_v3(t->nrm[0][i], t->nrm[1][i], t->nrm[2][i]),
                                   t->two[i] > 0.0f ? CDL_SKD_TWO_SIDED : 0, &z);
        if (w > 0.0f && add_hit(out, i, w, z > 0.0f ? 1.0f / z : 0.0f))
            return -1;
    }
    return 0;
}
