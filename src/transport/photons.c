#include "transport/photons.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK 256u              /* paths per parallel work item */
#define MAX_BATCH (1u << 20)    /* paths in flight (bounds the buffered photons) */

typedef struct ph_buf {
    cdl_photon *g, *c;
    uint32_t ng, nc, capg, capc;
    uint64_t rays, cand;
    int fail;
} ph_buf;

typedef struct trace_ctx {
    const cdl_scene *s;
    const cdl_walk *walk;
    const cdl_photon_params *pp;
    float q;
    cdl_sampler_kind kind;
    uint64_t seed;
    uint32_t pass;
} trace_ctx;

static int push(cdl_photon **a, uint32_t *n, uint32_t *cap, const cdl_photon *ph)
{
    if (*n == *cap) {
        uint32_t c = *cap ? 2 * *cap : 1024;
        cdl_photon *p = realloc(*a, sizeof(cdl_photon) * c);
        if (!p)
            return -1;
        *a = p;
        *cap = c;
    }
    (*a)[(*n)++] = *ph;
    return 0;
}

/* Light path i: its photons, each kept or dropped by the deposition test. */
static void trace_path(const trace_ctx *cx, uint64_t i, int caustic_only, cdl_vertex_store *vs, ph_buf *b)
{
    const cdl_photon_params *pp = cx->pp;
    cdl_sampler smp;
    cdl_sampler_start(&smp, cx->kind, cx->seed, i, cx->pass);
    cdl_vs_clear(vs);
    uint32_t nv = cdl_trace_light_subpath(cx->s, cx->walk, &smp, vs, &b->rays);
    if (nv < 2)
        return;
    uint32_t light = (uint32_t)vs->light[0];
    for (uint32_t v = 1; v < nv; v++) {
        if (cdl_mat_is_delta(cx->s->mats[vs->mat[v]].type))
            continue;
        cdl_vec3 beta = vs->beta[v];
        if (cdl_is_black(beta) || !cdl_is_finite3(beta))
            continue;
        b->cand++;
        int32_t par = vs->parent[v];
        int caustic = par > 0 && (vs->flags[par] & CDL_V_DELTA);
        if (!caustic && caustic_only)
            continue;
        float prob = 1.0f;
        /* the cheap test against q first: p(x) is a kd-tree query */
        if (!caustic && pp->caustic_random && cx->q < 1.0f) {
            if (cdl_sampler_cheap(&smp) >= cx->q)
                continue;
            prob = cx->q;
        }
        if (pp->imp) {
            float p = cdl_importance_p(pp->imp, vs->p[v]);
            if (p < pp->eps) {
                if (pp->discard)
                    continue;
                p = pp->eps;
            }
            if (!(p > 0.0f) || (p < 1.0f && cdl_sampler_cheap(&smp) >= p))
                continue;
            prob *= p;
        }
        cdl_photon ph;
        ph.p[0] = vs->p[v].x;
        ph.p[1] = vs->p[v].y;
        ph.p[2] = vs->p[v].z;
        ph.power[0] = beta.x / prob;
        ph.power[1] = beta.y / prob;
        ph.power[2] = beta.z / prob;
        uint32_t flags = (vs->depth[v] == 1 ? CDL_PH_PRIMARY : 0u) | (caustic ? CDL_PH_CAUSTIC : 0u);
        ph.wi = cdl_oct_encode_bits(vs->wi[v], 15) | flags << 30;
        /* the normal of the side the photon arrived on */
        cdl_vec3 ng = cdl_dot(vs->ng[v], vs->wi[v]) < 0.0f ? cdl_neg(vs->ng[v]) : vs->ng[v];
        ph.n = (uint16_t)cdl_oct_encode_bits(ng, 8);
        if (flags & CDL_PH_PRIMARY)
            ph.tag = (uint16_t)(light < CDL_PH_NO_LIGHT ? light : CDL_PH_NO_LIGHT);
        else
            ph.tag = (uint16_t)vs->depth[v]; /* <= maxdepth <= 1024 */
        if (caustic ? push(&b->c, &b->nc, &b->capc, &ph) : push(&b->g, &b->ng, &b->capg, &ph))
            b->fail = 1;
    }
}

/* Two ray offsets at p (the margin every path vertex keeps). */
static float two_offsets(const cdl_scene *s, cdl_vec3 p)
{
    return 2.0f * (s->eps + cdl_maxf(fabsf(p.x), cdl_maxf(fabsf(p.y), fabsf(p.z))) * 1e-5f);
}

cdl_vec3 cdl_photon_vis_origin(const void *scene, cdl_vec3 x, cdl_vec3 nx, cdl_vec3 wx, float lift)
{
    const cdl_scene *s = scene;
    /* back along the ray that found x: the side of x its light reaches,
     * even on a line where a sheet of zero thickness meets a wall */
    cdl_vec3 a = cdl_madd(x, wx, two_offsets(s, x));
    cdl_hit h;
    if (!(lift > 0.0f))
        return a;
    /* the lift itself must not pass through anything (a thin wall just
     * above a floor, a shelf board): half way to the first hit */
    if (cdl_intersect(s, a, nx, lift, &h))
        lift = 0.5f * h.t;
    return cdl_madd(a, nx, lift);
}

int cdl_photon_visible(const void *scene, cdl_vec3 o, cdl_vec3 p, cdl_vec3 wp)
{
    const cdl_scene *s = scene;
    /* back along the photon's own last segment: free space on its side */
    cdl_vec3 b = cdl_madd(p, wp, two_offsets(s, p));
    cdl_vec3 d = cdl_sub(b, o);
    float dl = cdl_length(d);
    if (!(dl > 0.0f))
        return 1;
    return !cdl_occluded(s, o, cdl_scale(d, 1.0f / dl), dl);
}

/* Paths [first, first + n) in chunks of CHUNK on all threads. */
static int run_batch(const trace_ctx *cx, uint64_t first, uint64_t n, int caustic_only, ph_buf *bufs)
{
    int64_t nchunks = (int64_t)((n + CHUNK - 1) / CHUNK);
    int fail = 0;
#pragma omp parallel
    {
        cdl_vertex_store vs;
        cdl_vs_init(&vs);
        int ok = cdl_vs_reserve(&vs, (uint32_t)cx->walk->maxdepth + 2, NULL) == 0;
#pragma omp for schedule(dynamic)
        for (int64_t c = 0; c < nchunks; c++) {
            ph_buf *b = &bufs[c];
            b->ng = b->nc = 0;
            b->rays = b->cand = 0;
            b->fail = !ok;
            uint64_t end = (uint64_t)(c + 1) * CHUNK < n ? (uint64_t)(c + 1) * CHUNK : n;
            for (uint64_t i = (uint64_t)c * CHUNK; ok && i < end; i++)
                trace_path(cx, first + i, caustic_only, &vs, b);
            if (b->fail) {
#pragma omp atomic write
                fail = 1;
            }
        }
        cdl_vs_free(&vs);
    }
    return fail;
}

static int has_emitting_light(const cdl_scene *s)
{
    for (uint32_t i = 0; i < s->nlights; i++)
        if (s->light_select.pmf[i] > 0.0f)
            return 1;
    return 0;
}

int cdl_photons_trace(const cdl_scene *s, const cdl_walk *walk, const cdl_photon_params *pp,
                      cdl_sampler_kind kind, uint64_t seed, uint32_t pass, cdl_photon_map *global,
                      cdl_photon_map *caustic, cdl_photon_stats *st, cdl_error *err)
{
    cdl_pmap_clear(global);
    cdl_pmap_clear(caustic);
    memset(st, 0, sizeof *st);
    if (!s->nlights)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the scene has no lights: no photons to trace");
    if (!has_emitting_light(s))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "no light of the scene emits any power");
    if (!pp->target)
        return cdl_error_set(err, CDL_ERR_USAGE, "photons", 0, "must be at least 1");
    int specular = 0;
    for (uint32_t m = 0; m < s->nmats; m++)
        specular |= cdl_mat_is_delta(s->mats[m].type);
    trace_ctx cx = {s, walk, pp, specular ? pp->q : 1.0f, kind, seed, pass};

    uint32_t maxchunks = MAX_BATCH / CHUNK;
    ph_buf *bufs = calloc(maxchunks, sizeof(ph_buf));
    cdl_vertex_store vs;
    cdl_vs_init(&vs);
    int rc = 0;
    if (!bufs || cdl_vs_reserve(&vs, (uint32_t)walk->maxdepth + 2, err)) {
        free(bufs);
        cdl_vs_free(&vs);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photons", 0, "out of memory");
    }
    /* phase 1: paths until the global map is full */
    /* a first quarter to learn the photons per path (often 2-3: a batch of
     * `target` paths would overshoot), then batches sized by that rate */
    uint64_t next = 0, batch = pp->target / 4 < CHUNK * 16 ? CHUNK * 16 : pp->target / 4;
    while (!rc && global->n < pp->target) {
        if (next >= pp->max_paths) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                               "photon budget cannot be met: %u photons requested, %u stored after %llu "
                               "paths (the limit, photon_paths_max); lower photons, or check that "
                               "the lights reach what the camera sees",
                               pp->target, global->n, (unsigned long long)next);
            break;
        }
        uint64_t nb = batch < MAX_BATCH ? batch : MAX_BATCH;
        nb = nb < pp->max_paths - next ? nb : pp->max_paths - next;
        if (run_batch(&cx, next, nb, 0, bufs)) {
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, "photons", 0, "out of memory");
            break;
        }
        uint32_t nchunks = (uint32_t)((nb + CHUNK - 1) / CHUNK);
        uint64_t done = next + nb;
        for (uint32_t c = 0; c < nchunks && !rc; c++) {
            ph_buf *b = &bufs[c];
            st->rays += b->rays;
            if (global->n + b->ng < pp->target) {
                st->candidates += b->cand;
                rc = cdl_pmap_append(global, b->g, b->ng, err) || cdl_pmap_append(caustic, b->c, b->nc, err);
                continue;
            }
            /* this chunk fills the map: take its paths one by one up to the one that does */
            uint64_t i = next + (uint64_t)c * CHUNK;
            ph_buf one = {0};
            for (; !rc && global->n < pp->target; i++) {
                one.ng = one.nc = 0;
                one.cand = 0;
                trace_path(&cx, i, 0, &vs, &one);
                st->candidates += one.cand;
                if (one.fail)
                    rc = cdl_error_set(err, CDL_ERR_SYSTEM, "photons", 0, "out of memory");
                else
                    rc = cdl_pmap_append(global, one.g, one.ng, err) ||
                         cdl_pmap_append(caustic, one.c, one.nc, err);
            }
            free(one.g);
            free(one.c);
            done = i;
            break;
        }
        next = done;
        if (rc || global->n >= pp->target)
            break;
        /* project the paths still needed from the rate so far */
        double rate = (double)global->n / (double)next;
        if (rate <= 0.0 && next >= (1u << 16)) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                               "photon budget cannot be met: no photon stored after %llu paths (do the "
                               "lights reach any surface%s?%s)",
                               (unsigned long long)next, pp->imp ? " the camera sees" : "",
                               pp->caustic_random && cx.q < 1.0f ? " is caustic_ratio too small?" : "");
            break;
        }
        double need = rate > 0.0 ? (double)(pp->target - global->n) / rate : (double)next * 4.0;
        if (rate > 0.0 && next >= (1u << 16) && (double)next + need > 1.5 * (double)pp->max_paths) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                               "photon budget cannot be met: %u photons need about %.3g paths at the "
                               "rate so far (%.3g stored per path), more than the limit of %llu "
                               "(photon_paths_max); lower photons%s",
                               pp->target, (double)next + need, rate, (unsigned long long)pp->max_paths,
                               pp->imp ? " or raise importance_eps" : "");
            break;
        }
        batch = (uint64_t)(need * 1.05) + CHUNK;
    }
    uint64_t n1 = next, n = next;
    /* phase 2 (prefix mode): the remaining paths fill only the caustic map */
    if (!rc && !pp->caustic_random && cx.q < 1.0f) {
        double want = floor((double)n1 / (double)cx.q);
        if (want > (double)pp->max_paths)
            rc = cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                               "photon budget cannot be met: caustic_ratio %g needs %.3g paths for the "
                               "caustic map, more than the limit of %llu (photon_paths_max)",
                               (double)cx.q, want, (unsigned long long)pp->max_paths);
        n = rc ? n1 : (uint64_t)want;
        for (uint64_t first = n1; !rc && first < n;) {
            uint64_t nb = n - first < MAX_BATCH ? n - first : MAX_BATCH;
            if (run_batch(&cx, first, nb, 1, bufs)) {
                rc = cdl_error_set(err, CDL_ERR_SYSTEM, "photons", 0, "out of memory");
                break;
            }
            for (uint32_t c = 0; c < (nb + CHUNK - 1) / CHUNK && !rc; c++) {
                st->rays += bufs[c].rays;
                st->candidates += bufs[c].cand;
                rc = cdl_pmap_append(caustic, bufs[c].c, bufs[c].nc, err);
            }
            first += nb;
        }
    }
    for (uint32_t c = 0; c < maxchunks; c++) {
        free(bufs[c].g);
        free(bufs[c].c);
    }
    free(bufs);
    cdl_vs_free(&vs);
    if (rc) {
        cdl_pmap_clear(global);
        cdl_pmap_clear(caustic);
        return rc;
    }
    st->paths = n;
    st->paths_global = pp->caustic_random ? n : n1;
    cdl_pmap_scale(global, 1.0f / (float)st->paths_global);
    cdl_pmap_scale(caustic, 1.0f / (float)n);
    if (cdl_pmap_build(global, err) || cdl_pmap_build(caustic, err))
        return err->code;
    return 0;
}
