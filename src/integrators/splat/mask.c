/* splat's visibility mask (Herzog et al. 2007, §8.1, proposed there as
 * future work): before a photon ray splats, the eye samples inside its
 * frustum, whatever their facing, are rasterized into a small occlusion
 * buffer in the kernel's plane: lateral offsets from the ray divided by
 * the kernel's radius at their depth (the cone's own perspective, so a
 * blocker near the narrow origin hides only what lies behind it), on at
 * most MASK_G x MASK_G cells, no finer than the samples' median
 * footprint. Each sample covers the surface patch its pixel sees (the
 * masking density: an ellipse, longer on surfaces seen at a grazing
 * angle, so a surface leaves no holes), and a cell keeps the sample
 * nearest the ray's origin. A feasible sample is then fed only if the
 * front sample of its cell does not hide it: that occluder lies nearer
 * along the ray and the sample lies behind the occluder's tangent plane
 * (seen from the ray's origin) by more than its own footprint, so a
 * surface never shadows its own neighbours. Only occluders the camera sees
 * count (they must be eye samples), as the report says; the surface the
 * ray leaves is no occluder, and a frustum holding one plane's samples
 * only needs no mask.
 *
 * Cost (issue 29): one traversal per ray, as the report rasterizes
 * "during the ray traversal": a batch of rays at a time (splat_mask_batch),
 * in parallel over the rays, each ray's traversal yields the frustum's
 * samples and the feasible ones (cdl_skd_splat_visit_both: the same
 * weights bit for bit as the traversal without masks). Most rays need no
 * buffer (mask_ray.c: one plane in the frustum, or no sample whose plane
 * has a feasible one behind it); the others rasterize and filter their
 * feasible samples right away, in two steps: first only the samples that
 * may hide one (the hiders: about a quarter of the rasterized ones on the
 * box), and the filter; only if it hides some (candidates), the rest as
 * near as the farthest front sample that hides one, and the candidates'
 * batches filtered again. A sample that is no hider hides nothing; it
 * only stands in front of hiders, so where the first step hides nothing
 * the full buffer hides nothing, and the cells of the candidates end with
 * the front samples the full buffer has: the same splats are kept. The survivors (weights, and 1 / z if the
 * occlusion test or the bandwidth AOV reads it, packed to their lanes)
 * are kept per ray, split by tree part; the batch then
 * splats part by part as without masks, each part replaying its rays'
 * kept splats in ray order, so every sample sums its splats in the same
 * order and the image is the one two traversals gave. A cell holds its
 * front sample as one 64-bit key, distance bits over the sample's index
 * (z >= 0: the float's bits order as the float), so z-min with the
 * index's tie-break is one unsigned min. On the Cornell box (global
 * light, 250000 photon rays) the kept splats of 8192 rays take about 70
 * MiB (of 4096 with 1 / z), the buffers 8 KiB per thread; a batch ends
 * in two barriers, where a thread another process holds up keeps the
 * other waiting (half as many batches: 10 % less time on a loaded
 * machine). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif
#include <omp.h>

#include "core/grow.h"
#include "integrators/splat/mask.h"
#include "integrators/splat/mask_ray.h"

/* A kept batch: its lanes' w then (if wiz) 1 / z from val[off], packed. */
typedef struct mask_rec {
    uint32_t first, keep, off;
} mask_rec;
/* A ray's kept batches in one part: rec[rec0, rec0 + n) of a worker. */
typedef struct mask_seg {
    uint32_t part, rec0, n;
} mask_seg;
typedef struct mask_pentry {
    uint32_t w, ray, rec0, n; /* worker, ray in the batch, its records */
} mask_pentry;

/* Per thread: what one ray's traversal holds, the buffer, and the kept
 * splats of the batch's rays it took. */
typedef struct mask_worker {
    mask_held *held;
    mask_feas *feas;
    mask_rec *rec;
    float *val;
    mask_seg *seg;
    uint64_t *grid; /* MASK_G^2 cells: distance bits << 32 | sample, UINT64_MAX empty */
    uint32_t *keep; /* per feasible batch its lanes the mask keeps */
    uint32_t capk, nh, caph, nf, capf, nrec, caprec, nval, capval, nseg, capseg;
    int oom;
} mask_worker;

struct splat_mask {
    uint32_t first;     /* the batch's first ray */
    int wiz;            /* 1 / z kept too (the occlusion test or the bandwidth AOV reads it) */
    float rho;          /* the eye samples' median footprint: the smallest cell worth having */
    float *pw;          /* per eye sample (tree order) its footprint, contiguous for the leaf loops */
    float *ax[6];       /* and the semi-axes of the surface patch it stands for (see prepare) */
    uint32_t npw;
    float scale;        /* the largest coordinate of the samples' box */
    mask_worker *w;
    int nw;
    uint32_t *rth;      /* per ray of the batch: the worker that took it, */
    uint32_t *rseg0, *rnseg; /* its segments */
    uint32_t *pstart, *pcur, npart; /* per part: its entries in plist, in ray order */
    mask_pentry *plist;
    uint32_t cappl;
};

uint32_t splat_mask_batch(const splat_state *s)
{
    return s->occl || s->want_bw ? SPLAT_MASK_BATCH / 2 : SPLAT_MASK_BATCH;
}

int splat_mask_alloc(splat_state *s, cdl_error *err)
{
    if (s->mask)
        return 0;
    splat_mask *m = s->mask = calloc(1, sizeof *m);
    if (m) {
        m->rth = malloc(sizeof *m->rth * SPLAT_MASK_BATCH);
        m->rseg0 = malloc(sizeof *m->rseg0 * SPLAT_MASK_BATCH);
        m->rnseg = malloc(sizeof *m->rnseg * SPLAT_MASK_BATCH);
    }
    if (!m || !m->rth || !m->rseg0 || !m->rnseg)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the visibility masks");
    return 0;
}

static void worker_free(mask_worker *w)
{
    free(w->held);
    free(w->feas);
    free(w->rec);
    free(w->val);
    free(w->seg);
    free(w->grid);
    free(w->keep);
}

void splat_mask_free(splat_state *s)
{
    splat_mask *m = s->mask;
    if (!m)
        return;
    for (int i = 0; i < m->nw; i++)
        worker_free(&m->w[i]);
    free(m->w);
    free(m->rth);
    free(m->rseg0);
    free(m->rnseg);
    free(m->pstart);
    free(m->pcur);
    free(m->plist);
    free(m->pw);
    for (int c = 0; c < 6; c++)
        free(m->ax[c]);
    free(m);
    s->mask = NULL;
}

size_t splat_mask_bytes(const splat_state *s)
{
    const splat_mask *m = s->mask;
    if (!m)
        return 0;
    size_t b = (size_t)SPLAT_MASK_BATCH * 12 + 7 * sizeof(float) * (size_t)m->npw +
               (size_t)m->cappl * sizeof(mask_pentry) + (size_t)(2 * m->npart + 1) * sizeof(uint32_t);
    for (int i = 0; i < m->nw; i++) {
        const mask_worker *w = &m->w[i];
        b += (size_t)w->caph * sizeof(mask_held) + (size_t)w->capf * sizeof(mask_feas) +
             (size_t)w->caprec * sizeof(mask_rec) + (size_t)w->capval * sizeof(float) +
             (size_t)w->capseg * sizeof(mask_seg) + (size_t)w->capk * sizeof(uint32_t) + (w->grid ? MASK_G * MASK_G * sizeof(uint64_t) : 0);
    }
    return b;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int splat_mask_prepare(splat_state *s)
{
    /* cells finer than the samples' spacing only cost clearing and
     * rasterizing: the median footprint of a strided subset bounds them */
    splat_mask *m = s->mask;
    if (m->npw < s->tree.n) {
        /* 16 lanes of padding: the leaf loops read whole batches */
        m->npw = 0;
        free(m->pw);
        m->pw = calloc((size_t)s->tree.n + 16, sizeof *m->pw);
        int ok = m->pw != NULL;
        for (int c = 0; c < 6; c++) {
            free(m->ax[c]);
            ok &= (m->ax[c] = calloc((size_t)s->tree.n + 16, sizeof *m->ax[c])) != NULL;
        }
        if (!ok)
            return CDL_ERR_SYSTEM;
        m->npw = s->tree.n;
    }
    /* a sample stands for the patch a pixel covers: a disc of radius
     * 0.6 pw across its view ray, landed on the surface: an ellipse whose
     * axis along the view is 1 / cos longer, at most 5x: a grazing
     * surface leaves holes beyond that, and longer patches widen every
     * shadow they cast (measured: 20x removed 99.9 % of the leak under a
     * plate seen edge-on, but doubled the Cornell box's direct-light
     * error) */
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->tree.n; q++) {
        const splat_eye *e = &s->eye[q];
        float r = 0.6f * e->pw, c = fabsf(cdl_dot(e->wo, e->f.n));
        float r2 = r / (c > 0.2f ? c : 0.2f);
        m->pw[q] = e->pw;
        m->ax[0][q] = r2 * e->f.t.x, m->ax[1][q] = r2 * e->f.t.y, m->ax[2][q] = r2 * e->f.t.z;
        m->ax[3][q] = r * e->f.b.x, m->ax[4][q] = r * e->f.b.y, m->ax[5][q] = r * e->f.b.z;
    }
    uint32_t n = s->tree.n < 4096 ? s->tree.n : 4096, step = n ? s->tree.n / n : 1;
    float *f = malloc(sizeof *f * (n ? n : 1));
    m->scale = 0.0f;
    for (int a = 0; a < 3; a++)
        m->scale = fmaxf(m->scale, fmaxf(fabsf(s->tree.bmin[a]), fabsf(s->tree.bmax[a])));
    m->rho = 0.0f; /* without memory: the full grid */
    if (!f)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        f[i] = m->pw[(size_t)i * step];
    qsort(f, n, sizeof *f, cmp_float);
    m->rho = n ? f[n / 2] : 0.0f;
    free(f);
    return 0;
}

/* The traversal's batches: the frustum's (occluders) and the feasible
 * ones, held until the ray's buffer is known. */
static void collect(void *ctx, uint32_t first, uint32_t m, uint32_t any, const float *z, uint32_t feasible,
                    const float *w, const float *iz)
{
    (void)m;
    mask_worker *x = ctx;
    if (any) {
        if (cdl_grow((void **)&x->held, &x->caph, x->nh + 1, sizeof *x->held)) {
            x->oom = 1;
            return;
        }
        mask_held *e = &x->held[x->nh++];
        e->first = first;
        e->mask = any;
        memcpy(e->z, z, sizeof e->z);
    }
    if (feasible) {
        if (cdl_grow((void **)&x->feas, &x->capf, x->nf + 1, sizeof *x->feas)) {
            x->oom = 1;
            return;
        }
        mask_feas *e = &x->feas[x->nf++];
        e->first = first;
        e->mask = feasible;
        memcpy(e->w, w, sizeof e->w);
        memcpy(e->iz, iz, sizeof e->iz);
    }
}

/* Packs the kept lanes of x at val (popcount(keep) floats). */
static inline void pack(float *val, uint32_t keep, const float *x)
{
#if defined(__AVX512F__)
    const __mmask16 lo = (__mmask16)((1u << __builtin_popcount(keep)) - 1u);
    _mm512_mask_storeu_ps(val, lo, _mm512_maskz_compress_ps((__mmask16)keep, _mm512_loadu_ps(x)));
#else
    for (uint32_t j = 0; keep; keep &= keep - 1, j++)
        val[j] = x[__builtin_ctz(keep)];
#endif
}

/* The inverse: 16 lanes, 0 where not kept. */
static inline void unpack(const float *val, uint32_t keep, float *x)
{
#if defined(__AVX512F__)
    const __mmask16 lo = (__mmask16)((1u << __builtin_popcount(keep)) - 1u);
    _mm512_storeu_ps(x, _mm512_maskz_expand_ps((__mmask16)keep, _mm512_maskz_loadu_ps(lo, val)));
#else
    for (uint32_t i = 0, j = 0; i < 16; i++) {
        int in = (int)(keep >> i & 1u);
        x[i] = in ? val[j] : 0.0f;
        j += (uint32_t)in;
    }
#endif
}

typedef struct build_count {
    uint64_t tested, weighed, nodes, rasterized, masks, buffers, masked;
} build_count;

/* Ray k of the batch on worker wid: one traversal, its mask if the
 * frustum holds more than one plane, and its surviving splats kept. */
static void build_ray(splat_state *s, uint32_t wid, uint32_t k, int flags, build_count *bc)
{
    splat_mask *m = s->mask;
    mask_worker *x = &m->w[wid];
    const cdl_photon_ray *r = &s->rays.r[m->first + k];
    cdl_splat_ray sr = splat_ray_of(s, r);
    cdl_skd_count cnt = {0, 0, 0};
    x->nh = x->nf = 0;
    cdl_skd_splat_visit_both(&s->tree, &sr, flags, collect, x, &cnt);
    bc->tested += cnt.tested;
    bc->weighed += cnt.weighed;
    bc->nodes += cnt.nodes;
    m->rth[k] = wid;
    m->rseg0[k] = x->nseg;
    m->rnseg[k] = 0;
    if (x->oom)
        return;
    cdl_frame f = cdl_frame_from(r->d);
    float big = fmaxf(m->scale, fmaxf(fabsf(r->o.x), fmaxf(fabsf(r->o.y), fabsf(r->o.z))));
    mask_ray mr = {&s->tree, r, m->pw, (const float *const *)m->ax, {f.t.x, f.t.y, f.t.z}, {f.b.x, f.b.y, f.b.z},
                   /* ~10x the rounding of a plane offset at the coordinates' scale */
                   1e-5f * big, 0, INT32_MIN, x->grid, 0};
    float hmax = r->h0 + r->dh * r->len;
    /* a mask if the frustum holds more than one plane, a buffer if one
     * of them may hide a feasible sample */
    if (cdl_grow((void **)&x->keep, &x->capk, x->nf, sizeof *x->keep)) {
        x->oom = 1;
        return;
    }
    uint32_t *keep = x->keep;
    for (uint32_t j = 0; j < x->nf; j++)
        keep[j] = x->feas[j].mask;
    if (hmax > 0.0f && x->nf && !splat_mask_one_plane(&mr, x->held, x->nh)) {
        bc->masks++;
        splat_mask_reach(&mr, x->feas, x->nf);
        if (splat_mask_hiders(&mr, x->held, x->nh, x->feas, x->nf)) {
            bc->buffers++;
            int g = MASK_G;
            if (2.0f * hmax < (float)g * m->rho)
                g = (int)ceilf(2.0f * hmax / m->rho);
            mr.g = g < 1 ? 1 : g;
            for (int c = 0; c < mr.g * mr.g; c++)
                x->grid[c] = UINT64_MAX;
            /* the hiders first: a sample no hider's front sample hides
             * is kept whatever the others add (they hide nothing and
             * only stand in front of hiders) */
            for (uint32_t b = 0; b < x->nh; b++)
                if (x->held[b].hide)
                    bc->rasterized += splat_mask_rasterize_lanes(&mr, &x->held[b], x->held[b].hide);
            uint32_t cand = 0, front = 0;
            for (uint32_t j = 0; j < x->nf; j++)
                cand |= x->feas[j].mask & ~(keep[j] = splat_mask_filter(&mr, &x->feas[j], &front));
            if (cand) {
                /* the buffer as it would be where a sample may stand in
                 * front of a hider that hides one (its key no larger), the
                 * candidates filtered again */
                if ((int32_t)front >= 0 && (int32_t)front < mr.reach)
                    mr.reach = (int32_t)front + 1;
                for (uint32_t b = 0; b < x->nh; b++)
                    if (x->held[b].mask & ~x->held[b].hide)
                        bc->rasterized += splat_mask_rasterize_lanes(&mr, &x->held[b], x->held[b].mask & ~x->held[b].hide);
                for (uint32_t j = 0; j < x->nf; j++)
                    if (keep[j] != x->feas[j].mask)
                        keep[j] = splat_mask_filter(&mr, &x->feas[j], &front);
            }
        }
    }
    const cdl_skd_part *parts = s->tree.parts;
    const uint32_t np = s->tree.nparts;
    uint32_t p = 0, cur = UINT32_MAX;
    for (uint32_t j = 0; j < x->nf; j++) {
        const mask_feas *fb = &x->feas[j];
        const uint32_t kj = keep[j];
        bc->masked += (uint64_t)__builtin_popcount(fb->mask & ~kj);
        if (!kj)
            continue;
        while (p + 1 < np && fb->first >= parts[p].hi)
            p++;
        uint32_t nk = (uint32_t)__builtin_popcount(kj), nv = m->wiz ? 2 * nk : nk;
        if (cdl_grow((void **)&x->rec, &x->caprec, x->nrec + 1, sizeof *x->rec) ||
            cdl_grow((void **)&x->val, &x->capval, x->nval + nv, sizeof *x->val)) {
            x->oom = 1;
            return;
        }
        if (cur == UINT32_MAX || x->seg[cur].part != p) {
            if (cdl_grow((void **)&x->seg, &x->capseg, x->nseg + 1, sizeof *x->seg)) {
                x->oom = 1;
                return;
            }
            cur = x->nseg++;
            x->seg[cur] = (mask_seg){p, x->nrec, 0};
            m->rnseg[k]++;
        }
        x->rec[x->nrec++] = (mask_rec){fb->first, kj, x->nval};
        pack(x->val + x->nval, kj, fb->w);
        if (m->wiz)
            pack(x->val + x->nval + nk, kj, fb->iz);
        x->nval += nv;
        x->seg[cur].n++;
    }
}

/* Workers for every thread, each with its buffer; their kept splats
 * emptied for a new batch. */
static int workers(splat_mask *m)
{
    int nth = omp_get_max_threads();
    if (nth > m->nw) {
        mask_worker *w = realloc(m->w, sizeof *w * (size_t)nth);
        if (!w)
            return -1;
        memset(w + m->nw, 0, sizeof *w * (size_t)(nth - m->nw));
        m->w = w;
        m->nw = nth;
    }
    for (int i = 0; i < m->nw; i++) {
        mask_worker *w = &m->w[i];
        if (!w->grid && !(w->grid = malloc(sizeof *w->grid * MASK_G * MASK_G)))
            return -1;
        w->nrec = w->nval = w->nseg = 0;
        w->oom = 0;
    }
    return 0;
}

/* Every part's entries, ray by ray (a counting sort of the segments). */
static int by_part(splat_mask *m, uint32_t nparts, uint32_t n)
{
    if (m->npart < nparts || !m->pstart) {
        free(m->pstart);
        free(m->pcur);
        m->pstart = malloc(sizeof *m->pstart * ((size_t)nparts + 1));
        m->pcur = malloc(sizeof *m->pcur * ((size_t)nparts + 1));
        m->npart = nparts;
        if (!m->pstart || !m->pcur) {
            m->npart = 0;
            return -1;
        }
    }
    memset(m->pcur, 0, sizeof *m->pcur * ((size_t)nparts + 1));
    uint32_t total = 0;
    for (uint32_t k = 0; k < n; k++) {
        const mask_seg *sg = m->w[m->rth[k]].seg + m->rseg0[k];
        for (uint32_t j = 0; j < m->rnseg[k]; j++)
            m->pcur[sg[j].part]++;
        total += m->rnseg[k];
    }
    if (cdl_grow((void **)&m->plist, &m->cappl, total, sizeof *m->plist))
        return -1;
    for (uint32_t p = 0, at = 0; p <= nparts; p++) {
        uint32_t c = p < nparts ? m->pcur[p] : 0;
        m->pstart[p] = m->pcur[p] = at;
        at += c;
    }
    for (uint32_t k = 0; k < n; k++) {
        const mask_seg *sg = m->w[m->rth[k]].seg + m->rseg0[k];
        for (uint32_t j = 0; j < m->rnseg[k]; j++)
            m->plist[m->pcur[sg[j].part]++] = (mask_pentry){m->rth[k], k, sg[j].rec0, sg[j].n};
    }
    return 0;
}

int splat_mask_build(splat_state *s, uint32_t first, uint32_t n, int flags)
{
    splat_mask *m = s->mask;
    m->first = first;
    m->wiz = splat_mask_batch(s) < SPLAT_MASK_BATCH;
    if (workers(m))
        return CDL_ERR_SYSTEM;
    build_count bc = {0, 0, 0, 0, 0, 0, 0};
#pragma omp parallel
    {
        build_count c = {0, 0, 0, 0, 0, 0, 0};
        uint32_t wid = (uint32_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 16)
        for (uint32_t k = 0; k < n; k++)
            build_ray(s, wid, k, flags, &c);
#pragma omp critical
        {
            bc.tested += c.tested, bc.weighed += c.weighed, bc.nodes += c.nodes;
            bc.rasterized += c.rasterized, bc.masks += c.masks, bc.buffers += c.buffers, bc.masked += c.masked;
        }
    }
    for (int i = 0; i < m->nw; i++)
        if (m->w[i].oom)
            return CDL_ERR_SYSTEM;
    if (by_part(m, s->tree.nparts, n))
        return CDL_ERR_SYSTEM;
    s->st.mask_tested += bc.tested;
    s->st.tested += bc.weighed;
    s->st.nodes += bc.nodes;
    s->st.rasterized += bc.rasterized;
    s->st.mask_rays += bc.masks;
    s->st.mask_buffers += bc.buffers;
    s->st.masked += bc.masked;
    return 0;
}

void splat_mask_replay(const splat_state *s, uint32_t part, splat_mask_fn fn, void *ctx)
{
    const splat_mask *m = s->mask;
    if (part >= m->npart)
        return;
    float w[16], iz[16] = {0.0f}; /* iz stays 0 where nothing reads it */
    for (uint32_t e = m->pstart[part]; e < m->pstart[part + 1]; e++) {
        const mask_pentry *pe = &m->plist[e];
        const mask_worker *x = &m->w[pe->w];
        for (uint32_t j = pe->rec0; j < pe->rec0 + pe->n; j++) {
            const mask_rec *rc = &x->rec[j];
            unpack(x->val + rc->off, rc->keep, w);
            if (m->wiz)
                unpack(x->val + rc->off + (uint32_t)__builtin_popcount(rc->keep), rc->keep, iz);
            fn(ctx, m->first + pe->ray, rc->first, rc->keep, w, iz);
        }
    }
}
