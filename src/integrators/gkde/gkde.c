/* gkde: generalized kernel density estimation (Bekaert, Slusallek, Cools,
 * Havran & Seidel 2003, "A custom designed density estimator for light
 * transport"). Each pass is one of the report's steps (§5):
 *
 * 1. eye paths (eye_paths per pixel) and light paths (light_paths per
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
 * 6. h is calibrated in the first step so that an eye vertex in direct
 *    light lies in about M first-bounce footprints (the expected count is
 *    pi N h^2 with eq. 7's radii, so h = sqrt(M / (pi N)) corrected by the
 *    measured count), and shrinks with the steps (progressive).
 *
 * Lights at infinity: their light paths start on a disk (the shared
 * tracer), no surface point, so no footprint has x_0 there; their direct
 * light is sampled at every eye vertex instead (cdl_gkde_sky).
 *
 * Determinism whatever the thread count: the eye vertices are split into
 * kd subtrees that one thread owns, and each subtree meets the footprints
 * in light-vertex order, so sums and the stratified draws never depend on
 * scheduling. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "core/morton.h"
#include "core/radix.h"
#include "core/rng.h"
#include "integrators/gkde/points.h"

#define LIGHT_CHUNK 1024


static int gkde_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    gkde_state *s = self;
    s->scene = scene;
    s->opt = *opt;
    s->walk.maxdepth = opt->maxdepth;
    s->walk.rr_depth = opt->rr_depth;
    s->walk.env_vertex = 1; /* eye paths that see the sky: its emission, weighted */
    s->n_light = opt->gkde.light_paths;
    s->eye_paths = opt->gkde.eye_paths ? opt->gkde.eye_paths : 1;
    /* h is calibrated to M overlaps of N first-bounce footprints, so h^2 ~
     * M / N and the normalization bias (§3) grows with it: M tied to N
     * keeps h whatever the light paths, fewer paths trading noise only */
    s->M = opt->gkde.links ? opt->gkde.links : gkde_default_links(s->n_light);
    s->h = opt->gkde.bandwidth;
    s->have_h = s->h > 0.0f;
    if (!scene->nlights)
        return cdl_error_set(err, CDL_ERR_INPUT, scene->path, 0, "gkde: the scene has no lights");
    for (uint32_t i = 0; i < scene->nlights; i++)
        s->at_infinity |= cdl_light_at_infinity(&scene->lights[i]);
    size_t npix = (size_t)opt->camera.width * (size_t)opt->camera.height;
    s->pv = calloc(npix * 6, sizeof *s->pv);
    s->pv_new = calloc(npix * 6, sizeof *s->pv_new);
    s->fold_at = 1;
    s->pixsum = malloc(npix * sizeof *s->pixsum);
    if (!s->pv || !s->pv_new || !s->pixsum)
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
           (size_t)s->lvs.cap * (sizeof *s->radius + sizeof *s->lv + 4 * sizeof *s->ball) +
           (size_t)s->npts * (4 * sizeof(float) + 6 + 3 * sizeof(uint32_t) + 3 * sizeof(double) +
                              sizeof(cdl_vec3) + sizeof(cdl_gkde_eye));
}

static int check_memory(gkde_state *s, cdl_error *err)
{
    size_t b = stored_bytes(s);
    if (b > s->st.peak_bytes)
        s->st.peak_bytes = b;
    if (b > (size_t)s->opt.gkde.max_mib << 20)
        return cdl_error_set(err, CDL_ERR_USAGE, "path_memory", 0,
                             "the stored paths need %.0f MiB, more than the cap of %u MiB: lower "
                             "light_paths, eye_paths or the resolution, or raise the cap",
                             (double)b / 1048576.0, s->opt.gkde.max_mib);
    return 0;
}

/* dst = chunks 0 .. n-1 in order (the eye vertices' pixels too if pix):
 * the same store whatever thread traced which chunk. */
static int join_chunks(gkde_state *s, cdl_vertex_store *dst, uint32_t n, int pix, cdl_error *err)
{
    cdl_vs_clear(dst);
    for (uint32_t c = 0; c < n; c++) {
        uint32_t n0 = dst->n;
        int rc = cdl_vs_append(dst, &s->chunks[c], err);
        if (rc)
            return rc;
        if (!pix)
            continue;
        uint32_t *ep = realloc(s->epix, sizeof(uint32_t) * dst->cap);
        if (!ep)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
        s->epix = ep;
        memcpy(s->epix + n0, s->chunk_pix[c], sizeof(uint32_t) * s->chunks[c].n);
    }
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
    return join_chunks(s, &s->evs, (uint32_t)H, 1, err);
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
    return join_chunks(s, &s->lvs, nc, 0, err);
}

/* The footprints in Morton order of their centres: consecutive footprints
 * meet the same eye points, so stages 3-5 find them in cache (the fixed
 * order the stratified draws follow; any fixed order is as good). */
static int sort_spatially(gkde_state *s, cdl_error *err)
{
    const cdl_vertex_store *l = &s->lvs;
    uint32_t n = s->nlv;
    uint64_t *key = malloc(sizeof *key * (n ? n : 1));
    if (!key)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t a = 0; a < n; a++) {
        const float *p = &l->p[s->lv[a]].x;
        for (int k = 0; k < 3; k++) {
            lo[k] = p[k] < lo[k] ? p[k] : lo[k];
            hi[k] = p[k] > hi[k] ? p[k] : hi[k];
        }
    }
    float ext = cdl_maxf(hi[0] - lo[0], cdl_maxf(hi[1] - lo[1], hi[2] - lo[2]));
    float sc = ext > 0.0f ? 1023.0f / ext : 0.0f;
#pragma omp parallel for schedule(static)
    for (uint32_t a = 0; a < n; a++) {
        const float *p = &l->p[s->lv[a]].x;
        key[a] = cdl_morton3(p, lo, sc) << 32 | s->lv[a];
    }
    /* the 30 Morton bits in three stable passes: ties keep the index order */
    uint64_t *tmp = malloc(sizeof *tmp * (n ? n : 1));
    if (!tmp) {
        free(key);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    }
    uint64_t *sorted = cdl_radix_sort_bits(key, tmp, n, 32, 62);
    free(sorted == key ? tmp : key);
    key = sorted;
    /* each part's pass over the footprints then reads them in order */
#pragma omp parallel for schedule(static)
    for (uint32_t a = 0; a < n; a++) {
        const uint32_t i = (uint32_t)key[a];
        s->lv[a] = i;
        s->ball[4 * (size_t)a] = l->p[i].x, s->ball[4 * (size_t)a + 1] = l->p[i].y;
        s->ball[4 * (size_t)a + 2] = l->p[i].z, s->ball[4 * (size_t)a + 3] = s->radius[i];
    }
    free(key);
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
    float *ball = lv ? realloc(s->ball, 4 * sizeof(float) * (l->n ? l->n : 1)) : NULL;
    if (r)
        s->radius = r;
    if (lv)
        s->lv = lv;
    if (ball)
        s->ball = ball;
    if (!r || !lv || !ball)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    s->nlv = 0;
    for (uint32_t i = 0; i < l->n; i++) {
        int32_t p = l->parent[i];
        r[i] = p < 0 ? 0.0f : cdl_footprint_radius(h, l->pdf_fwd[i], r[p], s->g.r_cap);
        /* a parent on the disk of a light at infinity is no surface point:
         * light sampling at the eye vertices takes that direct light */
        if (p >= 0 && !(l->flags[p] & (CDL_V_DELTA | CDL_V_INFINITE)) && l->depth[i] <= s->opt.maxdepth &&
            r[i] > 0.0f && isfinite(r[i]))
            lv[s->nlv++] = i;
    }
    return sort_spatially(s, err);
}


static void count_hit(void *ctx, uint32_t q, float d2)
{
    (void)d2;
    uint32_t *c = ctx;
#pragma omp atomic
    c[q]++;
}

/* First-bounce footprints (radius h / sqrt(p(x_1)), capped) an eye point
 * lies in: the mean over the points that lie in at least one. */
static double overlaps(const gkde_state *s, float h, float cap_unit, uint32_t *per_point)
{
    const cdl_vertex_store *l = &s->lvs;
    memset(per_point, 0, sizeof(uint32_t) * s->npts);
#pragma omp parallel for schedule(dynamic, 1024)
    for (int64_t i = 0; i < (int64_t)l->n; i++) {
        if (l->depth[i] != 1 || !(l->pdf_fwd[i] > 0.0f))
            continue;
        float u = 1.0f / sqrtf(l->pdf_fwd[i]), r = h * (u < cap_unit ? u : cap_unit);
        cdl_kd_ball(&s->kd, l->p[i], r * r, count_hit, per_point);
    }
    uint64_t total = 0, lit = 0;
    for (uint32_t q = 0; q < s->npts; q++) {
        total += per_point[q];
        lit += per_point[q] > 0;
    }
    return lit ? (double)total / (double)lit : 0.0;
}

/* h such that an eye point in direct light lies in about K first-bounce
 * footprints (overlaps). §5 aims at K = M overlaps averaged over every
 * eye point: where the camera sees mostly indirectly lit surfaces (a room
 * lit through a door ajar) that average is small and h came out several
 * times too large, the points no footprint reaches saying nothing about h.
 * K is no longer M: with h shrinking over the steps, h_0 sets the bias
 * of the early steps (2 overlaps: 0.980 of path at 48 s in the door-ajar
 * room, 0.954 at 5), while M stays the cap of trial links. Counts grow as
 * h^2 on surfaces; the mean over reached points is at least 1. */
static void calibrate(gkde_state *s, float cap_unit)
{
    double M = s->opt.gkde.overlaps >= 2.0f ? (double)s->opt.gkde.overlaps : 2.0;
    double h = sqrt(M / (CDL_PI * (double)s->n_light));
    uint32_t *pp = malloc(sizeof(uint32_t) * (s->npts ? s->npts : 1));
    if (!pp)
        return; /* the caller's fallback: no calibration, h as given (0: an error later) */
    for (int it = 0, good = 0; it < 12 && good < 3; it++) {
        double c = overlaps(s, (float)h, cap_unit, pp);
        if (!(c > 0.0)) {
            h *= 4.0;
            continue;
        }
        h *= sqrt(M / c);
        good++;
    }
    free(pp);
    s->h = (float)h;
    s->have_h = 1;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The footprint cap in units of h: footprint_cap times the median of
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


/* Direct light from every light at infinity at every eye point: one light
 * sample each (a hash of seed, pass and vertex: the same whatever the
 * thread count), weighted against the merges and the eye path. */
static uint64_t sky_light(gkde_state *s, uint32_t pass)
{
    const cdl_scene *sc = s->scene;
    uint64_t rays = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : rays)
    for (uint32_t q = 0; q < s->npts; q++) {
        const cdl_gkde_eye *ye = gkde_eye_of(s, q);
        cdl_rng rng;
        cdl_rng_seed(&rng, cdl_mix64(s->opt.seed ^ 0x6a09e667f3bcc909ULL ^ ((uint64_t)pass << 32)), ye->y);
        for (uint32_t i = 0; i < sc->nlights; i++) {
            if (!cdl_light_at_infinity(&sc->lights[i]))
                continue;
            float u1 = cdl_rng_float(&rng), u2 = cdl_rng_float(&rng);
            s->acc[q] = cdl_add(s->acc[q], cdl_gkde_sky(&s->g, ye, i, u1, u2, &rays));
        }
    }
    return rays;
}

/* A step's eye and light vertices and their points. */
static int load_step(gkde_state *s, uint32_t pass, uint64_t *rays, cdl_error *err)
{
    double t0 = cdl_time_now();
    int rc = trace_eyes(s, pass, rays, err);
    double t1 = cdl_time_now();
    if (!rc)
        rc = trace_lights(s, pass, rays, err);
    double t2 = cdl_time_now();
    s->st.t_eye += t1 - t0;
    s->st.t_light += t2 - t1;
    s->g.lvs = &s->lvs;
    s->g.evs = &s->evs;
    if (!rc)
        rc = gkde_build_points(s, err);
    if (!rc)
        rc = check_memory(s, err);
    return rc;
}

/* h and the cap come from step 0's vertices, whichever step is rendered
 * first (a distributed render's other processes start elsewhere). */
static void fix_bandwidth(gkde_state *s)
{
    float u = cap_unit(s);
    if (!s->have_h)
        calibrate(s, u);
    s->r_cap = s->h * u;
}

static size_t tally_size(const gkde_state *s)
{
    return 6 * (size_t)s->opt.camera.width * (size_t)s->opt.camera.height;
}

/* The tallies since the last fold join those the plans read. */
static void fold(gkde_state *s, const double *sum)
{
    size_t n = tally_size(s);
    for (size_t i = 0; i < n; i++) {
        double v = (double)s->pv[i] + (sum ? sum[i] : (double)s->pv_new[i]);
        s->pv[i] = v < 4294967295.0 ? (uint32_t)v : UINT32_MAX;
    }
    memset(s->pv_new, 0, n * sizeof *s->pv_new);
    s->fold_at = s->fold_at > UINT32_MAX / 2 ? UINT32_MAX : 2 * s->fold_at;
}

static size_t gkde_adapt_size(const void *self)
{
    return tally_size(self);
}

static uint32_t gkde_adapt_next(const void *self)
{
    return ((const gkde_state *)self)->fold_at;
}

static void gkde_adapt_get(const void *self, double *out)
{
    const gkde_state *s = self;
    for (size_t i = 0, n = tally_size(s); i < n; i++)
        out[i] = (double)s->pv_new[i];
}

static void gkde_adapt_fold(void *self, const double *sum)
{
    fold(self, sum);
}

static int gkde_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    gkde_state *s = self;
    s->cancel = film->cancel;
    double t0 = cdl_time_now();
    int rc = 0;
    while (pass >= s->fold_at)
        fold(s, NULL);
    if (!(s->r_cap > 0.0f) && pass != 0) {
        uint64_t rays = 0;
        if (!(rc = load_step(s, 0, &rays, err)) && !cdl_cancelled(s->cancel))
            fix_bandwidth(s);
    }
    if (!rc)
        rc = load_step(s, pass, &film->rays, err);
    if (rc || cdl_cancelled(s->cancel))
        return rc;
    double t2 = cdl_time_now();
    if (!(s->r_cap > 0.0f))
        fix_bandwidth(s);
    /* consistent: h (and the cap, eq. 7's radii with it) shrinks with the
     * step, h_i^2 = h_0^2 cdl_progressive_r2(i), so the kernel's blur and
     * normalization bias vanish; M stays the cap of trial links per eye
     * vertex, whose candidates fall as h^2 until all are linked */
    float sh = sqrtf(cdl_progressive_r2(&s->opt, pass));
    s->g.h = s->h * sh;
    s->g.r_cap = s->r_cap * sh;
    rc = footprints(s, s->g.h, err);
    if (rc)
        return rc;
    s->g.radius = s->radius;
    s->st.t_count += cdl_time_now() - t2;
    uint64_t lr = gkde_link_all(s, pass);
    if (lr == UINT64_MAX)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory for candidate links");
    film->rays += lr;
    if (s->at_infinity)
        film->rays += sky_light(s, pass);
    rc = check_memory(s, err);
    if (rc)
        return rc;
    if (cdl_cancelled(s->cancel))
        return 0; /* an interrupted step adds nothing */
    /* the step's image: links per eye vertex, emitters the eye paths hit */
    const cdl_camera *cam = &s->opt.camera;
    size_t npix = (size_t)cam->width * (size_t)cam->height;
    memset(s->pixsum, 0, npix * sizeof *s->pixsum);
    double unocc = 0.0;
    for (uint32_t q = 0; q < s->npts; q++) {
        uint32_t y = gkde_point_vertex(s, q);
        s->pixsum[s->epix[y]] = cdl_add(s->pixsum[s->epix[y]], s->acc[q]);
        uint32_t *pv = &s->pv_new[gkde_pv_bucket(s, y)];
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

static void gkde_report(const void *self, cdl_stats *out)
{
    const gkde_state *s = self;
    const gkde_stats *t = &s->st;
    if (!t->steps)
        return;
    double pts = t->points > 0.0 ? t->points : 1.0, tt = t->t_total > 0.0 ? t->t_total : 1.0;
    cdl_stats_printf(out, "gkde: h %.4g%s, %u light paths and %u eye path(s) per pixel per step; per eye vertex and "
           "step %.1f candidate links, %.1f trial links, %.1f unoccluded (M = %u); stored paths %.1f MiB "
           "(peak)\n",
           (double)s->h, s->opt.gkde.bandwidth > 0.0f ? " (given)" : " (calibrated)", s->n_light, s->eye_paths,
           t->candidates / pts, t->trials / pts, t->unoccluded / pts, s->M, (double)t->peak_bytes / 1048576.0);
    cdl_stats_printf(out, "gkde: time over %u steps %.2f s: eye paths %.0f %%, light paths %.0f %%, counting %.0f %%, "
           "linking %.0f %%, shadow rays %.0f %%, scoring %.0f %% (CPU seconds of all threads "
           "for the last three)\n",
           t->steps, t->t_total, 100.0 * t->t_eye / tt, 100.0 * t->t_light / tt, 100.0 * t->t_count / tt,
           100.0 * t->t_link / tt, 100.0 * t->t_rays / tt, 100.0 * t->t_score / tt);
    cdl_stats_add(out, "h", (double)s->h);
    cdl_stats_add(out, "unoccluded_links", t->unoccluded / pts);
    cdl_stats_add(out, "memory_mib", (double)t->peak_bytes / 1048576.0);
    cdl_stats_add(out, "t_eye", t->t_eye);
    cdl_stats_add(out, "t_light", t->t_light);
    cdl_stats_add(out, "t_count", t->t_count);
    cdl_stats_add(out, "t_link", t->t_link);
    cdl_stats_add(out, "t_rays", t->t_rays);
    cdl_stats_add(out, "t_score", t->t_score);
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
    free(s->ball);
    cdl_kd_free(&s->kd);
    free(s->pts);
    free(s->parts);
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
    free(s->eye);
    free((void *)s->eye_ready);
    free(s->pv);
    free(s->pv_new);
    free(s->pixsum);
}

#define AT(f) CDL_PARAM_AT(cdl_options, gkde.f)
static const cdl_param rows[] = {
    {"light_paths", CDL_PARAM_INT, "N", "50000", "light paths per step", 1, 1e8, AT(light_paths)},
    {"eye_paths", CDL_PARAM_INT, "N", "1", "eye paths per pixel and step", 1, 1024, AT(eye_paths)},
    {"links", CDL_PARAM_INT, "M", "", "unoccluded links wanted per eye vertex (default: one per 10000 light paths, at "
     "least 1, so that the calibrated h does not grow as N shrinks)", 1, 100000, AT(links)},
    {"bandwidth", CDL_PARAM_FLOAT, "h", "", "footprint bandwidth of eq. 7 (default: calibrated in the first step so "
     "that an eye vertex lies in about M first-bounce footprints)", 1e-9, 1e3, AT(bandwidth)},
    {"overlaps", CDL_PARAM_FLOAT, "K", "2", "h_0 is calibrated so that an eye vertex in direct light lies in about K "
     "first-bounce footprints (the report: K = M = 10)", 2, 1e4,
     .note = "a point a footprint reaches lies in one at least, so fewer cannot be calibrated to", AT(overlaps)},
    {"footprint_cap", CDL_PARAM_FLOAT, "F", "2", "footprint radii at most F times the median first-bounce one (0: "
     "eq. 7 unbounded)", 0, 1e6, AT(footprint_cap)},
    {"path_memory", CDL_PARAM_INT, "MiB", "4096", "cap on the stored light and eye vertices", 1, 1048576, .unit = "MiB",
     AT(max_mib)},
};
#undef AT
static const cdl_param_table table =
    CDL_PARAM_TABLE("Generalized kernel density estimation (gkde; Bekaert et al. 2003)", rows);
static const cdl_param_table *const tables[] = {&cdl_density_table, &cdl_shadow_table, &table, NULL};

const cdl_integrator_vtbl cdl_gkde_integrator = {
    .params = tables,
    .name = "gkde",
    .summary = "generalized kernel density estimation (Bekaert et al. 2003): footprints, trial links, "
               "shadow rays to the parent",
    .prepare = gkde_prepare,
    .render_pass = gkde_render_pass,
    .destroy = gkde_destroy,
    .report = gkde_report,
    .adapt_size = gkde_adapt_size,
    .adapt_next = gkde_adapt_next,
    .adapt_get = gkde_adapt_get,
    .adapt_fold = gkde_adapt_fold,
    .self_size = sizeof(gkde_state),
};
