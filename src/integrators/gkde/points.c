/* gkde's stages 3 to 5 (§5 of Bekaert et al. 2003) on the eye points:
 * candidate counting with one ball query per footprint, stratified trial
 * linking (eq. 10), one shadow-ray bundle per footprint and the scores
 * (transport/gkde_link.c). The points are split into kd subtrees that one
 * thread owns; each meets the footprints in light-vertex order, so the
 * image does not depend on the thread count. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/log.h"
#include "core/rng.h"
#include "integrators/gkde/points.h"

#define MAX_BUNDLE 4096 /* links per footprint and subtree traced at once */
#define RANGE 0x80000000u /* a candidate record entry starting a range of points */

/* The kd-tree over the eye vertices that can be linked, its points moved
 * into tree order, and the subtrees threads own. */
int gkde_build_points(gkde_state *s, cdl_error *err)
{
    const cdl_vertex_store *e = &s->evs;
    uint32_t n = 0;
    for (uint32_t i = 0; i < e->n; i++)
        n += !(e->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA | CDL_V_INFINITE)) && e->depth[i] <= s->opt.maxdepth;
    if (n >= RANGE)
        return cdl_error_set(err, CDL_ERR_USAGE, "gkde", 0, "%u eye vertices: more than 2^31 per step", n);
    float *pts = malloc(sizeof(float) * 4 * (n ? n : 1));
    if (!pts)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    n = 0;
    for (uint32_t i = 0; i < e->n; i++) {
        if ((e->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA | CDL_V_INFINITE)) || e->depth[i] > s->opt.maxdepth)
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
    GROW(count) GROW(tested) GROW(unocc) GROW(wsum) GROW(scale) GROW(cum) GROW(acc) GROW(pdepth) GROW(eye) GROW(eye_ready)
#undef GROW
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < n; q++) {
        uint32_t y = gkde_point_vertex(s, q);
        s->pdepth[q] = s->evs.depth[y];
        atomic_init(&s->eye_ready[q], 0);
    }
    free(s->parts);
    /* about four parts per thread; results do not depend on the split */
    int depth = 1;
    while (depth < CDL_KD_PART_MAX_DEPTH && (1 << depth) < 4 * omp_get_max_threads())
        depth++;
    s->parts = malloc(sizeof(cdl_kd_part) << depth);
    if (!s->parts)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
    s->nparts = cdl_kd_parts(&s->kd, n, depth, s->parts);
    if (s->nparts > s->nrec) {
        struct rec_buf *r = realloc(s->rec, sizeof *r * s->nparts);
        if (!r)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "gkde", 0, "out of memory");
        memset(r + s->nrec, 0, sizeof *r * (s->nparts - s->nrec));
        s->rec = r;
        s->nrec = s->nparts;
    }
    return 0;
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

/* A range of points inside the footprint: one record entry (RANGE | a, b)
 * when every point in it may be linked. */
static void count_range(void *ctx, uint32_t a, uint32_t b)
{
    count_ctx *c = ctx;
    gkde_state *s = c->s;
    uint32_t ok = 1;
    for (uint32_t q = a; q < b; q++)
        ok &= (int)s->pdepth[q] <= c->max_eye_depth;
    if (!ok || b - a < 3) {
        for (uint32_t q = a; q < b; q++)
            count_cb(ctx, q, 0.0f);
        return;
    }
    if (rec_push(c->r, RANGE | a) || rec_push(c->r, b))
        return;
    for (uint32_t q = a; q < b; q++) {
        s->count[q]++;
        s->wsum[q] += c->a;
    }
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
    if (c->n == MAX_BUNDLE) {
        score_links(s, c);
        c->n = 0;
    }
    /* branch-free (most candidates are drawn no time, unpredictably): a
     * point with scale 0 takes every candidate once, at weight 1 */
    double sc = s->scale[q], ev = c->a * sc;
    cdl_strat st = {sc, s->cum[q]};
    uint32_t k = cdl_strat_next(&st, c->a);
    s->cum[q] = st.cum;
    k = sc > 0.0 ? k : 1;
    c->q[c->n] = q;
    c->w[c->n] = (float)((double)k / (sc > 0.0 ? ev : 1.0)); /* drawn k times, expected a m / W */
    c->n += k > 0;
    c->trials += k > 0;
}

#define PREFETCH 8 /* links ahead: a record is a few cache lines anywhere in the part */

static void prefetch_eye(const gkde_state *s, uint32_t q)
{
#if defined(__GNUC__)
    const char *p = (const char *)&s->eye[q];
    for (size_t o = 0; o < sizeof(cdl_gkde_eye); o += 64)
        __builtin_prefetch(p + o);
#else
    (void)s, (void)q;
#endif
}

static void score_links(gkde_state *s, link_ctx *lc)
{
    const cdl_vertex_store *l = &s->lvs;
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
    for (uint32_t i = 0; i < lc->n && i < PREFETCH; i++)
        prefetch_eye(s, lc->q[i]);
    for (uint32_t i = 0; i < lc->n; i++) {
        uint32_t q = lc->q[i];
        if (i + PREFETCH < lc->n)
            prefetch_eye(s, lc->q[i + PREFETCH]);
        const cdl_gkde_eye *ye = gkde_eye_of(s, q);
        cdl_vec3 c = cdl_gkde_link(&s->g, &par, ye, &b->ls[nb]);
        if (cdl_is_black(c))
            continue;
        cdl_vec3 d = cdl_sub(ye->p, px);
        cdl_vec3 o = point ? px : cdl_offset(s->scene, px, l->ng[xp], d);
        cdl_vec3 end = cdl_offset(s->scene, ye->p, ye->b.ng, cdl_neg(d));
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
    if (s->opt.single_shadow_rays) /* shadow_rays single: for comparison */
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

/* Stages 3 to 5 over the subtrees; returns the shadow rays traced. */
uint64_t gkde_link_all(gkde_state *s, uint32_t pass)
{
    uint32_t n = s->npts;
    double M = (double)s->M;
    /* stage 3: candidates */
    double t0 = cdl_time_now();
#pragma omp parallel for schedule(dynamic, 1)
    for (uint32_t g = 0; g < s->nparts; g++) {
        const cdl_kd_part *sg = &s->parts[g];
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
            const float *b = &s->ball[4 * (size_t)a];
            if (!cdl_kd_part_meets(sg, cdl_v3(b[0], b[1], b[2]), b[3]))
                continue;
            uint32_t xk = s->lv[a];
            float R = b[3];
            c.a = accept_weight(s, xk);
            c.max_eye_depth = s->opt.maxdepth - (int)s->lvs.depth[xk] + 1;
            size_t at = r->n;
            if (rec_push(r, a) || rec_push(r, 0))
                break;
            cdl_kd_part_ball(&s->kd, sg, s->lvs.p[xk], R * R, count_cb, count_range, &c);
            if (r->n == at + 2)
                r->n = at; /* none */
            else
                r->v[at + 1] = (uint32_t)(r->n - at - 2);
        }
    }
    size_t rec_bytes = 0;
    for (uint32_t g = 0; g < s->nparts; g++) {
        if (s->rec[g].fail)
            return UINT64_MAX;
        rec_bytes += s->rec[g].cap * sizeof(uint32_t);
    }
    s->rec_bytes = rec_bytes;
    /* stage 4's plan: M / P_vis draws, or every candidate */
    uint64_t cand = 0;
#pragma omp parallel for schedule(static) reduction(+ : cand)
    for (uint32_t q = 0; q < n; q++) {
        uint32_t y = gkde_point_vertex(s, q);
        const uint32_t *pv = &s->pv[gkde_pv_bucket(s, y)];
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
    s->st.candidates += (double)cand;
    /* stages 4 and 5: trial links, shadow-ray bundles, scores; the parts
     * with the most candidate records first, so the threads finish
     * together (each part's links are its own: the same result) */
    uint32_t *order = malloc(sizeof *order * (s->nparts ? s->nparts : 1));
    if (!order)
        return UINT64_MAX;
    for (uint32_t j = 0; j < s->nparts; j++) {
        uint32_t i = j;
        for (; i > 0 && s->rec[order[i - 1]].n < s->rec[j].n; i--)
            order[i] = order[i - 1];
        order[i] = j;
    }
    double t_link = 0.0, t_rays = 0.0, t_score = 0.0;
    uint64_t trials = 0, rays = 0;
#pragma omp parallel reduction(+ : t_link, t_rays, t_score, trials, rays)
    {
        link_ctx *lc = malloc(sizeof *lc);
        bundle *b = malloc(sizeof *b);
#pragma omp for schedule(dynamic, 1)
        for (uint32_t j = 0; j < s->nparts; j++) {
            const uint32_t g = order[j];
            if (!lc || !b || cdl_cancelled(s->cancel))
                continue;
            const cdl_kd_part *sg = &s->parts[g];
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
                for (uint32_t j = 0; j < c; j++) {
                    if (!(qs[j] & RANGE)) {
                        link_point(lc, qs[j]);
                        continue;
                    }
                    for (uint32_t q = qs[j] & ~RANGE; q < qs[j + 1]; q++)
                        link_point(lc, q);
                    j++;
                }
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
    free(order);
    s->st.t_link += t_link;
    s->st.t_rays += t_rays;
    s->st.t_score += t_score;
    s->st.trials += (double)trials;
    return rays;
}
