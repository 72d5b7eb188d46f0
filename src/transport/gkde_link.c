#include "transport/gkde_link.h"

#include "transport/subpath.h"

#define MAX_PATH 2100 /* two subpaths of at most maxdepth (1024) + 2 vertices */

/* Per-vertex densities of a full path z_0 .. z_{n-1} (light to eye). */
typedef struct path_pdfs {
    float pl[MAX_PATH]; /* area density of z_i sampled from the light side (z_0: as a light-path start) */
    float pe[MAX_PATH]; /* area density of z_i sampled from the eye side */
    uint8_t delta[MAX_PATH];
    int n;
    int s0;    /* the eye path alone can sample it (z_0 on an area light or the sky) */
    int inf;   /* z_0 at infinity: no merge at z_1 (x_0 on the disk is no surface
                * point), light sampling at z_1 instead */
    float pls; /* that light sample's solid-angle density of z_0's direction */
} path_pdfs;

/* z_0 on light li at infinity, seen along w from z_1: pl_0 the light
 * path's density of that start (light choice times direction, solid angle
 * as in bdpt) and pls light sampling's (every light at infinity sampled
 * once per eye vertex); a distant light's Dirac direction cancels in both. */
static void infinite_start(const cdl_scene *s, int32_t li, cdl_vec3 w, path_pdfs *pp)
{
    const cdl_light *l = &s->lights[li];
    pp->inf = 1;
    pp->pls = l->type == CDL_LIGHT_DISTANT ? 1.0f : cdl_light_pdf_li(l, cdl_v3(0, 0, 0), w, INFINITY);
    pp->pl[0] = s->light_select.pmf[li] * pp->pls;
    pp->delta[0] = 0;
}

static cdl_vec3 point_normal(const cdl_vertex_store *vs, uint32_t i)
{
    return (vs->flags[i] & (CDL_V_CAMERA | CDL_V_DELTA_LIGHT)) ? cdl_v3(0.0f, 0.0f, 0.0f) : vs->ng[i];
}

static float log1(float p) { return p > 0.0f ? logf(p) : 0.0f; } /* Dirac or unknown: cancels */

/* Weight of strategy `cur` (merge at z_cur; 0: the eye path alone) among
 * every strategy that can sample the path: the balance heuristic over
 * d_j = prod_{i<=j} pl_i prod_{i>=j} pe_i N pi R_j^2 (merging at z_j: the
 * light path to z_{j-1}, a light vertex in a footprint of radius R_j of
 * eq. 7 around z_j, found by one of N light paths) and d_0 = prod pe_i. It
 * is eq. 9 for two strategies; a partition of unity for any path, so the
 * strategies' sum stays consistent. */
static float weight_log(const cdl_gkde_ctx *g, const path_pdfs *pp, int cur)
{
    int n = pp->n;
    double lsum_pe[MAX_PATH + 1];
    lsum_pe[n] = 0.0;
    for (int i = n - 1; i >= 0; i--)
        lsum_pe[i] = lsum_pe[i + 1] + log1(pp->pe[i]);
    double ld[MAX_PATH];
    uint8_t ok[MAX_PATH];
    double lpl = log1(pp->pl[0]), best = -INFINITY;
    double lnpi = log((double)g->n_light * CDL_PI);
    float r = 0.0f;
    ok[0] = (uint8_t)pp->s0;
    ld[0] = lsum_pe[0];
    if (ok[0])
        best = ld[0];
    for (int j = 1; j < n; j++) {
        lpl += log1(pp->pl[j]);
        r = cdl_footprint_radius(g->h, pp->pl[j], r, g->r_cap);
        ok[j] = !pp->delta[j] && !pp->delta[j - 1] && r > 0.0f;
        ld[j] = lpl + lsum_pe[j] + lnpi + 2.0 * log((double)r);
        if (j == 1 && pp->inf) { /* light sampling at z_1 */
            ok[j] = !pp->delta[1];
            ld[j] = log1(pp->pls) + lsum_pe[1];
        }
        if (ok[j] && ld[j] > best)
            best = ld[j];
    }
    if (!ok[cur] || !isfinite(best))
        return 0.0f;
    double sum = 0.0;
    for (int j = 0; j < n; j++)
        if (ok[j])
            sum += exp(ld[j] - best);
    return (float)(exp(ld[cur] - best) / sum);
}

static double nz(float p) { return p > 0.0f ? (double)p : 1.0; } /* as log1: a Dirac density cancels */

/* The same weight by the ratios d_j / d_0 in double (no logarithms: the
 * cost of most links' weight); the logarithms when a ratio overflows. */
static float weight(const cdl_gkde_ctx *g, const path_pdfs *pp, int cur)
{
    int n = pp->n;
    double npi = (double)g->n_light * CDL_PI, b = 1.0, sum = pp->s0 ? 1.0 : 0.0;
    double dcur = cur == 0 ? sum : 0.0;
    float r = 0.0f;
    for (int j = 1; j < n; j++) {
        b *= j == 1 ? nz(pp->pl[0]) * nz(pp->pl[1]) / nz(pp->pe[0]) : nz(pp->pl[j]) / nz(pp->pe[j - 1]);
        r = cdl_footprint_radius(g->h, pp->pl[j], r, g->r_cap);
        int ls = j == 1 && pp->inf; /* light sampling at z_1 */
        if (pp->delta[j] || (!ls && (pp->delta[j - 1] || !(r > 0.0f))))
            continue;
        double d = ls ? nz(pp->pls) / nz(pp->pe[0]) : b * npi * (double)r * (double)r;
        sum += d;
        if (j == cur)
            dcur = d;
    }
    if (!(dcur > 0.0))
        return 0.0f;
    if (!(sum < INFINITY))
        return weight_log(g, pp, cur);
    return (float)(dcur / sum);
}

/* The eye vertices of y's path from y (depth l) down to y_1 fill z_k ..
 * z_{k+l-1}; light-side densities from z_{k+2} on are the stored reverse
 * ones (the caller sets z_k and z_{k+1}). Returns 0 if too long. */
static int fill_eye(const cdl_vertex_store *evs, uint32_t y, int k, path_pdfs *pp)
{
    int l = evs->depth[y];
    if (k + l > MAX_PATH)
        return 0;
    pp->n = k + l;
    int32_t v = (int32_t)y;
    for (int i = k; i < k + l; i++, v = evs->parent[v]) {
        pp->pe[i] = evs->pdf_fwd[v];
        pp->pl[i] = evs->pdf_rev[v];
        pp->delta[i] = (evs->flags[v] & CDL_V_DELTA) != 0;
    }
    return 1;
}

/* fill_eye from y's record when it holds the whole eye path. */
static int fill_eye_rec(const cdl_gkde_ctx *g, const cdl_gkde_eye *ye, int k, path_pdfs *pp)
{
    int l = ye->depth;
    if (l > CDL_GKDE_EYE_INLINE)
        return fill_eye(g->evs, ye->y, k, pp);
    if (k + l > MAX_PATH)
        return 0;
    pp->n = k + l;
    for (int i = 0; i < l; i++) {
        pp->pe[k + i] = ye->pe[i];
        pp->pl[k + i] = ye->pl[i];
        pp->delta[k + i] = (uint8_t)(ye->delta >> i & 1);
    }
    return 1;
}

static void vertex_init(const cdl_gkde_ctx *g, const cdl_vertex_store *vs, uint32_t i, cdl_gkde_vertex *v)
{
    v->vs = vs;
    v->i = i;
    if (!(vs->flags[i] & CDL_V_LIGHT)) /* a light-path start scatters by its emission */
        cdl_vs_bsdf(g->cx.scene, vs, i, &v->b);
}

static cdl_vec3 vertex_f(const cdl_gkde_ctx *g, const cdl_gkde_vertex *v, cdl_vec3 from, cdl_vec3 to,
                         int light_side)
{
    return cdl_vertex_f_bsdf(&g->cx, v->vs, v->i, &v->b, from, to, light_side);
}

/* Area density at `to` (normal nt) of sampling it from the built vertex. */
static float vertex_pdf(const cdl_gkde_ctx *g, const cdl_gkde_vertex *v, cdl_vec3 from, cdl_vec3 to,
                        cdl_vec3 nt)
{
    cdl_vec3 p = v->vs->p[v->i], w = cdl_sub(to, p);
    float len = cdl_length(w);
    if (!(len > 0.0f))
        return 0.0f;
    float sa = cdl_vertex_pdf_sa_bsdf(&g->cx, v->vs, v->i, &v->b, from, cdl_scale(w, 1.0f / len));
    return cdl_pdf_to_area(sa, p, to, nt);
}

void cdl_gkde_parent_init(const cdl_gkde_ctx *g, uint32_t xk, cdl_gkde_parent *par)
{
    const cdl_vertex_store *lvs = g->lvs;
    int32_t xp = lvs->parent[xk];
    par->xk = xk;
    par->ok = xp >= 0 && !(lvs->flags[xp] & (CDL_V_DELTA | CDL_V_INFINITE));
    if (!par->ok)
        return;
    vertex_init(g, lvs, (uint32_t)xp, &par->xp);
    par->xpp = lvs->parent[xp];
    par->from = par->xpp >= 0 ? lvs->p[par->xpp] : lvs->p[xp];
    par->nx = (lvs->flags[xp] & CDL_V_DELTA_LIGHT) ? cdl_v3(0.0f, 0.0f, 0.0f) : lvs->ns[xp];
    /* the footprint's disc seen from x_{k-1} (eq. 8b); a grazing x_k has
     * a vanishing disc, kept finite */
    par->cos_k = cdl_maxf(fabsf(cdl_dot(lvs->ng[xk], lvs->wi[xk])), 1e-3f);
}

void cdl_gkde_eye_init(const cdl_gkde_ctx *g, uint32_t y, cdl_gkde_eye *e)
{
    const cdl_vertex_store *evs = g->evs;
    cdl_vs_bsdf(g->cx.scene, evs, y, &e->b);
    uint32_t ye = (uint32_t)evs->parent[y];
    e->p = evs->p[y];
    e->ns = evs->ns[y];
    e->beta = evs->beta[y];
    e->to = evs->p[ye];
    e->to_n = point_normal(evs, ye);
    e->y = y;
    e->depth = evs->depth[y];
    e->delta = 0;
    int32_t v = (int32_t)y;
    for (int i = 0; i < e->depth && i < CDL_GKDE_EYE_INLINE; i++, v = evs->parent[v]) {
        e->pe[i] = evs->pdf_fwd[v];
        e->pl[i] = evs->pdf_rev[v];
        e->delta |= (uint8_t)(((evs->flags[v] & CDL_V_DELTA) != 0) << i);
    }
}

/* Area density at `to` (normal nt) of y sampling it, light arriving from `from`. */
static float eye_pdf(const cdl_gkde_eye *e, cdl_vec3 from, cdl_vec3 to, cdl_vec3 nt)
{
    cdl_vec3 w = cdl_sub(to, e->p);
    float len = cdl_length(w);
    if (!(len > 0.0f))
        return 0.0f;
    float sa = cdl_bsdf_pdf(&e->b, cdl_normalize(cdl_sub(from, e->p)), cdl_scale(w, 1.0f / len));
    return cdl_pdf_to_area(sa, e->p, to, nt);
}

cdl_vec3 cdl_gkde_link(const cdl_gkde_ctx *g, const cdl_gkde_parent *par, const cdl_gkde_eye *ye,
                       cdl_gkde_link_state *ls)
{
    const cdl_vertex_store *lvs = g->lvs;
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    if (!par->ok)
        return zero;
    uint32_t xp = par->xp.i;
    cdl_vec3 px = lvs->p[xp], py = ye->p, d = cdl_sub(py, px);
    float r2 = cdl_dot(d, d);
    if (!(r2 > 0.0f))
        return zero;
    cdl_vec3 w = cdl_scale(d, 1.0f / sqrtf(r2));
    cdl_vec3 fl = vertex_f(g, &par->xp, par->from, py, 1);
    if (cdl_is_black(fl))
        return zero;
    cdl_vec3 fe = cdl_bsdf_eval(&ye->b, cdl_neg(w), cdl_normalize(cdl_sub(ye->to, py)), 0);
    if (cdl_is_black(fe))
        return zero;
    float p_sa = cdl_vertex_pdf_sa_bsdf(&g->cx, lvs, xp, &par->xp.b, par->from, w);
    if (!(p_sa > 0.0f))
        return zero;
    float cos_x = cdl_is_black(par->nx) ? 1.0f : fabsf(cdl_dot(par->nx, w));
    float cos_y = fabsf(cdl_dot(ye->ns, w));
    float R = g->radius[par->xk];
    float kern = cos_x * cos_y / (CDL_PI * R * R * par->cos_k * p_sa);
    cdl_vec3 c = cdl_mul(cdl_mul(lvs->beta[xp], fl), cdl_mul(fe, ye->beta));
    /* x_k exists only if the light path survived Russian roulette at x_{k-1} */
    c = cdl_scale(c, kern / (g->n_light * lvs->rr[xp]));
    if (cdl_is_black(c) || !cdl_is_finite3(c))
        return zero;
    ls->ye = ye;
    ls->p_sa = p_sa;
    return c;
}

float cdl_gkde_link_weight(const cdl_gkde_ctx *g, const cdl_gkde_parent *par, const cdl_gkde_link_state *ls)
{
    const cdl_vertex_store *lvs = g->lvs;
    const cdl_gkde_eye *ye = ls->ye;
    uint32_t xp = par->xp.i;
    cdl_vec3 px = lvs->p[xp], py = ye->p;
    /* the path: x_0 .. x_{k-1}, then y_l .. y_1 */
    path_pdfs pp;
    int k = lvs->depth[xp] + 1;
    if (!fill_eye_rec(g, ye, k, &pp))
        return 0.0f;
    int32_t v = (int32_t)xp, x0 = v, x1 = v;
    for (int i = k - 1; i >= 0; i--, v = lvs->parent[v]) {
        pp.pl[i] = lvs->pdf_fwd[v];
        pp.pe[i] = lvs->pdf_rev[v];
        pp.delta[i] = i > 0 && (lvs->flags[v] & CDL_V_DELTA) != 0;
        x1 = x0;
        x0 = v;
    }
    pp.s0 = !(lvs->flags[x0] & CDL_V_DELTA_LIGHT);
    pp.inf = 0;
    if (lvs->flags[x0] & CDL_V_INFINITE)
        infinite_start(g->cx.scene, lvs->light[x0], lvs->wi[x1], &pp);
    /* densities through the new edge x_{k-1} -> y, both ways */
    pp.pl[k] = cdl_pdf_to_area(ls->p_sa, px, py, ye->b.ng);
    if (k + 1 < pp.n)
        pp.pl[k + 1] = eye_pdf(ye, px, ye->to, ye->to_n);
    pp.pe[k - 1] = eye_pdf(ye, ye->to, px, point_normal(lvs, xp));
    if (k == 2 && pp.inf) /* x_1 sampling the direction to x_0: solid angle */
        pp.pe[0] = cdl_vertex_pdf_sa_bsdf(&g->cx, lvs, xp, &par->xp.b, py, lvs->wi[xp]);
    else if (k >= 2)
        pp.pe[k - 2] = vertex_pdf(g, &par->xp, py, par->from, point_normal(lvs, (uint32_t)par->xpp));
    return weight(g, &pp, k);
}

cdl_vec3 cdl_gkde_emitted(const cdl_gkde_ctx *g, uint32_t y)
{
    const cdl_vertex_store *evs = g->evs;
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    if (!(evs->flags[y] & CDL_V_EMITTER) || evs->light[y] < 0)
        return zero;
    const cdl_light *l = &g->cx.scene->lights[evs->light[y]];
    int inf = (evs->flags[y] & CDL_V_INFINITE) != 0; /* the eye path left the scene */
    cdl_vec3 Le = inf ? cdl_light_env_Le(l, cdl_neg(evs->wi[y])) : cdl_light_Le_uv(l, evs->ng[y], evs->wi[y], evs->u[y], evs->v[y]);
    if (cdl_is_black(Le))
        return zero;
    cdl_vec3 c = cdl_mul(evs->beta[y], Le);
    path_pdfs pp;
    if (!fill_eye(evs, y, 0, &pp))
        return zero;
    if (pp.n == 1)
        return c; /* seen directly: nothing else samples it */
    pp.s0 = 1;
    pp.delta[0] = 0;
    pp.inf = 0;
    int32_t z1 = evs->parent[y];
    if (inf) {
        infinite_start(g->cx.scene, evs->light[y], cdl_neg(evs->wi[y]), &pp);
        pp.pl[1] = cdl_light_pdf_disk(l, evs->wi[y], evs->ng[z1]);
    } else {
        pp.pl[0] = cdl_light_pdf_origin(g->cx.scene, evs->light[y]);
        pp.pl[1] = cdl_pdf_to_area(cdl_light_pdf_dir(l, evs->ng[y], evs->wi[y]), evs->p[y], evs->p[z1],
                                   point_normal(evs, (uint32_t)z1));
    }
    return cdl_scale(c, weight(g, &pp, 0));
}

cdl_vec3 cdl_gkde_sky(const cdl_gkde_ctx *g, const cdl_gkde_eye *ye, uint32_t li, float u1, float u2,
                      uint64_t *rays)
{
    const cdl_scene *s = g->cx.scene;
    const cdl_light *l = &s->lights[li];
    cdl_vec3 zero = cdl_v3(0.0f, 0.0f, 0.0f);
    cdl_light_sample ls;
    if (!cdl_light_sample_li(l, ye->p, u1, u2, &ls) || !(ls.pdf > 0.0f))
        return zero;
    cdl_vec3 wo = cdl_normalize(cdl_sub(ye->to, ye->p));
    cdl_vec3 f = cdl_bsdf_eval(&ye->b, wo, ls.wi, 0);
    if (cdl_is_black(f))
        return zero;
    /* the path z_0 (at infinity), z_1 = y, ..., y_1 */
    path_pdfs pp;
    if (!fill_eye_rec(g, ye, 1, &pp))
        return zero;
    pp.s0 = !cdl_light_is_delta(l);
    infinite_start(s, (int32_t)li, ls.wi, &pp);
    pp.pe[0] = cdl_bsdf_pdf(&ye->b, wo, ls.wi);
    pp.pl[1] = cdl_light_pdf_disk(l, ls.wi, ye->b.ng);
    if (pp.n > 2)
        pp.pl[2] = eye_pdf(ye, cdl_add(ye->p, ls.wi), ye->to, ye->to_n);
    float w = weight(g, &pp, 1);
    if (!(w > 0.0f))
        return zero;
    (*rays)++;
    if (!cdl_light_sample_visible(s, l, ye->p, ye->b.ng, &ls))
        return zero;
    float cos = fabsf(cdl_dot(ls.wi, ye->ns));
    return cdl_scale(cdl_mul(cdl_mul(f, ls.Li), ye->beta), w * cos / ls.pdf);
}
