/* vcm: vertex connection and merging (Georgiev, Krivanek, Davidovic &
 * Slusallek 2012; the same estimator as Hachisuka, Pantaleoni & Jensen
 * 2012's unified path sampling), after SmallVCM, the authors' reference
 * implementation.
 *
 * A pass traces one light subpath per pixel with the shared tracer
 * (transport/subpath.c; the same sample streams as bdpt's independent
 * light paths), keeps them in the shared vertex store (one store per chunk
 * of paths, so threads fill them without locks and in a fixed order), and
 * puts the vertices that can be merged with (on a surface that is not
 * purely specular, past y_0) into a hash grid of cells 2 r wide
 * (spatial/hashgrid, SmallVCM's structure: O(n) to build, a query reads
 * at most 8 cells). Then one eye subpath per pixel:
 *   vertex connection  bdpt's strategies against the pixel's own light
 *                      path (cdl_connect_all: s = 0; s = 1 by light
 *                      sampling; s >= 2; t = 1, light tracing onto the
 *                      film, which is how a light path reaches the camera);
 *   vertex merging     at every eye vertex z_k whose BSDF is not purely
 *                      specular, every light vertex of every light path
 *                      of the pass within r: the eye's BSDF at z_k for the
 *                      light vertex's incoming direction times its
 *                      throughput, over pi r^2 N (a box kernel, N light
 *                      paths).
 * The radius of pass i (1-based, the global pass index, so MPI ranks
 * agree) is r_i = r_1 i^((alpha - 1) / 2), SmallVCM's schedule: merging's
 * bias falls with the passes (progressive off keeps r_1).
 *
 * MIS. Every strategy (the connection of each (s, t) and the merge at
 * each interior vertex) is weighted by the balance or power heuristic
 * over all of them, merges counted with eta = pi r^2 N (n_VC = 1). SmallVCM
 * keeps running sums dVCM, dVC, dVM that its tracer updates at every
 * bounce; here they would need a second subpath tracer or three more
 * fields filled by the shared one for this method alone. Instead the
 * weights come from the densities the shared store already holds
 * (pdf_fwd, pdf_rev), as bdpt's do: transport/mis.c's walk over them adds
 * a merge term at every interior non-delta vertex, so a connection's
 * weight (cdl_connect_all) counts every merge; with eta = 0 the weights
 * are bdpt's, bit for bit (vcm_mode connect is bdpt). A merge's weight
 * walks the same records (cdl_merge_weight), but merges are many (every
 * light vertex near every eye vertex), so vcm takes it in O(1) from
 * partial sums of that walk computed once per stored vertex
 * (cdl_merge_partials_eye / _light: SmallVCM's quantities, derived after
 * tracing instead of during it) and the two densities through the merge;
 * tests/test_vcm.c checks the two agree on real subpaths and that all
 * weights of a path sum to 1.
 *
 * vcm_mode merge is merging alone (SmallVCM's "bpm", a progressive photon
 * mapper that merges at every eye vertex, the merges weighted against each
 * other): light is picked up by the eye path only when every vertex before
 * it was specular (nothing could be merged there), as in SmallVCM.
 *
 * Merges test visibility by default (merge_visibility): a shadow ray from
 * the eye vertex (moved back along its ray and lifted off the surface) to
 * the light vertex (moved back along its own), pm's test
 * (cdl_photon_visible), so no light reaches a room that no light path
 * enters, however thin its wall. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "integrators/integrator.h"
#include "spatial/photon_map.h"
#include "spatial/hashgrid.h"
#include "transport/connect.h"
#include "transport/photons.h"

enum { VCM_FULL, VCM_CONNECT, VCM_MERGE };

#define CHUNK 256 /* light paths per chunk store (a thread's unit of work) */
/* The default r_1 in pixel footprints at the first hits: SmallVCM's
 * default (0.003 of the scene's bounding radius at 512 x 512) is about one
 * footprint on its Cornell box; tied to the footprint, the expected number
 * of light vertices a merge finds stays the same at any resolution (one
 * light path per pixel). */
#define FOOTPRINTS 1.5f

/* A light vertex that can be merged with, in bucket order: position (the
 * hash grid reads the first three floats), unit direction towards its
 * predecessor, throughput, its light subpath's partial MIS sums and
 * density conversion (cdl_merge_partials_light) and its depth. 52 bytes:
 * a merge reads nothing else of the light path. */
typedef struct vcm_lv {
    float p[3], wi[3], beta[3];
    float a1, a2, gl;
    uint32_t depth;
} vcm_lv;
#define LV_FLOATS (sizeof(vcm_lv) / sizeof(float))

typedef struct lv_buf {
    vcm_lv *v;
    uint32_t n, cap;
} lv_buf;

typedef struct vcm_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    int mode;
    float r1;               /* first pass's radius */
    float r, eta, norm;     /* this pass's radius, pi r^2 N, 1 / (pi r^2 N) */
    uint32_t npaths, nchunks; /* light paths connected to (one per pixel) and their chunks */
    uint32_t nvm, nvm_chunks; /* light paths merged with (the npaths first) and all chunks */
    cdl_vertex_store *chunks; /* light paths: path i in chunks[i / CHUNK] from start[i], len[i] vertices */
    uint32_t *start, *len;
    lv_buf *bufs;             /* each chunk's mergeable vertices, in path order */
    vcm_lv *lv;               /* all of them, in bucket order */
    uint32_t nlv, lv_cap;
    cdl_hashgrid grid;
    cdl_splats *tile_splats;
    int ntiles;
    /* statistics */
    uint32_t passes;
    double t_light, t_build, t_eye;
    size_t peak_bytes;
    uint64_t stored, queries, found, merged; /* over all passes */
    uint64_t nlv_last;
} vcm_state;

/* Median pixel footprint (its width at the first hit) over a grid of
 * camera rays through the image; 0 if none hits. */
static float median_footprint(const cdl_scene *s, const cdl_camera *cam)
{
    enum { G = 32 };
    float fp[G * G];
    int n = 0;
    float pix = cam->ortho ? 2.0f * cam->half_h / (float)cam->height : 2.0f * cam->tan_half / (float)cam->height;
    for (int gy = 0; gy < G; gy++)
        for (int gx = 0; gx < G; gx++) {
            cdl_vec3 o, d;
            cdl_camera_gen(cam, ((float)gx + 0.5f) * (float)cam->width / G,
                           ((float)gy + 0.5f) * (float)cam->height / G, &o, &d);
            cdl_hit h;
            if (cdl_intersect(s, o, d, FLT_MAX, &h) && h.t > 0.0f)
                fp[n++] = cam->ortho ? pix : h.t * pix;
        }
    if (!n)
        return 0.0f;
    /* insertion sort: 1024 numbers once */
    for (int i = 1; i < n; i++) {
        float v = fp[i];
        int j = i;
        for (; j > 0 && fp[j - 1] > v; j--)
            fp[j] = fp[j - 1];
        fp[j] = v;
    }
    return fp[n / 2];
}

static int vcm_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    vcm_state *st = self;
    st->scene = scene;
    st->opt = *opt;
    st->mode = opt->vcm.mode;
    if (opt->mis != CDL_MIS_BALANCE && opt->mis != CDL_MIS_POWER)
        return cdl_error_set(err, CDL_ERR_USAGE, "mis", 0, "vcm weights by the balance or the power heuristic");
    if (st->mode < VCM_FULL || st->mode > VCM_MERGE)
        return cdl_error_set(err, CDL_ERR_USAGE, "vcm_mode", 0, "unknown mode %d", st->mode);
    st->walk.maxdepth = opt->maxdepth;
    st->walk.rr_depth = opt->rr_depth;
    st->walk.env_vertex = 1;
    st->r1 = opt->vcm.radius;
    if (!(st->r1 > 0.0f)) {
        st->r1 = FOOTPRINTS * median_footprint(scene, &opt->camera);
        if (!(st->r1 > 0.0f)) /* nothing in view: SmallVCM's default */
            st->r1 = 0.003f * 0.5f * cdl_length(cdl_sub(scene->bmax, scene->bmin));
        if (!(st->r1 > 0.0f))
            return cdl_error_set(err, CDL_ERR_INPUT, scene->path, 0, "the scene has no extent to size merges by");
    }
    uint64_t npix = (uint64_t)opt->camera.width * (uint64_t)opt->camera.height;
    if (npix > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_USAGE, "res", 0, "too many pixels for vcm's light paths");
    st->npaths = (uint32_t)npix;
    st->nchunks = (st->npaths + CHUNK - 1) / CHUNK;
    double nvm = st->mode == VCM_CONNECT ? (double)npix : ceil((double)opt->vcm.merge_paths * (double)npix);
    if (!(nvm >= (double)npix) || nvm > (double)(UINT32_MAX / 4))
        return cdl_error_set(err, CDL_ERR_USAGE, "merge_paths", 0,
                             "%g light paths per pixel for merging make %.0f a pass: at least one per pixel, at "
                             "most %u in all", (double)opt->vcm.merge_paths, nvm, UINT32_MAX / 4);
    st->nvm = (uint32_t)nvm;
    st->nvm_chunks = st->nchunks + (st->nvm - st->npaths + CHUNK - 1) / CHUNK;
    st->chunks = calloc(st->nchunks, sizeof *st->chunks);
    st->start = calloc(st->npaths, sizeof(uint32_t));
    st->len = calloc(st->npaths, sizeof(uint32_t));
    st->bufs = calloc(st->nvm_chunks, sizeof *st->bufs);
    int tx = (opt->camera.width + 15) / 16, ty = (opt->camera.height + 15) / 16;
    st->ntiles = tx * ty;
    st->tile_splats = calloc((size_t)st->ntiles, sizeof(cdl_splats));
    if (!st->chunks || !st->start || !st->len || !st->bufs || !st->tile_splats)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "vcm", 0, "out of memory");
    return 0;
}

/* A light vertex merges can use: on a surface that is not purely
 * specular, past y_0, with at most maxdepth bounces before it (an eye
 * vertex adds at least one more segment). */
static int mergeable(const vcm_state *st, const cdl_vertex_store *vs, uint32_t i)
{
    return vs->depth[i] >= 1 && (int)vs->depth[i] <= st->opt.maxdepth &&
           !(vs->flags[i] & (CDL_V_INFINITE | CDL_V_LIGHT)) && !cdl_is_black(vs->beta[i]) &&
           !cdl_mat_is_delta(st->scene->mats[vs->mat[i]].type);
}

static size_t state_bytes(const vcm_state *st)
{
    size_t b = (size_t)st->lv_cap * sizeof(vcm_lv) + cdl_hashgrid_bytes(&st->grid) +
               (size_t)st->npaths * 2 * sizeof(uint32_t);
    for (uint32_t c = 0; c < st->nchunks; c++)
        b += cdl_vs_bytes(&st->chunks[c]);
    for (uint32_t c = 0; c < st->nvm_chunks; c++)
        b += (size_t)st->bufs[c].cap * sizeof(vcm_lv);
    return b;
}

/* The sample counts of every strategy (mis.h): one light path per eye
 * path for connections and light tracing (n_VC = 1), all N searched by a
 * merge (eta); merge alone: merges and, where nothing can be merged, the
 * eye path's own hits of lights (specular_emission). */
static cdl_mis_counts counts(const vcm_state *st)
{
    if (st->mode == VCM_MERGE)
        return (cdl_mis_counts){0.0f, 0.0f, 0.0f, 0.0f, 0.0f, st->eta};
    return (cdl_mis_counts){1.0f, 1.0f, 1.0f, 0.0f, 0.0f, st->mode == VCM_FULL ? st->eta : 0.0f};
}

/* Appends one path's mergeable vertices to its chunk's buffer. */
static int keep_mergeable(const vcm_state *st, const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t l0,
                          uint32_t nl, float *part, uint32_t room, lv_buf *b)
{
    float *a1 = part, *a2 = part + room, *gl = part + 2 * room;
    cdl_merge_partials_light(cx, vs, l0, nl, a1, a2, gl);
    for (uint32_t a = 1; a < nl; a++) {
        uint32_t j = l0 + a;
        if (!mergeable(st, vs, j))
            continue;
        if (b->n == b->cap) {
            uint32_t cap = b->cap ? 2 * b->cap : 4 * CHUNK;
            vcm_lv *v = realloc(b->v, (size_t)cap * sizeof *v);
            if (!v)
                return 1;
            b->v = v;
            b->cap = cap;
        }
        b->v[b->n++] = (vcm_lv){{vs->p[j].x, vs->p[j].y, vs->p[j].z},
                                {vs->wi[j].x, vs->wi[j].y, vs->wi[j].z},
                                {vs->beta[j].x, vs->beta[j].y, vs->beta[j].z},
                                a1[a], a2[a], gl[a], vs->depth[j]};
    }
    return 0;
}

/* The pass's light paths, their mergeable vertices and the hash grid over
 * them. Paths 0 .. npaths - 1 (one per pixel) are kept whole for the
 * connections; the rest (merge_paths) only leave their mergeable vertices.
 * Path i draws from sample stream npaths + i, or 2 npaths + i past npaths
 * (2 npaths + pixel is a pixel's resampling stream). */
static int trace_lights(vcm_state *st, uint32_t pass, uint64_t *rays, cdl_error *err)
{
    double t0 = cdl_time_now();
    uint32_t room = (uint32_t)st->opt.maxdepth + 3;
    uint64_t total = 0;
    int fail = 0;
    int merging = st->mode != VCM_CONNECT;
    cdl_mis_counts cnt = counts(st);
    cdl_connect_ctx cx = {st->scene, &st->opt.camera, st->opt.mis, 0.0f, &cnt, 1};
    uint32_t nchunks = merging ? st->nvm_chunks : st->nchunks;
#pragma omp parallel reduction(+ : total, fail)
    {
        float *part = malloc(sizeof(float) * 3 * room);
        cdl_vertex_store scratch;
        cdl_vs_init(&scratch);
        if (!part)
            fail++;
#pragma omp for schedule(dynamic, 1)
        for (uint32_t c = 0; c < nchunks; c++) {
            int keep = c < st->nchunks;
            cdl_vertex_store *vs = keep ? &st->chunks[c] : &scratch;
            uint32_t i0 = keep ? c * CHUNK : st->npaths + (c - st->nchunks) * CHUNK;
            uint32_t lim = keep ? st->npaths : st->nvm, end = i0 + CHUNK < lim ? i0 + CHUNK : lim;
            cdl_vs_clear(vs);
            st->bufs[c].n = 0;
            for (uint32_t i = i0; part && !fail && i < end; i++) {
                if (!keep)
                    cdl_vs_clear(vs);
                if (cdl_vs_reserve(vs, vs->n + room, NULL)) {
                    fail++;
                    break;
                }
                cdl_sampler smp;
                cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed,
                                  (uint64_t)i + (keep ? 1 : 2) * (uint64_t)st->npaths, pass);
                uint64_t r = 0;
                uint32_t l0 = vs->n;
                uint32_t nl = cdl_trace_light_subpath(st->scene, &st->walk, &smp, vs, &r);
                total += r;
                if (keep) {
                    st->start[i] = l0;
                    st->len[i] = nl;
                }
                if (merging && keep_mergeable(st, &cx, vs, l0, nl, part, room, &st->bufs[c]))
                    fail++;
            }
        }
        cdl_vs_free(&scratch);
        free(part);
    }
    *rays += total;
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "vcm", 0, "out of memory for the light paths");
    st->t_light += cdl_time_now() - t0;
    if (!merging)
        return 0;
    t0 = cdl_time_now();
    uint64_t n = 0;
    for (uint32_t c = 0; c < nchunks; c++)
        n += st->bufs[c].n;
    if (n > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "vcm", 0, "%llu light vertices to merge with: too many",
                             (unsigned long long)n);
    if (n > st->lv_cap) {
        free(st->lv);
        st->lv_cap = (uint32_t)(n + n / 4);
        st->lv = malloc((size_t)st->lv_cap * sizeof(vcm_lv));
        if (!st->lv) {
            st->lv_cap = 0;
            return cdl_error_set(err, CDL_ERR_SYSTEM, "vcm", 0, "out of memory for %llu light vertices",
                                 (unsigned long long)n);
        }
    }
    /* gather in chunk order (fixed by the paths, not the threads) */
    for (uint32_t c = 0, o = 0; c < nchunks; c++) {
        if (st->bufs[c].n)
            memcpy(st->lv + o, st->bufs[c].v, st->bufs[c].n * sizeof(vcm_lv));
        o += st->bufs[c].n;
        if (st->bufs[c].cap > 64 * CHUNK) { /* a deep chunk's buffer is not kept between passes */
            free(st->bufs[c].v);
            st->bufs[c] = (lv_buf){0};
        }
    }
    st->nlv = (uint32_t)n;
    if (cdl_hashgrid_build(&st->grid, (const float *)st->lv, (uint32_t)LV_FLOATS, st->nlv, st->r, err))
        return err->code;
    /* bucket order, in place by following the permutation's cycles: a
     * query's points lie together in memory */
    uint32_t *ord = st->grid.order;
    for (uint32_t i = 0; i < st->nlv; i++) {
        if (ord[i] == i)
            continue;
        vcm_lv tmp = st->lv[i];
        uint32_t j = i;
        for (;;) {
            uint32_t k = ord[j];
            ord[j] = j;
            if (k == i) {
                st->lv[j] = tmp;
                break;
            }
            st->lv[j] = st->lv[k];
            j = k;
        }
    }
    cdl_hashgrid_make_identity(&st->grid, (const float *)st->lv);
    st->stored += n;
    st->nlv_last = n;
    st->t_build += cdl_time_now() - t0;
    return 0;
}

typedef struct merge_ctx {
    const vcm_state *st;
    uint32_t t; /* eye vertices up to and including the merge vertex */
    const cdl_bsdf *b;
    float b1, b2, ge; /* the eye subpath's partial MIS sums at the merge vertex */
    cdl_vec3 x, wo, nx, origin;
    int have_origin;
    cdl_vec3 sum;
    uint64_t found, merged, rays;
} merge_ctx;

static void merge_visit(void *ctx, uint32_t i, float d2)
{
    (void)d2;
    merge_ctx *m = ctx;
    const vcm_state *st = m->st;
    const vcm_lv *lv = &st->lv[i];
    m->found++;
    /* the merged path's bounces: (t - 1) + depth - 1 */
    if ((int)(m->t + lv->depth) - 2 > st->opt.maxdepth)
        return;
    cdl_vec3 wi = cdl_v3(lv->wi[0], lv->wi[1], lv->wi[2]);
    cdl_vec3 f = cdl_bsdf_eval(m->b, m->wo, wi, 0);
    if (cdl_is_black(f))
        return;
    /* the densities through the merge, both ways: y_{m-1} sampled by the
     * eye vertex's BSDF, and z_{k-1} for light arriving from y_{m-1} */
    float pe = cdl_bsdf_pdf(m->b, m->wo, wi) * lv->gl;
    float pl = m->b2 > 0.0f ? cdl_bsdf_pdf(m->b, wi, m->wo) * m->ge : 0.0f;
    float w = cdl_mis_merge_partials(st->opt.mis, lv->a1, lv->a2, pe, m->b1, m->b2, pl);
    if (!(w > 0.0f))
        return;
    if (st->opt.vcm.visibility) {
        if (!m->have_origin) {
            m->origin = cdl_photon_vis_origin(st->scene, m->x, m->nx, m->wo, CDL_VIS_LIFT * st->r);
            m->have_origin = 1;
        }
        m->rays++;
        if (!cdl_photon_visible(st->scene, m->origin, cdl_v3(lv->p[0], lv->p[1], lv->p[2]), wi))
            return;
    }
    m->merged++;
    m->sum = cdl_add(m->sum, cdl_scale(cdl_mul(f, cdl_v3(lv->beta[0], lv->beta[1], lv->beta[2])), w));
}

/* Vertex merging at every eye vertex of evs[0 .. ne); part holds 3 ne floats. */
static cdl_vec3 merge_all(const vcm_state *st, const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t ne,
                          float *part, uint64_t *rays, uint64_t *found, uint64_t *merged, uint64_t *queries)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    float r2 = st->r * st->r, *b1 = part, *b2 = part + ne, *ge = part + 2 * ne;
    cdl_merge_partials_eye(cx, evs, ne, b1, b2, ge);
    for (uint32_t k = 1; k < ne && (int)k <= st->opt.maxdepth; k++) {
        if (evs->flags[k] & CDL_V_INFINITE)
            break;
        cdl_bsdf b;
        cdl_vs_bsdf(st->scene, evs, k, &b);
        if (cdl_bsdf_is_delta(&b))
            continue;
        cdl_vec3 wo = evs->wi[k];
        merge_ctx m = {st, k + 1, &b, b1[k], b2[k], ge[k], evs->p[k], wo,
                       cdl_dot(b.ng, wo) < 0.0f ? cdl_neg(b.ng) : b.ng, cdl_v3(0.0f, 0.0f, 0.0f), 0,
                       cdl_v3(0.0f, 0.0f, 0.0f), 0, 0, 0};
        (*queries)++;
        cdl_hashgrid_ball(&st->grid, evs->p[k], r2, merge_visit, &m);
        *rays += m.rays;
        *found += m.found;
        *merged += m.merged;
        L = cdl_add(L, cdl_mul(evs->beta[k], m.sum));
    }
    return cdl_scale(L, st->norm);
}

/* Merging alone: light the eye path hits after specular vertices only
 * (nothing could be merged before it); the rest is the merges'. */
static cdl_vec3 specular_emission(const vcm_state *st, const cdl_connect_ctx *cx, const cdl_vertex_store *evs,
                                  uint32_t ne)
{
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    for (uint32_t t = 2; t <= ne && (int)t - 2 <= st->opt.maxdepth; t++) {
        L = cdl_add(L, cdl_connect_eye_only(cx, evs, t)); /* weight 1: no merge and no connection counts */
        if (!(evs->flags[t - 1] & CDL_V_DELTA))
            break;
    }
    return L;
}

static uint64_t vcm_tile(void *self, cdl_film *film, int x0, int y0, int x1, int y1, uint32_t pass,
                         uint64_t *rays)
{
    vcm_state *st = self;
    const cdl_camera *cam = &st->opt.camera;
    cdl_vertex_store evs, tvs;
    cdl_vs_init(&evs);
    cdl_vs_init(&tvs);
    cdl_error err;
    uint32_t room = (uint32_t)st->opt.maxdepth + 3;
    float *part = malloc(sizeof(float) * 3 * room);
    if (!part || cdl_vs_reserve(&evs, room, &err) || cdl_vs_reserve(&tvs, 1, &err)) {
        free(part);
        cdl_vs_free(&evs);
        cdl_vs_free(&tvs);
        return 0;
    }
    int tile = (y0 / 16) * ((film->width + 15) / 16) + x0 / 16;
    cdl_splats *splats = &st->tile_splats[tile];
    int connect = st->mode != VCM_MERGE, merge = st->mode != VCM_CONNECT;
    /* one light path per eye path for connections and light tracing (n_VC
     * = 1); merges search all N: eta */
    cdl_mis_counts cnt = counts(st);
    cdl_connect_ctx cx = {st->scene, cam, st->opt.mis, 0.0f, &cnt, 0};
    cdl_connect_ctx cx_spec = cx;
    cdl_mis_counts cnt_spec = cnt;
    cnt_spec.eye = 1.0f;
    cx_spec.counts = &cnt_spec;
    uint64_t bad = 0, found = 0, merged = 0, queries = 0;
    int a_merge = cdl_film_find_aov(film, "merge"), a_count = cdl_film_find_aov(film, "mergecount");
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++) {
            uint32_t pix = (uint32_t)y * (uint32_t)film->width + (uint32_t)x;
            cdl_sampler smp;
            float jx, jy, fx, fy, fw;
            cdl_sampler_start(&smp, st->opt.sampler, st->opt.seed, pix, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            cdl_vs_clear(&evs);
            cdl_camera_sample(cam, x, y, jx, jy, &fx, &fy, &fw);
            uint32_t ne = cdl_trace_eye_subpath(st->scene, cam, fx, fy, &st->walk, &smp, &evs, rays);
            cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
            if (connect) {
                cdl_sampler rsmp;
                cdl_sampler_start(&rsmp, st->opt.sampler, st->opt.seed, (uint64_t)pix + 2 * (uint64_t)st->npaths,
                                  pass);
                L = cdl_connect_all(&cx, st->opt.maxdepth, &evs, ne, &st->chunks[pix / CHUNK], st->start[pix],
                                    st->len[pix], 1, splats, 1.0f, &rsmp, &tvs, rays);
            } else {
                L = specular_emission(st, &cx_spec, &evs, ne);
            }
            cdl_vec3 Lm = cdl_v3(0.0f, 0.0f, 0.0f);
            uint64_t merged0 = merged;
            if (merge)
                Lm = merge_all(st, &cx, &evs, ne, part, rays, &found, &merged, &queries);
            if (a_count >= 0)
                film->aovs[a_count].sum[pix] += (double)(merged - merged0);
            L = cdl_add(L, Lm);
            bad += (uint64_t)cdl_film_add(film, x, y, fw == 1.0f ? L : cdl_scale(L, fw));
            if (a_merge >= 0 && cdl_is_finite3(L)) { /* the merges' part of this sample */
                double *d = film->aovs[a_merge].sum + 3 * (size_t)pix;
                d[0] += (double)(fw * Lm.x);
                d[1] += (double)(fw * Lm.y);
                d[2] += (double)(fw * Lm.z);
            }
        }
    free(part);
    cdl_vs_free(&evs);
    cdl_vs_free(&tvs);
#pragma omp atomic
    st->found += found;
#pragma omp atomic
    st->merged += merged;
#pragma omp atomic
    st->queries += queries;
    return bad;
}

static int vcm_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    vcm_state *st = self;
    /* SmallVCM's schedule by the global pass index (1-based) */
    st->r = st->r1;
    if (st->opt.progressive)
        st->r *= powf((float)pass + 1.0f, 0.5f * (st->opt.alpha - 1.0f));
    st->eta = (float)CDL_PI * st->r * st->r * (float)st->nvm;
    st->norm = 1.0f / st->eta;
    int rc = trace_lights(st, pass, &film->rays, err);
    if (rc)
        return rc;
    size_t bytes = state_bytes(st);
    st->peak_bytes = bytes > st->peak_bytes ? bytes : st->peak_bytes;
    double t0 = cdl_time_now();
    cdl_render_tiles(self, film, pass, vcm_tile);
    st->t_eye += cdl_time_now() - t0;
    st->passes++;
    if (st->mode == VCM_MERGE)
        return 0;
    if (cdl_cancelled(film->cancel)) {
        for (int i = 0; i < st->ntiles; i++)
            st->tile_splats[i].n = 0; /* an interrupted pass's splats are incomplete */
        return 0;
    }
    for (int i = 0; i < st->ntiles; i++)
        film->nonfinite += cdl_film_merge_splats(film, &st->tile_splats[i]);
    film->splat_passes++;
    return 0;
}

static void vcm_report(const void *self, cdl_stats *out)
{
    const vcm_state *st = self;
    static const char *const modes[] = {"full", "connect", "merge"};
    double mib = 1.0 / (1024.0 * 1024.0), P = st->passes ? (double)st->passes : 1.0;
    double q = st->queries ? (double)st->queries : 1.0;
    cdl_stats_printf(out, "vcm: mode %s, %u light paths per pass (%u merged with), merge radius r_1 %.4g (%s), r %.4g at pass %u; "
                     "%.0f light vertices stored per pass (%llu in the last); per merge query %.2f found, %.2f "
                     "merged; memory %.2f MiB (peak: light paths, %zu B per light vertex + hash grid)\n",
                     modes[st->mode], st->npaths, st->mode == VCM_CONNECT ? 0 : st->nvm, st->r1, st->opt.vcm.radius > 0.0f ? "given" : "1.5 pixel footprints",
                     st->r, st->passes, (double)st->stored / P, (unsigned long long)st->nlv_last,
                     (double)st->found / q, (double)st->merged / q, (double)st->peak_bytes * mib, sizeof(vcm_lv));
    cdl_stats_printf(out, "vcm: time over %u passes: light paths %.2f s, hash grid %.2f s, eye paths %.2f s\n",
                     st->passes, st->t_light, st->t_build, st->t_eye);
    cdl_stats_add(out, "radius", (double)st->r1);
    cdl_stats_add(out, "light_vertices", (double)st->stored / P);
    cdl_stats_add(out, "found_per_query", (double)st->found / q);
    cdl_stats_add(out, "merged_per_query", (double)st->merged / q);
    cdl_stats_add(out, "memory_mib", (double)st->peak_bytes * mib);
    cdl_stats_add(out, "t_light", st->t_light);
    cdl_stats_add(out, "t_build", st->t_build);
    cdl_stats_add(out, "t_eye", st->t_eye);
}

static void vcm_destroy(void *self)
{
    vcm_state *st = self;
    if (st->chunks)
        for (uint32_t c = 0; c < st->nchunks; c++)
            cdl_vs_free(&st->chunks[c]);
    if (st->tile_splats)
        for (int i = 0; i < st->ntiles; i++)
            cdl_splats_free(&st->tile_splats[i]);
    free(st->chunks);
    free(st->start);
    free(st->len);
    if (st->bufs)
        for (uint32_t c = 0; c < st->nvm_chunks; c++)
            free(st->bufs[c].v);
    free(st->bufs);
    free(st->lv);
    free(st->tile_splats);
    cdl_hashgrid_free(&st->grid);
}

static const double aov_bits[] = {CDL_AOV_MERGE, CDL_AOV_MERGECOUNT};
static const cdl_param rows[] = {
    {"radius", CDL_PARAM_FLOAT, "r", "", "merge radius of the first pass, r_1 (pass i: r_1 i^((alpha - 1) / 2)); "
     "default 1.5 times the median pixel footprint at the first hits (printed in the statistics)", 1e-9, 1e9,
     CDL_PARAM_AT(cdl_options, vcm.radius)},
    {"vcm_mode", CDL_PARAM_CHOICE, "KIND", "full", "full (connections and merges under one MIS), connect (bdpt's "
     "strategies alone: bdpt) or merge (merging alone at every eye vertex: a progressive photon mapper over the same "
     "light paths)", .choices = "full|connect|merge", CDL_PARAM_AT(cdl_options, vcm.mode)},
    {"mis", CDL_PARAM_CHOICE, "KIND", "power", "weights of all strategies: balance (SmallVCM's) or power",
     .choices = "balance|power", CDL_PARAM_AT(cdl_options, mis)},
    {"merge_visibility", CDL_PARAM_BOOL, "on|off", "on", "a merge counts only if a free segment joins the eye vertex "
     "to the light vertex (a shadow ray each, as pm's visibility): no light through thin walls; off: SmallVCM's "
     "merges", CDL_PARAM_AT(cdl_options, vcm.visibility)},
    {"merge_paths", CDL_PARAM_FLOAT, "k", "1", "light paths traced per pass for merging, in multiples of the pixels: "
     "one per pixel is also connected to (SmallVCM's count), the others are only merged with", 1, 1024,
     CDL_PARAM_AT(cdl_options, vcm.merge_paths)},
    {"aov", CDL_PARAM_CHOICE, "NAME", "", "extra EXR layers, repeatable: merge (the merges' MIS-weighted part of the "
     "image; the rest is the connections') or mergecount (light vertices merged per pixel sample)",
     .choices = "merge|mergecount", .values = aov_bits, .flags = CDL_PARAM_BITS,
     CDL_PARAM_AT(cdl_options, aov)},
};
static const cdl_param_table table =
    CDL_PARAM_TABLE("Vertex connection and merging (vcm; Georgiev et al. 2012)", rows);
static const cdl_param_table *const tables[] = {&cdl_density_table, &table, NULL};

const cdl_integrator_vtbl cdl_vcm_integrator = {
    .params = tables,
    .name = "vcm",
    .summary = "vertex connection and merging: bdpt's strategies and photon merging at every eye vertex under one "
               "MIS; vcm_mode, radius",
    .prepare = vcm_prepare,
    .render_pass = vcm_render_pass,
    .destroy = vcm_destroy,
    .report = vcm_report,
    .self_size = sizeof(vcm_state),
};
