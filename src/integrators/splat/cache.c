/* splat's radiance cache (Herzog et al. 2007, §6.3, §6.3.1).
 *
 * The maps are computed by photon splatting at a sparse set of eye
 * samples only, the records, and interpolated to every sample:
 *  1. regions: the subtrees of the eye-sample tree holding at most
 *     2^(0.3 log2 N) samples (spatial/splatkd.c); each starts with one
 *     record, the sample in its middle;
 *  2. every photon ray traverses the tree down to the subtrees of at most
 *     2^(0.7 log2 N) samples its frustum reaches and is remembered there
 *     (the report keeps these references so that later passes skip the
 *     upper levels of the tree); there it meets the subtree's records, 16
 *     at a time (those whose bounding sphere it reaches); a record gathers
 *     irradiance, its map, the harmonic mean of the rays' distances z along
 *     them, and the gradient of the irradiance (eq. 6.9-6.11);
 *  3. each record's radius is eps R, R the harmonic mean distance within
 *     2 and 50 pixel widths (eq. 6.5, 6.6), shrunk to E / |grad E| where
 *     the irradiance changes faster (eq. 6.12; cache_spacing geometric
 *     leaves it), and by (passes)^(-1/6) as the kernels are (the report
 *     renders one frame; without it the average kept the cache's
 *     interpolation error: not consistent); records are splatted in
 *     image space onto the eye samples of their own segment within that
 *     radius with the weight of eq. 6.7
 *     (or Ward's), gathered pixel by pixel (deterministic);
 *  4. a region any of whose samples has fewer than N_c records halves its
 *     stride: its every (stride/2)-th sample becomes a record; the new
 *     records meet only the rays remembered above them; 3-4 repeat until
 *     no region changes;
 *  5. every sample's map is the weighted mean of its records' (eq. 6.8).
 * Eq. 6.6 prints the harmonic mean distance without the count of rays and
 * eq. 6.7 the squared distance over the radius unsquared: candela takes
 * n / sum(1 / z) and (d / (eps R))^2, so the weight falls to zero at eps R
 * as the text says. Records with a normal facing away (N . N_c <= 0) give
 * nothing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "film/segments.h"
#include "integrators/splat/cache.h"
#include "integrators/splat/maps.h"
#include "integrators/splat/occlusion.h"

#define CELL 16 /* pixels per side of the bins records are sorted into for the gather */

typedef struct splat_cache {
    cdl_skd_region *reg;  /* regions, where records are taken from */
    uint32_t nreg;
    cdl_skd_region *lst;  /* the subtrees that remember rays, each over whole regions */
    uint32_t nlst;
    uint32_t *lst_reg;    /* per list subtree: its first region (nlst + 1) */
    int32_t *stop;        /* per tree node: the list subtree rooted there, or -1 */
    uint32_t *reg_of; /* per sample */
    uint32_t *stride; /* per region: its records are every stride-th sample from stride / 2 */
    uint32_t *nb, *ne; /* per region: its records of this round, [nb, ne) in rec */
    size_t *roff;     /* per list subtree: its rays, rays[roff[l] .. roff[l + 1]) */
    uint32_t *rays;
    uint8_t *is_rec;
    uint32_t *rec, nrec, rec_cap;
    float *grad[3];   /* per sample: gradient of the irradiance's luminance (world) */
    float *rrad;      /* per record: radius eps R (world) */
    float *cw, *cwg, *cE[3], *cG, *cgm; /* per sample: weighted sums of the records' values */
    float *cn;                           /* and of their splat counts (for filter's boxes) */
    uint16_t *cnt;    /* per sample: records it gathered from */
    uint32_t *poff, *psam; /* pixel -> its samples */
    cdl_segments sg;
} splat_cache;

/* (region << 32 | ray) references found by one part, in ray order. */
typedef struct refs {
    uint64_t *v;
    size_t n, cap;
    int fail;
} refs;

static void push_ref(refs *b, uint64_t x)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 4096;
        uint64_t *v = realloc(b->v, sizeof *v * cap);
        if (!v) {
            b->fail = 1;
            return;
        }
        b->v = v;
        b->cap = cap;
    }
    b->v[b->n++] = x;
}

static int add_record(splat_cache *c, uint32_t q)
{
    if (c->nrec == c->rec_cap) {
        uint32_t cap = c->rec_cap ? 2 * c->rec_cap : 1024;
        uint32_t *rec = realloc(c->rec, sizeof *rec * cap);
        float *rr = realloc(c->rrad, sizeof *rr * cap);
        if (rec)
            c->rec = rec;
        if (rr)
            c->rrad = rr;
        if (!rec || !rr)
            return -1;
        c->rec_cap = cap;
    }
    c->is_rec[q] = 1;
    c->rec[c->nrec++] = q;
    return 0;
}

/* Region r's records at its stride that are not records yet. */
static int add_records(splat_cache *c, uint32_t r)
{
    const cdl_skd_region *g = &c->reg[r];
    uint32_t st = c->stride[r];
    c->nb[r] = c->nrec;
    for (uint32_t i = g->lo + st / 2; i < g->hi; i += st)
        if (!c->is_rec[i] && add_record(c, i))
            return -1;
    c->ne[r] = c->nrec;
    return 0;
}

/* The splat of the ray in t (frustum sr) onto record sample q, weighed
 * again with the irradiance gradient. Returns 1 if it fed q. */
static int record_hit(splat_state *s, splat_cache *c, splat_terms *t, const cdl_splat_ray *sr, uint32_t q)
{
    const cdl_skd *tr = &s->tree;
    float z;
    cdl_vec3 g;
    float w = cdl_splat_weight_grad(sr, cdl_v3(tr->p[0][q], tr->p[1][q], tr->p[2][q]),
                                    cdl_v3(tr->nrm[0][q], tr->nrm[1][q], tr->nrm[2][q]),
                                    tr->two[q] > 0.0f ? CDL_SKD_TWO_SIDED : 0, &z, &g);
    if (!(w > 0.0f))
        return 0;
    if (s->occl) {
        uint64_t rays = 0;
        int seen = splat_occl_seen(s, t->r, q, z > 0.0f ? 1.0f / z : 0.0f, &rays);
        if (rays) {
#pragma omp atomic
            s->st.occl_rays += rays;
        }
        if (!seen)
            return 0;
    }
    splat_maps_add(s, t, q, w, z > 0.0f ? 1.0f / z : 0.0f);
    float lum = cdl_luminance(t->r->flux);
    c->grad[0][q] += lum * g.x;
    c->grad[1][q] += lum * g.y;
    c->grad[2][q] += lum * g.z;
    return 1;
}

/* Whether the frustum of r reaches the sphere (centre c, radius rad). */
static int reaches(const cdl_splat_ray *r, const float *c, float rad)
{
    cdl_vec3 D = cdl_sub(cdl_v3(c[0], c[1], c[2]), r->o);
    float z = cdl_dot(D, r->d), zmax = r->len + (r->cap > 0.0f ? r->cap : 1.0f) * (r->h0 + r->dh * r->len);
    if (z + rad < 0.0f || z - rad > zmax)
        return 0;
    cdl_vec3 e = cdl_sub(D, cdl_scale(r->d, z));
    float zr = z + rad < r->len ? z + rad : r->len, R = r->h0 + r->dh * zr + rad;
    return cdl_dot(e, e) <= R * R;
}

/* This round's records of each list subtree laid out as the tree lays
 * out samples (SoA, 16 floats of padding), with a bounding sphere per 16
 * (in tree order, every 16 records lie close together). */
typedef struct views {
    float *buf;   /* per list subtree l from off[l]: 7 arrays of stride[l] floats, then the spheres */
    size_t *off;
    uint32_t *stride;
} views;

static void views_free(views *v)
{
    free(v->buf);
    free(v->off);
    free(v->stride);
}

static void list_records(const splat_cache *c, uint32_t l, uint32_t *j0, uint32_t *j1)
{
    *j0 = c->nb[c->lst_reg[l]];
    *j1 = c->ne[c->lst_reg[l + 1] - 1];
}

static int views_build(const splat_state *s, const splat_cache *c, views *v, cdl_error *err)
{
    v->off = malloc(sizeof *v->off * ((size_t)c->nlst + 1));
    v->stride = malloc(sizeof *v->stride * (c->nlst ? c->nlst : 1));
    if (!v->off || !v->stride)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
    size_t total = 0;
    for (uint32_t l = 0; l < c->nlst; l++) {
        uint32_t j0, j1;
        list_records(c, l, &j0, &j1);
        uint32_t m = j1 > j0 ? j1 - j0 : 0;
        v->off[l] = total;
        v->stride[l] = m ? m + 16 : 0;
        total += m ? 7 * (size_t)(m + 16) + 4 * (size_t)((m + 15) / 16) : 0;
    }
    v->off[c->nlst] = total;
    v->buf = calloc(total ? total : 1, sizeof(float));
    if (!v->buf)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
#pragma omp parallel for schedule(dynamic, 16)
    for (uint32_t l = 0; l < c->nlst; l++) {
        uint32_t j0, j1;
        list_records(c, l, &j0, &j1);
        if (j0 >= j1)
            continue;
        uint32_t m = j1 - j0, st = v->stride[l];
        float *b0 = v->buf + v->off[l], *sph = b0 + 7 * (size_t)st;
        for (uint32_t j = j0; j < j1; j++) {
            uint32_t q = c->rec[j];
            for (int a = 0; a < 3; a++) {
                b0[(size_t)a * st + (j - j0)] = s->tree.p[a][q];
                b0[(size_t)(3 + a) * st + (j - j0)] = s->tree.nrm[a][q];
            }
            b0[(size_t)6 * st + (j - j0)] = s->tree.two[q];
        }
        for (uint32_t b = 0; b < m; b += 16) {
            uint32_t e = b + 16 < m ? b + 16 : m;
            float lo[3], hi[3], r2 = 0.0f;
            for (int a = 0; a < 3; a++) {
                const float *pa = b0 + (size_t)a * st;
                lo[a] = hi[a] = pa[b];
                for (uint32_t i = b + 1; i < e; i++) {
                    lo[a] = fminf(lo[a], pa[i]);
                    hi[a] = fmaxf(hi[a], pa[i]);
                }
                sph[b / 4 + (uint32_t)a] = 0.5f * (lo[a] + hi[a]);
                r2 += 0.25f * (hi[a] - lo[a]) * (hi[a] - lo[a]);
            }
            sph[b / 4 + 3] = sqrtf(r2) * 1.0001f + 1e-6f * (fabsf(lo[0]) + fabsf(lo[1]) + fabsf(lo[2]));
        }
    }
    return 0;
}

/* The ray in t (frustum sr) onto list subtree l's records of the round:
 * 16 at a time through the leaf test where it reaches their sphere, the
 * feasible ones weighed again with the gradient. */
static void test_list(splat_state *s, splat_cache *c, const views *v, uint32_t l, splat_terms *t,
                      const cdl_splat_ray *sr, uint64_t *splats, uint64_t *tested)
{
    uint32_t j0, j1;
    list_records(c, l, &j0, &j1);
    if (j0 >= j1)
        return;
    uint32_t m = j1 - j0, st = v->stride[l];
    float *b0 = v->buf + v->off[l];
    const float *sph = b0 + 7 * (size_t)st;
    cdl_skd view;
    memset(&view, 0, sizeof view);
    for (int a = 0; a < 3; a++) {
        view.p[a] = b0 + (size_t)a * st;
        view.nrm[a] = b0 + (size_t)(3 + a) * st;
    }
    view.two = b0 + (size_t)6 * st;
    for (uint32_t b = 0; b < m; b += 16) {
        if (!reaches(sr, sph + b / 4, sph[b / 4 + 3]))
            continue;
        float w[16], iz[16];
        uint32_t mm = m - b < 16 ? m - b : 16;
        uint32_t mask = cdl_skd_weigh16(&view, b, mm, sr, w, iz);
        *tested += mm;
        for (; mask; mask &= mask - 1)
            *splats += (uint64_t)record_hit(s, c, t, sr, c->rec[j0 + b + (uint32_t)__builtin_ctz(mask)]);
    }
}

/* A later round: each list subtree's new records meet the rays it
 * remembered (the upper levels of the tree skipped). */
static int splat_round(splat_state *s, splat_cache *c, cdl_error *err)
{
    views v = {NULL, NULL, NULL};
    int rc = views_build(s, c, &v, err);
    uint64_t splats = 0, tested = 0;
#pragma omp parallel for schedule(dynamic, 4) reduction(+ : splats, tested)
    for (uint32_t l = 0; l < c->nlst; l++) {
        if (rc || v.stride[l] == 0 || cdl_cancelled(s->cancel))
            continue;
        for (size_t i = c->roff[l]; i < c->roff[l + 1]; i++) {
            splat_terms t;
            t.r = &s->rays.r[c->rays[i]];
            t.ready = 0;
            cdl_splat_ray sr = splat_ray_of(s, t.r);
            test_list(s, c, &v, l, &t, &sr, &splats, &tested);
        }
    }
    views_free(&v);
    s->st.splats += splats;
    s->st.tested += tested;
    return rc;
}

typedef struct list_ctx {
    splat_state *s;
    splat_cache *c;
    const views *v;
    splat_terms t;
    cdl_splat_ray sr;
    uint32_t ray;
    refs *out;
    uint64_t splats, tested;
} list_ctx;

/* A ray reached list subtree l: remembered there, and (round 0) splatted
 * onto its first records while the ray is at hand. */
static void on_list(void *ctx, int32_t l)
{
    list_ctx *x = ctx;
    push_ref(x->out, (uint64_t)(uint32_t)l << 32 | x->ray);
    test_list(x->s, x->c, x->v, (uint32_t)l, &x->t, &x->sr, &x->splats, &x->tested);
}

/* Round 0: every ray down to the list subtrees its frustum reaches,
 * remembered there in ray order and splatted onto their first records. */
static int first_round(splat_state *s, splat_cache *c, cdl_error *err)
{
    uint32_t np = s->tree.nparts;
    refs *bufs = calloc(np ? np : 1, sizeof *bufs);
    views v = {NULL, NULL, NULL};
    if (!bufs)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
    int rc = views_build(s, c, &v, err);
    if (rc) {
        views_free(&v);
        free(bufs);
        return rc;
    }
    const int flags = s->opt.splat.cull ? CDL_SKD_CULL : 0;
    uint64_t nodes = 0, splats = 0, tested = 0;
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : nodes, splats, tested)
    for (uint32_t part = 0; part < np; part++) {
        cdl_skd_count cnt = {0, 0, 0};
        list_ctx x;
        memset(&x, 0, sizeof x);
        x.s = s;
        x.c = c;
        x.v = &v;
        x.out = &bufs[part];
        for (uint32_t k = 0; k < s->rays.n && !cdl_cancelled(s->cancel) && !bufs[part].fail; k++) {
            x.t.r = &s->rays.r[k];
            x.t.ready = 0;
            x.sr = splat_ray_of(s, x.t.r);
            x.ray = k;
            cdl_skd_stop_visit(&s->tree, part, &x.sr, flags, c->stop, on_list, &x, &cnt);
        }
        nodes += cnt.nodes;
        splats += x.splats;
        tested += x.tested;
    }
    views_free(&v);
    s->st.nodes += nodes;
    s->st.splats += splats;
    s->st.tested += tested;
    int fail = 0;
    size_t total = 0;
    for (uint32_t p = 0; p < np; p++) {
        fail |= bufs[p].fail;
        total += bufs[p].n;
    }
    c->roff = calloc((size_t)c->nlst + 1, sizeof *c->roff);
    c->rays = malloc(sizeof *c->rays * (total ? total : 1));
    size_t *at = malloc(sizeof *at * (c->nlst ? c->nlst : 1));
    if (fail || !c->roff || !c->rays || !at) {
        for (uint32_t p = 0; p < np; p++)
            free(bufs[p].v);
        free(bufs);
        free(at);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for %zu ray references", total);
    }
    /* per list subtree, its rays in ray order (a subtree lies in one part) */
    for (uint32_t p = 0; p < np; p++)
        for (size_t i = 0; i < bufs[p].n; i++)
            c->roff[(bufs[p].v[i] >> 32) + 1]++;
    for (uint32_t l = 0; l < c->nlst; l++)
        c->roff[l + 1] += c->roff[l];
    memcpy(at, c->roff, sizeof *at * c->nlst);
    for (uint32_t p = 0; p < np; p++) {
        for (size_t i = 0; i < bufs[p].n; i++)
            c->rays[at[bufs[p].v[i] >> 32]++] = (uint32_t)bufs[p].v[i];
        free(bufs[p].v);
    }
    free(at);
    free(bufs);
    s->st.ray_refs += total;
    return 0;
}

/* The radius eps R of record j (eq. 6.5, 6.6, 6.12). */
static float record_radius(const splat_state *s, const splat_cache *c, uint32_t q)
{
    const splat_eye *e = &s->eye[q];
    float rmin = 2.0f * e->pw, rmax = 50.0f * e->pw;
    float R = s->nsum[q] > 0.0f && s->izsum[q] > 0.0f ? s->nsum[q] / s->izsum[q] : rmax;
    R = R < rmin ? rmin : R > rmax ? rmax : R;
    if (!s->opt.splat.cache_geometric) {
        /* the gradient in the record's tangent plane against the
         * geometric one E / R of the split-sphere model */
        cdl_vec3 n = cdl_v3(s->tree.nrm[0][q], s->tree.nrm[1][q], s->tree.nrm[2][q]);
        cdl_vec3 g = cdl_v3(c->grad[0][q], c->grad[1][q], c->grad[2][q]);
        g = cdl_sub(g, cdl_scale(n, cdl_dot(g, n)));
        float gl = cdl_length(g), E = cdl_luminance(cdl_v3(s->E[0][q], s->E[1][q], s->E[2][q]));
        if (gl > 0.0f && E < gl * R)
            R = E / gl > rmin ? E / gl : rmin;
    }
    /* shrunk with the passes as the kernels are: later passes take more
     * records, and the average converges */
    return s->opt.splat.cache * R * (float)s->pp.bw_scale;
}

/* Eq. 6.7 (or Ward's weight) of record q (radius rr) at sample y. */
static float cache_weight(const splat_state *s, uint32_t q, float rr, uint32_t y)
{
    const cdl_skd *t = &s->tree;
    float dx = t->p[0][y] - t->p[0][q], dy = t->p[1][y] - t->p[1][q], dz = t->p[2][y] - t->p[2][q];
    float d2 = dx * dx + dy * dy + dz * dz;
    float nn = t->nrm[0][y] * t->nrm[0][q] + t->nrm[1][y] * t->nrm[1][q] + t->nrm[2][y] * t->nrm[2][q];
    if (!(nn > 0.0f) || !(d2 < rr * rr))
        return 0.0f;
    if (s->opt.splat.cache_ward) {
        /* Ward et al. 1988: 1 / (d / R + sqrt(1 - N . N_c)), used where it
         * exceeds 1 / eps, so within eps R; infinite at the record */
        float R = rr / s->opt.splat.cache;
        float den = sqrtf(d2) / R + sqrtf(fmaxf(0.0f, 1.0f - nn));
        float w = den > 1e-6f ? 1.0f / den : 1e6f;
        return w > 1.0f / s->opt.splat.cache ? w : 0.0f;
    }
    float n2 = nn * nn, a = 1.0f - d2 / (rr * rr) / (n2 * n2);
    return a > 0.0f ? a * a : 0.0f;
}

/* Records [j0, j1) onto the eye samples of their segments within their
 * radii, gathered pixel by pixel from bins of CELL x CELL pixels. */
static int cache_splat(splat_state *s, splat_cache *c, uint32_t j0, uint32_t j1, cdl_error *err)
{
    const cdl_camera *cam = &s->opt.camera;
    int W = cam->width, H = cam->height, bw = (W + CELL - 1) / CELL, bh = (H + CELL - 1) / CELL;
    size_t nb = (size_t)bw * (size_t)bh;
    int32_t *half = malloc(sizeof *half * (j1 > j0 ? j1 - j0 : 1)); /* footprint half-width in pixels */
    size_t *off = calloc(nb + 1, sizeof *off);
    if (!half || !off) {
        free(half);
        free(off);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
    }
#pragma omp parallel for schedule(static)
    for (uint32_t j = j0; j < j1; j++) {
        uint32_t q = c->rec[j];
        c->rrad[j] = record_radius(s, c, q);
        float h = c->rrad[j] / s->eye[q].pw;
        half[j - j0] = (int32_t)ceilf(h < (float)(W + H) ? h : (float)(W + H));
    }
    /* bins: count, offsets, fill in record order */
    for (int pass = 0; pass < 2; pass++) {
        size_t *at = NULL;
        uint32_t *list = NULL;
        if (pass) {
            for (size_t b = 0; b < nb; b++)
                off[b + 1] += off[b];
            at = malloc(sizeof *at * (nb ? nb : 1));
            list = malloc(sizeof *list * (off[nb] ? off[nb] : 1));
            if (!at || !list) {
                free(at);
                free(list);
                free(half);
                free(off);
                return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
            }
            memcpy(at, off, sizeof *at * nb);
        }
        for (uint32_t j = j0; j < j1; j++) {
            uint32_t p = s->eye[c->rec[j]].pixel;
            int px = (int)(p % (uint32_t)W), py = (int)(p / (uint32_t)W), hw = half[j - j0];
            int bx0 = (px - hw < 0 ? 0 : px - hw) / CELL, bx1 = (px + hw >= W ? W - 1 : px + hw) / CELL;
            int by0 = (py - hw < 0 ? 0 : py - hw) / CELL, by1 = (py + hw >= H ? H - 1 : py + hw) / CELL;
            for (int by = by0; by <= by1; by++)
                for (int bx = bx0; bx <= bx1; bx++) {
                    size_t b = (size_t)by * (size_t)bw + (size_t)bx;
                    if (pass)
                        list[at[b]++] = j;
                    else
                        off[b + 1]++;
                }
        }
        if (!pass)
            continue;
        free(at);
        const int glossy_maps = s->nglossy > 0, K3 = 3 * (int)s->K;
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t b = 0; b < nb; b++) {
            int bx = (int)(b % (size_t)bw), by = (int)(b / (size_t)bw);
            for (size_t i = off[b]; i < off[b + 1]; i++) {
                uint32_t j = list[i], q = c->rec[j], rp = s->eye[q].pixel;
                int px = (int)(rp % (uint32_t)W), py = (int)(rp / (uint32_t)W), hw = half[j - j0];
                int32_t seg = c->sg.id[rp];
                int x0 = bx * CELL, y0 = by * CELL, x1 = x0 + CELL > W ? W : x0 + CELL, y1 = y0 + CELL > H ? H : y0 + CELL;
                x0 = px - hw > x0 ? px - hw : x0;
                y0 = py - hw > y0 ? py - hw : y0;
                x1 = px + hw + 1 < x1 ? px + hw + 1 : x1;
                y1 = py + hw + 1 < y1 ? py + hw + 1 : y1;
                uint32_t gq = s->gloss[q];
                float lum_g = cdl_length(cdl_v3(c->grad[0][q], c->grad[1][q], c->grad[2][q]));
                for (int y = y0; y < y1; y++)
                    for (int x = x0; x < x1; x++) {
                        uint32_t p = (uint32_t)y * (uint32_t)W + (uint32_t)x;
                        if (c->sg.id[p] != seg)
                            continue;
                        for (uint32_t k = c->poff[p]; k < c->poff[p + 1]; k++) {
                            uint32_t yq = c->psam[k];
                            float w = cache_weight(s, q, c->rrad[j], yq);
                            if (!(w > 0.0f))
                                continue;
                            uint32_t gy = s->gloss[yq];
                            c->cw[yq] += w;
                            for (int ch = 0; ch < 3; ch++)
                                c->cE[ch][yq] += w * s->E[ch][q];
                            c->cgm[yq] += w * lum_g;
                            c->cn[yq] += w * s->nsum[q];
                            if (gy == SPLAT_LAMBERT) {
                                c->cnt[yq] += c->cnt[yq] < UINT16_MAX;
                            } else if (glossy_maps && gq != SPLAT_LAMBERT) {
                                /* a glossy sample takes its map from glossy records only */
                                const float *src = splat_gmap_at(s, gq, 0);
                                c->cwg[yq] += w;
                                c->cnt[yq] += c->cnt[yq] < UINT16_MAX;
                                if (s->opt.splat.mode == CDL_SPLAT_HISTOGRAM)
                                    for (int kk = 0; kk < (int)s->K; kk++)
                                        for (int ch = 0; ch < 3; ch++)
                                            c->cG[(size_t)gy * K3 + 3 * kk + ch] += w * splat_gmap_at(s, gq, kk)[ch];
                                else
                                    for (int kk = 0; kk < K3; kk++)
                                        c->cG[(size_t)gy * K3 + kk] += w * src[kk];
                            }
                        }
                    }
            }
        }
        free(list);
    }
    free(half);
    free(off);
    return 0;
}

static int cache_init(splat_state *s, splat_cache *c, cdl_error *err)
{
    const cdl_camera *cam = &s->opt.camera;
    const cdl_splat_options *o = &s->opt.splat;
    uint32_t N = s->neye, np = (uint32_t)cam->width * (uint32_t)cam->height;
    uint32_t size = N > 1 ? (uint32_t)floor(pow(2.0, 0.3 * log2((double)N))) : 1;
    uint32_t lsize = N > 1 ? (uint32_t)floor(pow(2.0, 0.7 * log2((double)N))) : 1;
    int rc = cdl_skd_regions(&s->tree, size, &c->reg, &c->nreg, err);
    if (!rc)
        rc = cdl_skd_regions(&s->tree, lsize > size ? lsize : size, &c->lst, &c->nlst, err);
    if (!rc)
        rc = cdl_segment(&c->sg, cam->width, cam->height, s->dz, s->dn,
                         cosf(o->filter_normal * (float)(CDL_PI / 180.0)), o->filter_depth, err);
    if (rc)
        return rc;
    size_t n = (size_t)N + 16, nr = c->nreg ? c->nreg : 1, K3 = 3 * (size_t)s->K;
    c->stop = malloc(sizeof *c->stop * (s->tree.nnodes ? s->tree.nnodes : 1));
    c->lst_reg = malloc(sizeof *c->lst_reg * ((size_t)c->nlst + 1));
    c->reg_of = malloc(sizeof *c->reg_of * n);
    c->stride = malloc(sizeof *c->stride * nr);
    c->nb = calloc(nr, sizeof *c->nb);
    c->ne = calloc(nr, sizeof *c->ne);
    c->is_rec = calloc(n, 1);
    c->cw = calloc(n, sizeof(float));
    c->cwg = calloc(n, sizeof(float));
    c->cgm = calloc(n, sizeof(float));
    c->cn = calloc(n, sizeof(float));
    c->cnt = calloc(n, sizeof *c->cnt);
    c->cG = calloc((s->nglossy ? s->nglossy : 1) * K3, sizeof(float));
    c->poff = calloc((size_t)np + 1, sizeof *c->poff);
    c->psam = malloc(sizeof *c->psam * n);
    int ok = c->stop && c->lst_reg && c->reg_of && c->stride && c->nb && c->ne && c->is_rec && c->cw && c->cwg && c->cgm && c->cn &&
             c->cnt && c->cG && c->poff && c->psam;
    for (int k = 0; k < 3; k++) {
        c->grad[k] = calloc(n, sizeof(float));
        c->cE[k] = calloc(n, sizeof(float));
        ok = ok && c->grad[k] && c->cE[k];
    }
    if (!ok)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the radiance cache");
    for (uint32_t i = 0; i < s->tree.nnodes; i++)
        c->stop[i] = -1;
    /* both in tree order; every region inside one list subtree */
    uint32_t r = 0;
    for (uint32_t l = 0; l < c->nlst; l++) {
        c->stop[c->lst[l].node] = (int32_t)l;
        c->lst_reg[l] = r;
        while (r < c->nreg && c->reg[r].lo < c->lst[l].hi)
            r++;
    }
    c->lst_reg[c->nlst] = r;
    for (uint32_t r = 0; r < c->nreg; r++) {
        c->stride[r] = c->reg[r].hi - c->reg[r].lo;
        for (uint32_t q = c->reg[r].lo; q < c->reg[r].hi; q++)
            c->reg_of[q] = r;
    }
    /* pixel -> samples */
    for (uint32_t q = 0; q < N; q++)
        c->poff[s->eye[q].pixel + 1]++;
    for (uint32_t p = 0; p < np; p++)
        c->poff[p + 1] += c->poff[p];
    uint32_t *at = malloc(sizeof *at * (np ? np : 1));
    if (!at)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the radiance cache");
    memcpy(at, c->poff, sizeof *at * np);
    for (uint32_t q = 0; q < N; q++)
        c->psam[at[s->eye[q].pixel]++] = q;
    free(at);
    return 0;
}

void splat_cache_free(splat_state *s)
{
    splat_cache *c = s->cache;
    if (!c)
        return;
    free(c->reg);
    free(c->lst);
    free(c->lst_reg);
    free(c->stop);
    free(c->reg_of);
    free(c->stride);
    free(c->nb);
    free(c->ne);
    free(c->roff);
    free(c->rays);
    free(c->is_rec);
    free(c->rec);
    free(c->rrad);
    for (int k = 0; k < 3; k++) {
        free(c->grad[k]);
        free(c->cE[k]);
    }
    free(c->cw);
    free(c->cwg);
    free(c->cgm);
    free(c->cn);
    free(c->cG);
    free(c->cnt);
    free(c->poff);
    free(c->psam);
    cdl_segments_free(&c->sg);
    free(c);
    s->cache = NULL;
}

int splat_cache_solve(splat_state *s, cdl_error *err)
{
    splat_cache_free(s);
    splat_cache *c = s->cache = calloc(1, sizeof *c);
    if (!c)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the radiance cache");
    double t0 = cdl_time_now();
    splat_maps_clear(s);
    int rc = cache_init(s, c, err);
    for (uint32_t r = 0; r < c->nreg && !rc; r++)
        if (add_records(c, r))
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache records");
    if (!rc)
        rc = first_round(s, c, err);
    double t_solve = cdl_time_now() - t0, t_cache = 0.0;
    uint32_t j0 = 0, rounds = 0;
    while (!rc && !cdl_cancelled(s->cancel)) {
        double t1 = cdl_time_now();
        uint32_t j1 = c->nrec;
        rc = cache_splat(s, c, j0, j1, err);
        if (rc)
            break;
        j0 = j1;
        rounds++;
        /* regions with a sample short of N_c records refine */
        uint8_t *want = calloc(c->nreg ? c->nreg : 1, 1);
        if (!want) {
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache");
            break;
        }
        for (uint32_t q = 0; q < s->neye; q++)
            if (c->cnt[q] < s->opt.splat.cache_min)
                want[c->reg_of[q]] = 1;
        uint32_t more = 0;
        for (uint32_t r = 0; r < c->nreg && !rc; r++) {
            c->nb[r] = c->ne[r] = c->nrec;
            if (!want[r] || c->stride[r] <= 1)
                continue;
            c->stride[r] /= 2;
            if (add_records(c, r))
                rc = cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the cache records");
            more += c->ne[r] - c->nb[r];
        }
        free(want);
        double t2 = cdl_time_now();
        t_cache += t2 - t1;
        if (rc || !more)
            break;
        rc = splat_round(s, c, err);
        t_solve += cdl_time_now() - t2;
    }
    if (rc)
        return rc;
    double t3 = cdl_time_now();
    /* eq. 6.8: every sample's map the weighted mean of its records' */
    const int K3 = 3 * (int)s->K;
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->neye; q++) {
        float w = c->cw[q];
        for (int ch = 0; ch < 3; ch++)
            s->E[ch][q] = w > 0.0f ? c->cE[ch][q] / w : 0.0f;
        c->cgm[q] = w > 0.0f ? c->cgm[q] / w : 0.0f;
        /* the splats a sample's value stands for: its records' (the
         * filter sizes its boxes by them; only records were splatted) */
        s->nsum[q] = w > 0.0f ? c->cn[q] / w : 0.0f;
        uint32_t g = s->gloss[q];
        if (g == SPLAT_LAMBERT)
            continue;
        float wg = c->cwg[q];
        if (s->opt.splat.mode == CDL_SPLAT_HISTOGRAM) {
            for (int k = 0; k < (int)s->K; k++)
                for (int ch = 0; ch < 3; ch++)
                    splat_gmap_at(s, g, k)[ch] = wg > 0.0f ? c->cG[(size_t)g * K3 + 3 * k + ch] / wg : 0.0f;
        } else {
            float *dst = splat_gmap_at(s, g, 0);
            for (int k = 0; k < K3; k++)
                dst[k] = wg > 0.0f ? c->cG[(size_t)g * K3 + k] / wg : 0.0f;
        }
    }
    t_cache += cdl_time_now() - t3;
    s->st.t_solve += t_solve;
    s->st.t_cache += t_cache;
    s->st.records += c->nrec;
    s->st.cache_passes += rounds;
    return 0;
}

int splat_cache_aov(const splat_state *s, uint32_t q, float out[3])
{
    const splat_cache *c = s->cache;
    if (!c)
        return 0;
    out[0] = c->is_rec[q] ? 1.0f : 0.0f;
    out[1] = (float)c->cnt[q];
    out[2] = c->cgm[q];
    return 1;
}

void splat_cache_report(const splat_state *s, cdl_stats *out)
{
    const splat_stats *t = &s->st;
    if (!s->cache || !t->passes)
        return;
    double P = (double)t->passes;
    cdl_stats_printf(out, "splat: cache: %.0f records per pass (%.2f %% of the eye samples) in %.1f rounds, %u regions, %.1f ray "
           "references per photon ray; T_cache %.2f s\n",
           (double)t->records / P, t->samples ? 100.0 * (double)t->records / (double)t->samples : 0.0,
           (double)t->cache_passes / P, s->cache->nreg,
           t->rays_stored ? (double)t->ray_refs / (double)t->rays_stored : 0.0, t->t_cache);
    cdl_stats_add(out, "records_per_pass", (double)t->records / P);
}
