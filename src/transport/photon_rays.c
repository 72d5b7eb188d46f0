#include "transport/photon_rays.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CHUNK 256u            /* paths per parallel work item */
#define MAX_BATCH (1u << 18)  /* paths in flight */
#define PILOT_PASS 0xfffffff0u /* the pilot's paths are seeded apart from every pass */
#define M0 6.812920690579612   /* 10^(5/6) */
#define A_MU 0.2

/* p~ of the vertex after x_from (eq. 4.8) when x_from sampled direction d
 * (length dlen) with solid-angle density psa, the segment's squared length
 * d2: x_from's density per projected solid angle (a Dirac after a
 * specular bounce counts as CDL_PRAY_DELTA_PDF) times p~(x_from), or x_0's
 * position density, over max(D~^2, d2). 0 where it is undefined. */
static double next_density(const cdl_vertex_store *vs, const double *pt, uint32_t from, cdl_vec3 d, double dlen,
                           double psa, double d2, double d2c)
{
    double perp;
    if (vs->flags[from] & CDL_V_DELTA) {
        perp = CDL_PRAY_DELTA_PDF;
    } else {
        int point = from == 0 && (vs->flags[0] & CDL_V_DELTA_LIGHT);
        cdl_vec3 n = from == 0 ? vs->ng[0] : vs->ns[from];
        double c = point ? 1.0 : fabs(cdl_dot(n, d)) / dlen;
        perp = psa / fmax(c, 1e-6);
    }
    double prev = from == 0 ? vs->pdf_fwd[0] : pt[from];
    double p = prev * perp / fmax(d2c, d2);
    return isfinite(p) ? p : 0.0;
}

/* p~(x_1) of a path from light l at infinity: its direction's density
 * (a distant light's one direction counts as 1, as a point light's one
 * position does) times the disk's 1 / (pi R^2). Rays from the disk are
 * parallel, so the density per area perpendicular to them at x_1 is the
 * disk's and no 1 / D falls off with distance. */
static double disk_density(const cdl_scene *s, const cdl_vertex_store *vs)
{
    const cdl_light *l = &s->lights[vs->light[0]];
    cdl_vec3 w = cdl_normalize(cdl_sub(vs->p[0], vs->p[1])); /* towards the light */
    double p = s->light_select.pmf[vs->light[0]] * cdl_light_pdf_disk(l, w, cdl_v3(0.0f, 0.0f, 0.0f));
    if (!cdl_light_is_delta(l))
        p *= cdl_light_pdf_li(l, cdl_v3(0.0f, 0.0f, 0.0f), w, FLT_MAX);
    return isfinite(p) ? p : 0.0;
}

/* p~ of every vertex of a traced path; 0 where it is undefined. */
static void path_density(const cdl_scene *s, const cdl_vertex_store *vs, uint32_t nv, float d2c, double *pt)
{
    pt[0] = 0.0;
    uint32_t first = 1;
    if (nv > 1 && (vs->flags[0] & CDL_V_INFINITE)) {
        /* y_0 on the disk: pdf_fwd[1] is the disk's density, not one that
         * turns back into a direction's at y_0 */
        pt[1] = disk_density(s, vs);
        first = 2;
    }
    for (uint32_t i = first; i < nv; i++) {
        cdl_vec3 d = cdl_sub(vs->p[i], vs->p[i - 1]);
        double d2 = cdl_dot(d, d), len = sqrt(d2);
        pt[i] = 0.0;
        if (!(len > 0.0))
            continue;
        /* the stored area density back to solid angle at x_{i-1} */
        double cos_i = fabs(cdl_dot(vs->ng[i], d)) / len, pf = vs->pdf_fwd[i];
        int delta = (vs->flags[i - 1] & CDL_V_DELTA) != 0;
        if (!delta && !(pf > 0.0 && cos_i > 1e-6))
            continue;
        pt[i] = next_density(vs, pt, i - 1, d, len, delta ? 0.0 : pf * d2 / cos_i, d2, d2c);
    }
}

/* The budget of the ray ending at x_v: direct (from the light), caustic
 * (every bounce before it specular) or indirect. */
static int category(uint32_t v, int all_specular)
{
    return v == 1 ? CDL_PRAY_DIRECT : all_specular ? CDL_PRAY_CAUSTIC : CDL_PRAY_INDIRECT;
}

typedef struct ray_buf {
    cdl_photon_ray *r;
    uint32_t *path; /* path offset within the batch of each ray */
    uint32_t n, cap;
    uint64_t rays;
    double sum_r, sum_len;
    uint64_t n_stat;
    int fail;
} ray_buf;

typedef struct trace_ctx {
    const cdl_scene *s;
    const cdl_walk *walk;
    const cdl_pray_params *pp; /* NULL: the pilot (statistics only) */
    float S, d2c;
    cdl_sampler_kind kind;
    uint64_t seed;
    uint32_t pass;
    double base[CDL_PRAY_CATS]; /* C / M_c^(1/6) */
    int caustic_only; /* the indirect budget is full: no ray past a path's first diffuse vertex is taken */
} trace_ctx;

static int push(ray_buf *b, const cdl_photon_ray *r, uint32_t path)
{
    if (b->n == b->cap) {
        uint32_t cap = b->cap ? 2 * b->cap : 1024;
        cdl_photon_ray *nr = realloc(b->r, sizeof *nr * cap);
        if (nr)
            b->r = nr;
        uint32_t *np = realloc(b->path, sizeof *np * cap);
        if (np)
            b->path = np;
        if (!nr || !np)
            return -1;
        b->cap = cap;
    }
    b->r[b->n] = *r;
    b->path[b->n++] = path;
    return 0;
}

static double bandwidth(const trace_ctx *cx, int cat, double pt)
{
    const cdl_pray_params *pp = cx->pp;
    /* around the mean bandwidth C m0 mu_C / M^(1/6) (the report prints the
     * bounds without m0, which would put the mean above the upper one) */
    double base = cx->base[cat], mean = base * M0 * pp->mu, lo = mean * pp->R, hi = mean / pp->R;
    if (!(pt > 0.0))
        return hi;
    double h = base * pp->w * pow(pt, -0.5 * pp->S);
    return h < lo ? lo : h > hi ? hi : h;
}

/* Distance from o along d to where it leaves the box [lo, hi] (grown a
 * little), at least `least`. */
static float exit_distance(cdl_vec3 o, cdl_vec3 d, cdl_vec3 lo, cdl_vec3 hi, float least)
{
    const float *po = &o.x, *pd = &d.x, *pl = &lo.x, *ph = &hi.x;
    float t = INFINITY, pad = 0.01f * cdl_length(cdl_sub(hi, lo));
    for (int a = 0; a < 3; a++) {
        if (pd[a] > 0.0f)
            t = fminf(t, (ph[a] + pad - po[a]) / pd[a]);
        else if (pd[a] < 0.0f)
            t = fminf(t, (pl[a] - pad - po[a]) / pd[a]);
    }
    return isfinite(t) && t > least ? t : least;
}

/* Appends ray x_{v-1} -> (x_v or, escaping, o + len d). */
static void add_ray(const trace_ctx *cx, const cdl_vertex_store *vs, uint32_t v, cdl_vec3 d, float len,
                    cdl_vec3 flux, double pt, int cat, double *h_prev, uint32_t off, ray_buf *b)
{
    if (!cx->pp) { /* the pilot */
        if (pt > 0.0) {
            b->sum_r += pow(pt, -0.5 * cx->S);
            b->sum_len += len;
            b->n_stat++;
        }
        return;
    }
    double h = bandwidth(cx, cat, pt);
    double hp = v == 1 ? 0.0 : *h_prev;
    *h_prev = h;
    if (!cx->pp->target[cat] || cdl_is_black(flux) || !cdl_is_finite3(flux))
        return;
    cdl_photon_ray r;
    r.o = vs->p[v - 1];
    r.d = d;
    if (v == 1 && (vs->flags[0] & CDL_V_DELTA_LIGHT)) {
        r.on = cdl_v3(0.0f, 0.0f, 0.0f);
    } else {
        cdl_vec3 n = vs->ng[v - 1];
        r.on = cdl_dot(n, r.d) < 0.0f ? cdl_neg(n) : n;
    }
    r.flux = flux;
    r.len = len;
    r.h0 = (float)(h < hp ? h : hp);
    r.dh = (float)((h > hp ? h - hp : 0.0) / len);
    r.pdf = (float)pt;
    r.depth = (uint16_t)v;
    r.cat = (uint8_t)cat;
    if (push(b, &r, off))
        b->fail = 1;
}

static void trace_path(const trace_ctx *cx, uint64_t i, uint32_t off, cdl_vertex_store *vs, double *pt, ray_buf *b)
{
    cdl_sampler smp;
    cdl_sampler_start(&smp, cx->kind, cx->seed, i, cx->pass);
    cdl_vs_clear(vs);
    cdl_escape esc;
    uint32_t nv = cdl_trace_light_subpath_esc(cx->s, cx->walk, &smp, vs, &b->rays, &esc, cx->caustic_only);
    if (nv < 1)
        return;
    path_density(cx->s, vs, nv, cx->d2c, pt);
    int all_specular = 1; /* every bounce before the current ray's end */
    int disk = (vs->flags[0] & CDL_V_INFINITE) != 0;
    double h_prev = 0.0;
    for (uint32_t v = 1; v < nv; v++) {
        cdl_vec3 d = cdl_sub(vs->p[v], vs->p[v - 1]);
        float len = cdl_length(d);
        int cat = category(v, all_specular);
        if (!(vs->flags[v] & CDL_V_DELTA))
            all_specular = 0; /* for the next ray: x_v scattered it */
        if (v == 1 && disk) {
            /* the ray from the disk of a light at infinity brings direct
             * light, which the eye samples take by light sampling (its
             * origin is no scene point to splat from); x_1's bandwidth
             * starts the next ray's kernel */
            if (cx->pp) /* no flux: sets h_prev only */
                add_ray(cx, vs, v, d, len, cdl_v3(0.0f, 0.0f, 0.0f), pt[1], category(2, all_specular), &h_prev, off,
                        b);
            continue;
        }
        if (!(len > 0.0f) || vs->depth[v] > cx->walk->maxdepth)
            continue;
        add_ray(cx, vs, v, cdl_scale(d, 1.0f / len), len, vs->beta[v], pt[v], cat, &h_prev, off, b);
    }
    /* the ray that left the scene passes eye samples too: it runs to the
     * scene's bounds (not one from the disk that missed the scene) */
    uint32_t last = nv - 1;
    if (!esc.escaped || (last == 0 && disk) || (int)vs->depth[last] + 1 > cx->walk->maxdepth)
        return;
    const cdl_scene *s = cx->s;
    float len = exit_distance(vs->p[last], esc.d, s->bmin, s->bmax, 1e-6f);
    double p = next_density(vs, pt, last, esc.d, 1.0, esc.pdf_dir, (double)len * len, cx->d2c);
    int cat = category(last + 1, all_specular);
    add_ray(cx, vs, last + 1, esc.d, len, esc.beta, p, cat, &h_prev, off, b);
}

/* Paths [first, first + n) in chunks of CHUNK on all threads. */
static int run_batch(const trace_ctx *cx, uint64_t first, uint64_t n, ray_buf *bufs)
{
    int64_t nchunks = (int64_t)((n + CHUNK - 1) / CHUNK);
    int fail = 0;
#pragma omp parallel
    {
        cdl_vertex_store vs;
        cdl_vs_init(&vs);
        uint32_t room = (uint32_t)cx->walk->maxdepth + 2;
        double *pt = malloc(sizeof(double) * room);
        int ok = pt && cdl_vs_reserve(&vs, room, NULL) == 0;
#pragma omp for schedule(dynamic)
        for (int64_t c = 0; c < nchunks; c++) {
            ray_buf *b = &bufs[c];
            b->n = 0;
            b->rays = b->n_stat = 0;
            b->sum_r = b->sum_len = 0.0;
            b->fail = !ok;
            uint64_t end = (uint64_t)(c + 1) * CHUNK < n ? (uint64_t)(c + 1) * CHUNK : n;
            for (uint64_t i = (uint64_t)c * CHUNK; ok && i < end; i++)
                trace_path(cx, first + i, (uint32_t)i, &vs, pt, b);
            if (b->fail) {
#pragma omp atomic write
                fail = 1;
            }
        }
        free(pt);
        cdl_vs_free(&vs);
    }
    return fail;
}

static void free_bufs(ray_buf *bufs, uint32_t n)
{
    for (uint32_t i = 0; bufs && i < n; i++) {
        free(bufs[i].r);
        free(bufs[i].path);
    }
    free(bufs);
}

static int check_lights(const cdl_scene *s, cdl_error *err)
{
    if (!s->nlights)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the scene has no lights: no photons to trace");
    for (uint32_t i = 0; i < s->nlights; i++)
        if (s->light_select.pmf[i] > 0.0f)
            return 0;
    return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the scene's lights emit nothing: no photons to trace");
}

int cdl_pray_pilot(const cdl_scene *s, const cdl_walk *walk, cdl_sampler_kind kind, uint64_t seed,
                   uint32_t n_paths, float S, float d2_clamp, float *w, float *mu, cdl_error *err)
{
    if (check_lights(s, err))
        return err->code;
    trace_ctx cx = {s, walk, NULL, S, d2_clamp, kind, seed, PILOT_PASS, {0}, 0};
    uint32_t nchunks = (n_paths + CHUNK - 1) / CHUNK;
    ray_buf *bufs = calloc(nchunks ? nchunks : 1, sizeof *bufs);
    if (!bufs || run_batch(&cx, 0, n_paths, bufs)) {
        free_bufs(bufs, nchunks);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photon rays", 0, "out of memory");
    }
    double sr = 0.0, sl = 0.0;
    uint64_t n = 0;
    for (uint32_t c = 0; c < nchunks; c++) {
        sr += bufs[c].sum_r;
        sl += bufs[c].sum_len;
        n += bufs[c].n_stat;
    }
    free_bufs(bufs, nchunks);
    if (!n)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                             "no photon of %u pilot paths hit a surface: the lights shine into nothing", n_paths);
    *mu = (float)(A_MU * sl / (double)n);
    *w = (float)(M0 * *mu / (sr / (double)n));
    return 0;
}

void cdl_pray_free(cdl_pray_set *set)
{
    free(set->r);
    memset(set, 0, sizeof *set);
}

static int take(cdl_pray_set *set, const cdl_photon_ray *r)
{
    if (set->n == set->cap) {
        uint32_t cap = set->cap ? 2 * set->cap : 4096;
        cdl_photon_ray *nr = realloc(set->r, sizeof *nr * cap);
        if (!nr)
            return -1;
        set->r = nr;
        set->cap = cap;
    }
    set->r[set->n++] = *r;
    return 0;
}

int cdl_pray_trace(const cdl_scene *s, const cdl_walk *walk, const cdl_pray_params *pp, cdl_sampler_kind kind,
                   uint64_t seed, uint32_t pass, cdl_pray_set *set, cdl_error *err)
{
    set->n = 0;
    memset(set->paths, 0, sizeof set->paths);
    memset(set->count, 0, sizeof set->count);
    set->traced = set->rays = 0;
    if (check_lights(s, err))
        return err->code;
    trace_ctx cx = {s, walk, pp, pp->S, pp->d2_clamp, kind, seed, pass, {0}, 0};
    int open[CDL_PRAY_CATS], nopen = 0;
    for (int c = 0; c < CDL_PRAY_CATS; c++) {
        open[c] = pp->target[c] > 0;
        nopen += open[c];
        double m = (double)pp->target[c];
        cx.base[c] = pp->C / pow(m > 1.0 ? m : 1.0, 1.0 / 6.0) * (pp->bw_scale > 0.0 ? pp->bw_scale : 1.0);
    }
    uint32_t maxchunks = MAX_BATCH / CHUNK;
    ray_buf *bufs = calloc(maxchunks, sizeof *bufs);
    if (!bufs)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "photon rays", 0, "out of memory");
    uint32_t total = 0;
    for (int c = 0; c < CDL_PRAY_CATS; c++)
        total += pp->target[c];
    uint64_t next = 0, batch = total / 4 < CHUNK * 16 ? CHUNK * 16 : total / 4, closed_at = 0;
    int rc = 0;
    while (nopen > 0 && next < pp->max_paths) {
        /* a budget far behind the full ones stops where it is */
        if (closed_at && next >= 4 * closed_at)
            break;
        uint64_t nb = batch < MAX_BATCH ? batch : MAX_BATCH;
        if (next + nb > pp->max_paths)
            nb = pp->max_paths - next;
        /* a budget full before this batch takes none of its rays (below):
         * with the indirect one full, a ray past a path's first diffuse
         * vertex (indirect) would be thrown away, so the paths end there
         * (the caustic budget is typically the last, filling on a small
         * fraction of several times the paths the others need) */
        cx.caustic_only = !open[CDL_PRAY_INDIRECT];
        if (run_batch(&cx, next, nb, bufs)) {
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, "photon rays", 0, "out of memory");
            break;
        }
        uint32_t nchunks = (uint32_t)((nb + CHUNK - 1) / CHUNK);
        uint64_t used = nb;
        /* rays in path order: a budget takes every ray of the paths up to
         * the one that fills it */
        for (uint32_t ch = 0; ch < nchunks && nopen > 0 && !rc; ch++) {
            const ray_buf *b = &bufs[ch];
            set->rays += b->rays;
            for (uint32_t k = 0; k < b->n && !rc; k++) {
                uint32_t path = b->path[k];
                const cdl_photon_ray *r = &b->r[k];
                int c = r->cat;
                /* a budget that filled on an earlier path takes no more */
                if (!open[c] && set->paths[c] <= next + path)
                    continue;
                if (take(set, r))
                    rc = cdl_error_set(err, CDL_ERR_SYSTEM, "photon rays", 0, "out of memory");
                set->count[c]++;
                if (open[c] && set->count[c] >= pp->target[c]) {
                    open[c] = 0;
                    nopen--;
                    set->paths[c] = next + path + 1;
                    if (!closed_at || set->paths[c] > closed_at)
                        closed_at = set->paths[c];
                }
            }
            if (nopen == 0) {
                /* the last budget filled in this chunk: later paths are not used */
                uint64_t last = 0;
                for (int c = 0; c < CDL_PRAY_CATS; c++)
                    last = set->paths[c] > last ? set->paths[c] : last;
                used = last - next;
            }
        }
        next += used;
        /* the rate so far sizes the next batch */
        if (set->n && nopen > 0) {
            double per_path = (double)set->n / (double)next;
            uint64_t need = 0;
            for (int c = 0; c < CDL_PRAY_CATS; c++)
                if (open[c])
                    need += pp->target[c] - set->count[c];
            double want = 1.1 * (double)need / per_path + CHUNK;
            batch = want < (double)MAX_BATCH ? (uint64_t)want : MAX_BATCH;
        } else {
            batch = batch * 2 < MAX_BATCH ? batch * 2 : MAX_BATCH;
        }
    }
    free_bufs(bufs, maxchunks);
    if (rc)
        return rc;
    set->traced = next;
    for (int c = 0; c < CDL_PRAY_CATS; c++)
        if (open[c])
            set->paths[c] = next; /* did not fill: every path traced counts */
    /* power per path of each budget */
    for (uint32_t k = 0; k < set->n; k++) {
        cdl_photon_ray *r = &set->r[k];
        r->flux = cdl_scale(r->flux, set->paths[r->cat] ? 1.0f / (float)set->paths[r->cat] : 0.0f);
    }
    return 0;
}
