/* gkde: generalized kernel density estimation (Bekaert, Slusallek, Cools,
 * Havran & Seidel 2003, "A custom designed density estimator for light
 * transport"). Each pass is one of the report's steps (§5):
 *
 * 1. eye paths (--eye-paths per pixel) and light paths (--light-paths per
 *    step) from the shared subpath tracer, all vertices kept;
 * 2. every light vertex x_k whose parent x_{k-1} is not specular gets a
 *    footprint sphere of radius R_k = h / sqrt(p(x_k)) + R_{k-1} (eq. 7);
 * 3. candidate link counting: a kd-tree over the eye vertices answers one
 *    ball query per footprint; each eye vertex sums the acceptance
 *    weights 1 / (R^2 cos) of the footprints it lies in (eq. 10);
 * 4. trial linking: each eye vertex keeps about M / P_vis of its
 *    candidates by stratified sampling of those weights (all of them when
 *    it has fewer), P_vis its pixel's unoccluded fraction in earlier steps;
 * 5. one bundle of shadow rays from x_{k-1} to the eye vertices a
 *    footprint keeps; unoccluded links score eq. 8 with the strategy
 *    weights of eq. 9 (transport/gkde_link.c), divided by the acceptance
 *    probability;
 * 6. h is calibrated in the first step so that an eye vertex lies in about
 *    M first-bounce footprints (the expected count is pi N h^2 with eq. 7's
 *    radii, so h = sqrt(M / (pi N)) corrected twice by the measured count).
 *
 * Determinism whatever the thread count: the eye vertices are split into
 * kd subtrees that one thread owns, and each subtree meets the footprints
 * in light-vertex order, so sums and the stratified draws never depend on
 * scheduling. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "core/rng.h"
#include "integrators/integrator.h"
#include "spatial/pointkd.h"
#include "transport/gkde_link.h"
#include "transport/subpath.h"

#define LIGHT_CHUNK 1024
#define SEG_MAX_DEPTH 10 /* at most 2^10 subtrees */
#define SEG_MIN 256
#define MAX_BUNDLE 4096 /* links per footprint and subtree traced at once */

/* A part of the eye points one thread owns: a kd subtree, plus the
 * points of the nodes above it whose right subtree starts here. */
typedef struct seg {
    uint32_t lo, hi;
    uint32_t extra[SEG_MAX_DEPTH], nextra;
    float bmin[3], bmax[3];
} seg;

typedef struct gkde_stats {
    double t_eye, t_light, t_count, t_link, t_rays, t_score, t_total;
    double candidates, trials, unoccluded, points; /* summed over steps */
    uint32_t steps;
    size_t peak_bytes;
} gkde_stats;

typedef struct gkde_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    uint32_t n_light, eye_paths, M;
    float h, r_cap;
    int have_h;
    cdl_vertex_store lvs, evs;
    cdl_vertex_store *chunks; /* per row (eye) or per LIGHT_CHUNK paths (light), reused */
    uint32_t **chunk_pix;
    uint32_t nchunks;
    uint32_t *epix;   /* pixel of each eye vertex */
    float *radius;    /* footprint radius of each light vertex */
    uint32_t *lv;     /* light vertices with a footprint */
    uint32_t nlv;
    float *pts;       /* usable eye vertices in tree order: x, y, z, store index bits */
    uint32_t npts;
    cdl_kdtree kd;
    seg *segs;
    uint32_t nseg;
    /* per part: the candidates of stage 3 as records (light vertex list
     * index, count, points), replayed by stage 4 without a second query */
    struct rec_buf {
        uint32_t *v;
        size_t n, cap;
        int fail;
    } *rec;
    uint32_t nrec;
    /* per point */
    uint32_t *count, *tested, *unocc;
    uint16_t *pdepth; /* eye depth, in tree order (the candidate test reads it) */
    double *wsum, *scale, *cum;
    cdl_vec3 *acc;
    /* per pixel: tested and unoccluded links in earlier steps, by eye depth 1, 2, 3+ */
    uint32_t *pv;
    cdl_vec3 *pixsum;
    size_t rec_bytes;
    cdl_gkde_ctx g;
    gkde_stats st;
} gkde_state;

static uint32_t point_vertex(const gkde_state *s, uint32_t q)
{
    uint32_t e;
    memcpy(&e, &s->pts[4 * (size_t)q + 3], sizeof e);
    return e;
}

static int gkde_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    gkde_state *s = self;
    s->scene = scene;
    s->opt = *opt;
    s->walk.maxdepth = opt->maxdepth;
    s->walk.rr_depth = opt->rr_depth;
    if (opt->light_paths == CDL_LIGHT_PATHS_PER_SAMPLE)
        return cdl_error_set(err, CDL_ERR_USAGE, "--light-paths", 0,
                             "gkde traces N light paths per step for all pixels: give a number");
    if (opt->interleave > 1)
        return cdl_error_set(err, CDL_ERR_USAGE, "--interleave", 0, "gkde does not interleave light paths");
    s->n_light = opt->light_paths ? opt->light_paths : 100000;
    s->eye_paths = opt->gkde.eye_paths ? opt->gkde.eye_paths : 1;
    s->M = opt->gkde.links ? opt->gkde.links : 10;
    s->h = opt->gkde.bandwidth;
    s->have_h = s->h > 0.0f;
    if (!scene->nlights)
        return cdl_error_set(err, CDL_ERR_INPUT, scene->path, 0, "gkde: the scene has no lights");
    for (uint32_t i = 0; i < scene->nlights; i++)
        if (scene->lights[i].type == CDL_LIGHT_DISTANT || scene->lights[i].type == CDL_LIGHT_INFINITE)
            return cdl_error_set(err, CDL_ERR_INPUT, scene->path, 0,
                                 "gkde does not support distant or infinite lights yet");
    size_t npix = (size_t)opt->camera.width * (size_t)opt->camera.height;
    s->pv = calloc(npix * 6, sizeof *s->pv);
    s->pixsum = malloc(npix * sizeof *s->pixsum);
    if (!s->pv || !s->pixsum)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    s->g.cx = (cdl_connect_ctx){scene, &s->opt.camera, CDL_MIS_BALANCE, 0.0f, NULL, 0};
    s->g.n_light = (float)s->n_light;
    return 0;
}

/* Chunk stores, reused across steps. */
static int chunks_reserve(gkde_state *s, uint32_t n, cdl_error *err)
{
    if (n <= s->nchunks)
        return 0;
    cdl_vertex_store *c = realloc(s->chunks, n * sizeof *c);
    uint32_t **p = c ? realloc(s->chunk_pix, n * sizeof *p) : NULL;
    if (c)
        s->chunks = c;
    if (p)
        s->chunk_pix = p;
    if (!c || !p)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    for (uint32_t i = s->nchunks; i < n; i++) {
        cdl_vs_init(&s->chunks[i]);
        s->chunk_pix[i] = NULL;
    }
    s->nchunks = n;
    return 0;
}

static size_t stored_bytes(const gkde_state *s)
{
    return s->rec_bytes + cdl_vs_bytes(&s->lvs) + cdl_vs_bytes(&s->evs) + (size_t)s->evs.cap * sizeof *s->epix +
           (size_t)s->lvs.cap * (sizeof *s->radius + sizeof *s->lv) +
           (size_t)s->npts * (4 * sizeof(float) + 5 + 3 * sizeof(uint32_t) + 3 * sizeof(double) +
                              sizeof(cdl_vec3));
}

static int check_memory(gkde_state *s, cdl_error *err)
{
    size_t b = stored_bytes(s);
    if (b > s->st.peak_bytes)
        s->st.peak_bytes = b;
    if (b > (size_t)s->opt.gkde.max_mib << 20)
        return cdl_error_set(err, CDL_ERR_USAGE, "--path-memory", 0,
                             "the stored paths need %.0f MiB, more than the cap of %u MiB: lower "
                             "--light-paths, --eye-paths or the resolution, or raise the cap",
                             (double)b / 1048576.0, s->opt.gkde.max_mib);
    return 0;
}

/* Eye paths of every pixel, one row per chunk, joined in row order. */
static int trace_eyes(gkde_state *s, uint32_t pass, uint64_t *rays, cdl_error *err)
{
    const cdl_camera *cam = &s->opt.camera;
    int W = cam->width, H = cam->height;
    uint32_t room = (uint32_t)s->opt.maxdepth + 2;
    if (chunks_reserve(s, (uint32_t)H, err))
        return err->code;
    int fail = 0;
    uint64_t total = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : total)
    for (int y = 0; y < H; y++) {
        cdl_vertex_store *vs = &s->chunks[y];
        cdl_vs_clear(vs);
        uint64_t r = 0;
        for (int x = 0; x < W && !fail; x++) {
            uint64_t pix = (uint64_t)y * (uint64_t)W + (uint64_t)x;
            for (uint32_t e = 0; e < s->eye_paths; e++) {
                uint32_t n0 = vs->n;
                if (cdl_vs_reserve(vs, n0 + room, NULL)) {
#pragma omp atomic write
                    fail = 1;
                    break;
                }
                uint32_t *pp = realloc(s->chunk_pix[y], sizeof(uint32_t) * vs->cap);
                if (!pp) {
#pragma omp atomic write
                    fail = 1;
                    break;
                }
                s->chunk_pix[y] = pp;
                cdl_sampler smp;
                float jx, jy;
                cdl_sampler_start(&smp, s->opt.sampler, s->opt.seed, pix * s->eye_paths + e, pass);
                cdl_sampler_2d(&smp, &jx, &jy);
                cdl_trace_eye_subpath(s->scene, cam, (float)x + jx, (float)y + jy, &s->walk, &smp, vs, &r);
                for (uint32_t i = n0; i < vs->n; i++)
                    pp[i] = (uint32_t)pix;
            }
        }
        total += r;
    }
    *rays += total;
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory for eye paths");
    cdl_vs_clear(&s->evs);
    for (int y = 0; y < H; y++) {
        uint32_t n0 = s->evs.n;
        int rc = cdl_vs_append(&s->evs, &s->chunks[y], err);
        if (rc)
            return rc;
        uint32_t *ep = realloc(s->epix, sizeof(uint32_t) * s->evs.cap);
        if (!ep)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
        s->epix = ep;
        memcpy(s->epix + n0, s->chunk_pix[y], sizeof(uint32_t) * s->chunks[y].n);
    }
    return 0;
}

static int trace_lights(gkde_state *s, uint32_t pass, uint64_t *rays, cdl_error *err)
{
    uint32_t nc = (s->n_light + LIGHT_CHUNK - 1) / LIGHT_CHUNK;
    uint32_t room = (uint32_t)s->opt.maxdepth + 2;
    if (chunks_reserve(s, nc, err))
        return err->code;
    int fail = 0;
    uint64_t total = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : total)
    for (uint32_t c = 0; c < nc; c++) {
        cdl_vertex_store *vs = &s->chunks[c];
        cdl_vs_clear(vs);
        uint64_t r = 0;
        uint32_t end = (c + 1) * LIGHT_CHUNK < s->n_light ? (c + 1) * LIGHT_CHUNK : s->n_light;
        for (uint32_t i = c * LIGHT_CHUNK; i < end; i++) {
            if (cdl_vs_reserve(vs, vs->n + room, NULL)) {
#pragma omp atomic write
                fail = 1;
                break;
            }
            cdl_sampler smp;
            cdl_sampler_start(&smp, s->opt.sampler, s->opt.seed ^ 0x5bd1e995u, (uint64_t)i, pass);
            cdl_trace_light_subpath(s->scene, &s->walk, &smp, vs, &r);
        }
        total += r;
    }
    *rays += total;
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory for light paths");
    cdl_vs_clear(&s->lvs);
    for (uint32_t c = 0; c < nc; c++) {
        int rc = cdl_vs_append(&s->lvs, &s->chunks[c], err);
        if (rc)
            return rc;
    }
    return 0;
}

/* Footprint radii (eq. 7) for bandwidth h, and the light vertices that
 * can link: x_k past the start whose parent is not specular, with a
 * bounce left for the eye path. */
static int footprints(gkde_state *s, float h, cdl_error *err)
{
    const cdl_vertex_store *l = &s->lvs;
    float *r = realloc(s->radius, sizeof(float) * (l->n ? l->n : 1));
    uint32_t *lv = r ? realloc(s->lv, sizeof(uint32_t) * (l->n ? l->n : 1)) : NULL;
    if (r)
        s->radius = r;
    if (lv)
        s->lv = lv;
    if (!r || !lv)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    s->nlv = 0;
    for (uint32_t i = 0; i < l->n; i++) {
        int32_t p = l->parent[i];
        r[i] = p < 0 ? 0.0f : cdl_footprint_radius(h, l->pdf_fwd[i], r[p], s->r_cap);
        if (p >= 0 && !(l->flags[p] & CDL_V_DELTA) && l->depth[i] <= s->opt.maxdepth && r[i] > 0.0f &&
            isfinite(r[i]))
            lv[s->nlv++] = i;
    }
    return 0;
}

static void grow_box(seg *g, const float *p)
{
    for (int a = 0; a < 3; a++) {
        g->bmin[a] = p[a] < g->bmin[a] ? p[a] : g->bmin[a];
        g->bmax[a] = p[a] > g->bmax[a] ? p[a] : g->bmax[a];
    }
}

static void add_seg(gkde_state *s, uint32_t lo, uint32_t hi, const uint32_t *extra, uint32_t nextra)
{
    seg *g = &s->segs[s->nseg++];
    g->lo = lo;
    g->hi = hi;
    g->nextra = nextra;
    for (int a = 0; a < 3; a++) {
        g->bmin[a] = INFINITY;
        g->bmax[a] = -INFINITY;
    }
    for (uint32_t q = lo; q < hi; q++)
        grow_box(g, &s->pts[4 * (size_t)q]);
    for (uint32_t i = 0; i < nextra; i++) {
        g->extra[i] = extra[i];
        grow_box(g, &s->pts[4 * (size_t)extra[i]]);
    }
}

/* Subtrees of [lo, hi) down to `depth` levels; the node points above
 * them join the first subtree after them (pend: those waiting). */
static void make_segs(gkde_state *s, uint32_t lo, uint32_t hi, int depth, const uint32_t *pend,
                      uint32_t npend)
{
    if (lo >= hi)
        return;
    if (hi - lo <= SEG_MIN || depth == 0) {
        add_seg(s, lo, hi, pend, npend);
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    make_segs(s, lo, mid, depth - 1, pend, npend);
    make_segs(s, mid + 1, hi, depth - 1, &mid, 1);
}

/* The points of g within distance sqrt(r2) of c, subtree first. */
static void seg_ball(const gkde_state *s, const seg *g, cdl_vec3 c, float r2, cdl_kd_visit fn, void *ctx)
{
    cdl_kd_ball_range(&s->kd, g->lo, g->hi, c, r2, fn, ctx);
    for (uint32_t i = 0; i < g->nextra; i++) {
        const float *p = &s->pts[4 * (size_t)g->extra[i]];
        float dx = p[0] - c.x, dy = p[1] - c.y, dz = p[2] - c.z, d2 = dx * dx + dy * dy + dz * dz;
        if (d2 <= r2)
            fn(ctx, g->extra[i], d2);
    }
}

static int sphere_meets(const seg *g, cdl_vec3 c, float r)
{
    float p[3] = {c.x, c.y, c.z}, d2 = 0.0f;
    for (int a = 0; a < 3; a++) {
        float d = p[a] < g->bmin[a] ? g->bmin[a] - p[a] : p[a] > g->bmax[a] ? p[a] - g->bmax[a] : 0.0f;
        d2 += d * d;
    }
    return d2 <= r * r;
}

/* The kd-tree over the eye vertices that can be linked, its points moved
 * into tree order, and the subtrees threads own. */
static int build_points(gkde_state *s, cdl_error *err)
{
    const cdl_vertex_store *e = &s->evs;
    uint32_t n = 0;
    for (uint32_t i = 0; i < e->n; i++)
        n += !(e->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA)) && e->depth[i] <= s->opt.maxdepth;
    float *pts = malloc(sizeof(float) * 4 * (n ? n : 1));
    if (!pts)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    n = 0;
    for (uint32_t i = 0; i < e->n; i++) {
        if ((e->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA)) || e->depth[i] > s->opt.maxdepth)
            continue;
        pts[4 * (size_t)n] = e->p[i].x;
        pts[4 * (size_t)n + 1] = e->p[i].y;
        pts[4 * (size_t)n + 2] = e->p[i].z;
        memcpy(&pts[4 * (size_t)n + 3], &i, sizeof i);
        n++;
    }
    cdl_kd_free(&s->kd);
    free(s->pts);
    s->pts = NULL;
    s->npts = 0;
    if (cdl_kd_build(&s->kd, pts, 4, n, err)) {
        free(pts);
        return err->code;
    }
    float *sorted = malloc(sizeof(float) * 4 * (n ? n : 1));
    if (!sorted) {
        free(pts);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    }
    for (uint32_t q = 0; q < n; q++)
        memcpy(&sorted[4 * (size_t)q], &pts[4 * (size_t)s->kd.idx[q]], 4 * sizeof(float));
    free(pts);
    s->pts = sorted;
    s->npts = n;
    s->kd.pts = sorted;
    cdl_kd_make_identity(&s->kd);
#define GROW(f)                                                                                    \
    {                                                                                              \
        void *p_ = realloc(s->f, sizeof *s->f * (n ? n : 1));                                      \
        if (!p_)                                                                                   \
            return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");                \
        s->f = p_;                                                                                 \
    }
    GROW(count) GROW(tested) GROW(unocc) GROW(wsum) GROW(scale) GROW(cum) GROW(acc) GROW(pdepth)
#undef GROW
    for (uint32_t q = 0; q < n; q++)
        s->pdepth[q] = s->evs.depth[point_vertex(s, q)];
    free(s->segs);
    /* about four parts per thread; results do not depend on the split */
    int depth = 1;
    while (depth < SEG_MAX_DEPTH && (1 << depth) < 4 * omp_get_max_threads())
        depth++;
    s->segs = malloc(sizeof(seg) << depth);
    if (!s->segs)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    s->nseg = 0;
    make_segs(s, 0, n, depth, NULL, 0);
    if (s->nseg > s->nrec) {
        struct rec_buf *r = realloc(s->rec, sizeof *r * s->nseg);
        if (!r)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
        memset(r + s->nrec, 0, sizeof *r * (s->nseg - s->nrec));
        s->rec = r;
        s->nrec = s->nseg;
    }
    return 0;
}

static void count_only(void *ctx, uint32_t q, float d2)
{
    (void)ctx, (void)q, (void)d2;
}

/* Mean number of first-bounce footprints (radius h / sqrt(p(x_1))) an eye
 * point lies in. */
static double overlaps(const gkde_state *s, float h, float cap_unit)
{
    const cdl_vertex_store *l = &s->lvs;
    uint64_t total = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : total)
    for (int64_t i = 0; i < (int64_t)l->n; i++) {
        if (l->depth[i] != 1 || !(l->pdf_fwd[i] > 0.0f))
            continue;
        float u = 1.0f / sqrtf(l->pdf_fwd[i]), r = h * (u < cap_unit ? u : cap_unit);
        total += cdl_kd_ball(&s->kd, l->p[i], r * r, count_only, NULL);
    }
    return s->npts ? (double)total / (double)s->npts : 0.0;
}

static void calibrate(gkde_state *s, float cap_unit)
{
    double M = (double)s->M, h = sqrt(M / (CDL_PI * (double)s->n_light));
    for (int it = 0, good = 0; it < 8 && good < 2; it++) {
        double c = overlaps(s, (float)h, cap_unit);
        if (!(c > 0.0)) {
            h *= 4.0;
            continue;
        }
        h *= sqrt(M / c); /* counts grow as h^2 on surfaces */
        good++;
    }
    s->h = (float)h;
    s->have_h = 1;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The footprint cap in units of h: --footprint-cap times the median of
 * 1 / sqrt(p(x_1)), so that the cap is that many median first-bounce radii.
 * Eq. 7 grows footprints by R_1 or so at every bounce; deep ones then
 * cover hundreds of eye vertices to be counted, of which eq. 10 keeps
 * almost none, and their disc normalization is the worst. */
static float cap_unit(const gkde_state *s)
{
    float f = s->opt.gkde.footprint_cap;
    const cdl_vertex_store *l = &s->lvs;
    uint32_t n = 0;
    for (uint32_t i = 0; i < l->n; i++)
        n += l->depth[i] == 1 && l->pdf_fwd[i] > 0.0f;
    float *r = n && f > 0.0f ? malloc(sizeof(float) * n) : NULL;
    if (!r)
        return INFINITY;
    n = 0;
    for (uint32_t i = 0; i < l->n; i++)
        if (l->depth[i] == 1 && l->pdf_fwd[i] > 0.0f)
            r[n++] = 1.0f / sqrtf(l->pdf_fwd[i]);
    qsort(r, n, sizeof *r, cmp_float);
    float u = f * r[n / 2];
    free(r);
    return u;
}

static float accept_weight(const gkde_state *s, uint32_t xk)
{
    const cdl_vertex_store *l = &s->lvs;
    float R = s->radius[xk];
    float c = cdl_maxf(fabsf(cdl_dot(l->ng[xk], l->wi[xk])), 1e-3f);
    return 1.0f / (R * R * c);
}

typedef struct count_ctx {
    gkde_state *s;
    double a;
    int max_eye_depth;
    struct rec_buf *r;
} count_ctx;

static int rec_push(struct rec_buf *r, uint32_t v)
{
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 1 << 16;
        uint32_t *p = realloc(r->v, cap * sizeof *p);
        if (!p) {
            r->fail = 1;
            return -1;
        }
        r->v = p;
        r->cap = cap;
    }
    r->v[r->n++] = v;
    return 0;
}

static void count_cb(void *ctx, uint32_t q, float d2)
{
    (void)d2;
    count_ctx *c = ctx;
    gkde_state *s = c->s;
    if ((int)s->pdepth[q] > c->max_eye_depth || rec_push(c->r, q))
        return;
    s->count[q]++;
    s->wsum[q] += c->a;
}

typedef struct bundle {
    cdl_gkde_link_state ls[MAX_BUNDLE];
    cdl_vec3 o[MAX_BUNDLE], d[MAX_BUNDLE], c[MAX_BUNDLE];
    float t[MAX_BUNDLE];
    uint32_t q[MAX_BUNDLE];
    uint8_t blocked[MAX_BUNDLE];
} bundle;

typedef struct link_ctx {
    gkde_state *s;
    double a;
    uint32_t n, q[MAX_BUNDLE];
    float w[MAX_BUNDLE];
    uint64_t trials;
    uint32_t xk;
    bundle *b;
    double t_score, t_rays;
} link_ctx;

static void score_links(gkde_state *s, link_ctx *lc);

/* Stage 4 for candidate q of the current footprint: its stratified draws. */
static void link_point(link_ctx *c, uint32_t q)
{
    gkde_state *s = c->s;
    float w = 1.0f;
    if (s->scale[q] > 0.0) {
        cdl_strat st = {s->scale[q], s->cum[q]};
        uint32_t k = cdl_strat_next(&st, c->a);
        s->cum[q] = st.cum;
        if (!k)
            return;
        w = (float)((double)k / (c->a * s->scale[q])); /* drawn k times, expected a m / W */
    }
    if (c->n == MAX_BUNDLE) {
        score_links(s, c);
        c->n = 0;
    }
    c->q[c->n] = q;
    c->w[c->n] = w;
    c->n++;
    c->trials++;
}

static void score_links(gkde_state *s, link_ctx *lc)
{
    const cdl_vertex_store *l = &s->lvs, *e = &s->evs;
    uint32_t xk = lc->xk;
    bundle *b = lc->b;
    double t0 = cdl_time_now();
    uint32_t xp = (uint32_t)l->parent[xk], nb = 0;
    cdl_vec3 px = l->p[xp];
    int point = (l->flags[xp] & CDL_V_DELTA_LIGHT) != 0;
    uint32_t skip = UINT32_MAX;
    if (l->flags[xp] & CDL_V_LIGHT) {
        const cdl_light *li = &s->scene->lights[l->light[xp]];
        if (li->type == CDL_LIGHT_SPHERE)
            skip = li->prim;
    }
    cdl_gkde_parent par;
    cdl_gkde_parent_init(&s->g, xk, &par);
    for (uint32_t i = 0; i < lc->n; i++) {
        uint32_t q = lc->q[i], y = point_vertex(s, q);
        cdl_vec3 c = cdl_gkde_link(&s->g, &par, y, &b->ls[nb]);
        if (cdl_is_black(c))
            continue;
        cdl_vec3 d = cdl_sub(e->p[y], px);
        cdl_vec3 o = point ? px : cdl_offset(s->scene, px, l->ng[xp], d);
        cdl_vec3 end = cdl_offset(s->scene, e->p[y], e->ng[y], cdl_neg(d));
        cdl_vec3 de = cdl_sub(end, o);
        float len = cdl_length(de);
        if (!(len > 0.0f))
            continue;
        b->o[nb] = o;
        b->d[nb] = cdl_scale(de, 1.0f / len);
        b->t[nb] = len;
        b->c[nb] = cdl_scale(c, lc->w[i]);
        b->q[nb] = q;
        nb++;
    }
    double t1 = cdl_time_now();
    lc->t_score += t1 - t0;
    if (!nb)
        return;
    if (s->opt.single_shadow_rays) /* --shadow-rays single: for comparison */
        for (uint32_t i = 0; i < nb; i++)
            b->blocked[i] = (uint8_t)cdl_occluded_skip(s->scene, b->o[i], b->d[i], b->t[i], skip);
    else
        cdl_occluded_bundle(s->scene, nb, b->o, b->d, b->t, skip, b->blocked);
    double t2 = cdl_time_now();
    lc->t_rays += t2 - t1;
    /* the strategy weights of the links that carry light */
    for (uint32_t i = 0; i < nb; i++) {
        uint32_t q = b->q[i];
        s->tested[q]++;
        if (!b->blocked[i]) {
            s->unocc[q]++;
            s->acc[q] = cdl_add(s->acc[q], cdl_scale(b->c[i], cdl_gkde_link_weight(&s->g, &par, &b->ls[i])));
        }
    }
    lc->t_score += cdl_time_now() - t2;
}

static uint32_t pv_bucket(const gkde_state *s, uint32_t y)
{
    uint32_t d = s->evs.depth[y];
    return 6 * s->epix[y] + 2 * (d >= 3 ? 2 : d - 1);
}

/* Stages 3 to 5 over the subtrees; returns the shadow rays traced. */
static uint64_t link_all(gkde_state *s, uint32_t pass)
{
    uint32_t n = s->npts;
    double M = (double)s->M;
    /* stage 3: candidates */
    double t0 = cdl_time_now();
#pragma omp parallel for schedule(dynamic, 1)
    for (uint32_t g = 0; g < s->nseg; g++) {
        const seg *sg = &s->segs[g];
        for (uint32_t q = sg->lo; q < sg->hi; q++) {
            s->count[q] = 0;
            s->wsum[q] = 0.0;
        }
        for (uint32_t i = 0; i < sg->nextra; i++) {
            s->count[sg->extra[i]] = 0;
            s->wsum[sg->extra[i]] = 0.0;
        }
        struct rec_buf *r = &s->rec[g];
        r->n = 0;
        r->fail = 0;
        count_ctx c = {s, 0.0, 0, r};
        for (uint32_t a = 0; a < s->nlv && !r->fail; a++) {
            uint32_t xk = s->lv[a];
            float R = s->radius[xk];
            if (!sphere_meets(sg, s->lvs.p[xk], R))
                continue;
            c.a = accept_weight(s, xk);
            c.max_eye_depth = s->opt.maxdepth - (int)s->lvs.depth[xk] + 1;
            size_t at = r->n;
            if (rec_push(r, a) || rec_push(r, 0))
                break;
            seg_ball(s, sg, s->lvs.p[xk], R * R, count_cb, &c);
            if (r->n == at + 2)
                r->n = at; /* none */
            else
                r->v[at + 1] = (uint32_t)(r->n - at - 2);
        }
    }
    size_t rec_bytes = 0;
    for (uint32_t g = 0; g < s->nseg; g++) {
        if (s->rec[g].fail)
            return UINT64_MAX;
        rec_bytes += s->rec[g].cap * sizeof(uint32_t);
    }
    s->rec_bytes = rec_bytes;
    /* stage 4's plan: M / P_vis draws, or every candidate */
    double cand = 0.0;
    for (uint32_t q = 0; q < n; q++) {
        uint32_t y = point_vertex(s, q);
        const uint32_t *pv = &s->pv[pv_bucket(s, y)];
        double pvis = ((double)pv[1] + 1.0) / ((double)pv[0] + 2.0), m = M / pvis;
        cand += s->count[q];
        s->scale[q] = (double)s->count[q] > m ? m / s->wsum[q] : 0.0;
        uint64_t h = cdl_mix64(s->opt.seed * 0x9e3779b97f4a7c15ULL ^ cdl_mix64(((uint64_t)pass << 32) ^ y));
        s->cum[q] = (double)(h >> 11) * 0x1.0p-53;
        s->tested[q] = s->unocc[q] = 0;
        s->acc[q] = cdl_v3(0.0f, 0.0f, 0.0f);
    }
    double t1 = cdl_time_now();
    s->st.t_count += t1 - t0;
    s->st.candidates += cand;
    /* stages 4 and 5: trial links, shadow-ray bundles, scores */
    double t_link = 0.0, t_rays = 0.0, t_score = 0.0;
    uint64_t trials = 0, rays = 0;
#pragma omp parallel reduction(+ : t_link, t_rays, t_score, trials, rays)
    {
        link_ctx *lc = malloc(sizeof *lc);
        bundle *b = malloc(sizeof *b);
#pragma omp for schedule(dynamic, 1)
        for (uint32_t g = 0; g < s->nseg; g++) {
            if (!lc || !b || cdl_cancel)
                continue;
            const seg *sg = &s->segs[g];
            lc->s = s;
            lc->trials = 0;
            lc->b = b;
            lc->t_score = lc->t_rays = 0.0;
            double ta = cdl_time_now();
            const struct rec_buf *r = &s->rec[g];
            for (size_t i = 0; i < r->n;) {
                uint32_t xk = s->lv[r->v[i]], c = r->v[i + 1];
                const uint32_t *qs = &r->v[i + 2];
                i += 2 + (size_t)c;
                lc->a = accept_weight(s, xk);
                lc->n = 0;
                lc->xk = xk;
                for (uint32_t j = 0; j < c; j++)
                    link_point(lc, qs[j]);
                if (lc->n)
                    score_links(s, lc);
            }
            t_link += cdl_time_now() - ta - lc->t_score - lc->t_rays;
            t_score += lc->t_score;
            t_rays += lc->t_rays;
            trials += lc->trials;
            for (uint32_t q = sg->lo; q < sg->hi; q++)
                rays += s->tested[q];
            for (uint32_t i = 0; i < sg->nextra; i++)
                rays += s->tested[sg->extra[i]];
        }
        free(lc);
        free(b);
    }
    s->st.t_link += t_link;
    s->st.t_rays += t_rays;
    s->st.t_score += t_score;
    s->st.trials += (double)trials;
    return rays;
}

static int gkde_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    gkde_state *s = self;
    double t0 = cdl_time_now();
    int rc = trace_eyes(s, pass, &film->rays, err);
    double t1 = cdl_time_now();
    if (!rc)
        rc = trace_lights(s, pass, &film->rays, err);
    double t2 = cdl_time_now();
    s->st.t_eye += t1 - t0;
    s->st.t_light += t2 - t1;
    if (!rc)
        rc = build_points(s, err);
    if (!rc)
        rc = check_memory(s, err);
    if (rc || cdl_cancel)
        return rc;
    if (!(s->r_cap > 0.0f)) { /* the first step fixes h and the cap */
        float u = cap_unit(s);
        if (!s->have_h)
            calibrate(s, u);
        s->r_cap = s->h * u;
    }
    s->g.h = s->h;
    s->g.r_cap = s->r_cap;
    rc = footprints(s, s->h, err);
    if (rc)
        return rc;
    s->g.lvs = &s->lvs;
    s->g.evs = &s->evs;
    s->g.radius = s->radius;
    s->st.t_count += cdl_time_now() - t2;
    uint64_t lr = link_all(s, pass);
    if (lr == UINT64_MAX)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory for candidate links");
    film->rays += lr;
    rc = check_memory(s, err);
    if (rc)
        return rc;
    if (cdl_cancel)
        return 0; /* an interrupted step adds nothing */
    /* the step's image: links per eye vertex, emitters the eye paths hit */
    const cdl_camera *cam = &s->opt.camera;
    size_t npix = (size_t)cam->width * (size_t)cam->height;
    memset(s->pixsum, 0, npix * sizeof *s->pixsum);
    double unocc = 0.0;
    for (uint32_t q = 0; q < s->npts; q++) {
        uint32_t y = point_vertex(s, q);
        s->pixsum[s->epix[y]] = cdl_add(s->pixsum[s->epix[y]], s->acc[q]);
        uint32_t *pv = &s->pv[pv_bucket(s, y)];
        pv[0] += s->tested[q];
        pv[1] += s->unocc[q];
        unocc += s->unocc[q];
    }
    for (uint32_t y = 0; y < s->evs.n; y++)
        if (s->evs.flags[y] & CDL_V_EMITTER)
            s->pixsum[s->epix[y]] = cdl_add(s->pixsum[s->epix[y]], cdl_gkde_emitted(&s->g, y));
    float inv = 1.0f / (float)s->eye_paths;
    uint64_t bad = 0;
    for (size_t p = 0; p < npix; p++)
        bad += (uint64_t)cdl_film_add(film, (int)(p % (size_t)cam->width), (int)(p / (size_t)cam->width),
                                      cdl_scale(s->pixsum[p], inv));
    film->nonfinite += bad;
    s->st.unoccluded += unocc;
    s->st.points += s->npts;
    s->st.steps++;
    s->st.t_total += cdl_time_now() - t0;
    return 0;
}

static void gkde_report(const void *self)
{
    const gkde_state *s = self;
    const gkde_stats *t = &s->st;
    if (cdl_log_quiet || !t->steps)
        return;
    double pts = t->points > 0.0 ? t->points : 1.0, tt = t->t_total > 0.0 ? t->t_total : 1.0;
    printf("gkde: h %.4g%s, %u light paths and %u eye path(s) per pixel per step; per eye vertex and "
           "step %.1f candidate links, %.1f trial links, %.1f unoccluded (M = %u); stored paths %.1f MiB "
           "(peak)\n",
           (double)s->h, s->opt.gkde.bandwidth > 0.0f ? " (given)" : " (calibrated)", s->n_light, s->eye_paths,
           t->candidates / pts, t->trials / pts, t->unoccluded / pts, s->M, (double)t->peak_bytes / 1048576.0);
    printf("gkde: time over %u steps %.2f s: eye paths %.0f %%, light paths %.0f %%, counting %.0f %%, "
           "linking %.0f %%, shadow rays %.0f %%, scoring %.0f %% (CPU seconds of all threads "
           "for the last three)\n",
           t->steps, t->t_total, 100.0 * t->t_eye / tt, 100.0 * t->t_light / tt, 100.0 * t->t_count / tt,
           100.0 * t->t_link / tt, 100.0 * t->t_rays / tt, 100.0 * t->t_score / tt);
}

static void gkde_destroy(void *self)
{
    gkde_state *s = self;
    cdl_vs_free(&s->lvs);
    cdl_vs_free(&s->evs);
    for (uint32_t i = 0; i < s->nchunks; i++) {
        cdl_vs_free(&s->chunks[i]);
        free(s->chunk_pix[i]);
    }
    free(s->chunks);
    free(s->chunk_pix);
    free(s->epix);
    free(s->radius);
    free(s->lv);
    cdl_kd_free(&s->kd);
    free(s->pts);
    free(s->segs);
    for (uint32_t i = 0; i < s->nrec; i++)
        free(s->rec[i].v);
    free(s->rec);
    free(s->count);
    free(s->pdepth);
    free(s->tested);
    free(s->unocc);
    free(s->wsum);
    free(s->scale);
    free(s->cum);
    free(s->acc);
    free(s->pv);
    free(s->pixsum);
}

const cdl_integrator_vtbl cdl_gkde_integrator = {
    .name = "gkde",
    .summary = "generalized kernel density estimation (Bekaert et al. 2003): footprints, trial links, "
               "shadow rays to the parent",
    .prepare = gkde_prepare,
    .render_pass = gkde_render_pass,
    .destroy = gkde_destroy,
    .report = gkde_report,
    .self_size = sizeof(gkde_state),
};
