/* The generalized kernel estimator of Bekaert et al. 2003 (gkde): links
 * between a light vertex x_k's footprint sphere and an eye vertex y inside
 * it, scored with the true BSDFs, cosines and visibility of the edge from
 * x_k's parent x_{k-1} to y (eq. 4, 8), weighted against the other ways
 * the same path could have been sampled (eq. 9, generalized) and
 * subsampled by stratified trial linking (eq. 10).
 *
 * A full path is z_0 (on a light) ... z_{n-1} (the first eye vertex y_1;
 * the camera is left out: every strategy shares it). Merging at z_j takes
 * the light subpath z_0 .. z_{j-1} plus a light vertex landing near z_j,
 * and the eye subpath from the camera down to z_j. */
#ifndef CDL_GKDE_LINK_H
#define CDL_GKDE_LINK_H

#include <math.h>

#include "transport/connect.h"

/* Footprint radius of eq. 7 from the light-side area density p of a
 * vertex and its parent's radius: h / sqrt(p) + R_parent, at most cap. A
 * vertex after a specular bounce (p = 0: a Dirac density) adds nothing of
 * its own. */
static inline float cdl_footprint_radius(float h, float pdf_area, float r_parent, float cap)
{
    float r = (pdf_area > 0.0f ? h / sqrtf(pdf_area) : 0.0f) + r_parent;
    return r < cap ? r : cap;
}

/* Stratified sampling of a discrete pdf (eq. 10, §5): m draws from the
 * weights a_i / W of one eye vertex's candidates, visited in a fixed
 * order, with a single offset u in [0, 1). Candidate i is drawn
 * floor(C_i + u) - floor(C_{i-1} + u) times, C_i = m (a_1 + .. + a_i) / W:
 * in expectation m a_i / W times, never more than one draw away from it. */
typedef struct cdl_strat {
    double scale; /* m / W */
    double cum;   /* C of the candidates so far, plus u */
} cdl_strat;

static inline void cdl_strat_init(cdl_strat *s, double m, double wsum, double u)
{
    s->scale = wsum > 0.0 ? m / wsum : 0.0;
    s->cum = u;
}

/* Draws of the next candidate (weight a). */
static inline uint32_t cdl_strat_next(cdl_strat *s, double a)
{
    double before = floor(s->cum);
    s->cum += a * s->scale;
    return (uint32_t)(floor(s->cum) - before);
}

/* What scoring a link needs besides the two stores. */
typedef struct cdl_gkde_ctx {
    cdl_connect_ctx cx;
    const cdl_vertex_store *lvs, *evs;
    const float *radius; /* footprint radius of each light vertex */
    float h;             /* bandwidth (eq. 7) */
    float r_cap;         /* largest footprint radius */
    float n_light;       /* light paths per step: the merge strategies' sample count */
} cdl_gkde_ctx;

/* A vertex with its BSDF built once (a light path's start has none: it
 * scatters by its emission distribution). */
typedef struct cdl_gkde_vertex {
    const cdl_vertex_store *vs;
    uint32_t i;
    cdl_bsdf b;
} cdl_gkde_vertex;

/* What the links of one footprint share: x_k, its parent x_{k-1} (with
 * its BSDF) and the parent's own predecessor. */
typedef struct cdl_gkde_parent {
    uint32_t xk;
    int32_t xpp;          /* x_{k-2}, or -1 */
    cdl_gkde_vertex xp;
    cdl_vec3 from;        /* position of x_{k-2} (x_{k-1} itself at a light) */
    cdl_vec3 nx;          /* shading normal of x_{k-1}; zero for point lights */
    float cos_k;          /* at x_k towards x_{k-1} */
    int ok;               /* x_{k-1} can be linked from */
} cdl_gkde_parent;

void cdl_gkde_parent_init(const cdl_gkde_ctx *g, uint32_t xk, cdl_gkde_parent *par);

/* An eye vertex y as links read it, built at most once per step (when a
 * link first reaches y: gkde_eye_of): every link to y reads one record (in
 * the eye points' tree order, so the candidates of a footprint sit together)
 * instead of the scattered store, and y's BSDF is built once, not per link. */
#define CDL_GKDE_EYE_INLINE 8
typedef struct cdl_gkde_eye {
    cdl_bsdf b;
    cdl_vec3 p, ns, beta;
    cdl_vec3 to, to_n; /* y's predecessor towards the camera: position, normal (zero: a point) */
    uint32_t y;        /* index in the eye store */
    uint16_t depth;
    uint8_t delta;     /* bit i: the i-th vertex from y towards the camera is specular */
    /* the densities of the eye path from y on (the store holds longer ones) */
    float pe[CDL_GKDE_EYE_INLINE], pl[CDL_GKDE_EYE_INLINE];
} cdl_gkde_eye;

/* Builds the record of eye vertex y (neither the camera nor delta). */
void cdl_gkde_eye_init(const cdl_gkde_ctx *g, uint32_t y, cdl_gkde_eye *e);

/* What the strategy weight of a link reuses from its score. */
typedef struct cdl_gkde_link_state {
    const cdl_gkde_eye *ye;
    float p_sa; /* x_{k-1} sampling the direction to y */
} cdl_gkde_link_state;

/* Score of the link (footprint of par->xk, eye vertex y) if the edge from
 * x_{k-1} to y is unoccluded: partial light score x partial eye score x
 * (8a) x (8b), per light path, before the strategy weight (the caller
 * divides by nothing more than the acceptance probability). Black when
 * the link cannot carry light (a BSDF or cosine is zero); ls is filled
 * otherwise. */
cdl_vec3 cdl_gkde_link(const cdl_gkde_ctx *g, const cdl_gkde_parent *par, const cdl_gkde_eye *ye,
                       cdl_gkde_link_state *ls);
/* Its weight among every strategy that samples the same path (eq. 9
 * generalized): computed only for links found unoccluded. */
float cdl_gkde_link_weight(const cdl_gkde_ctx *g, const cdl_gkde_parent *par, const cdl_gkde_link_state *ls);

/* Emission an eye vertex y lying on an area light collects (the eye path
 * alone), times its weight against the merges of the same path. */
cdl_vec3 cdl_gkde_emitted(const cdl_gkde_ctx *g, uint32_t y);

/* Direct light at eye vertex y from light li at infinity: one light
 * sample (u1, u2) and its shadow ray, weighted against the eye path
 * hitting the sky and the merges at later vertices (the merge at y would
 * need x_0 on the light's disk, no surface point: this strategy replaces
 * it). */
cdl_vec3 cdl_gkde_sky(const cdl_gkde_ctx *g, const cdl_gkde_eye *ye, uint32_t li, float u1, float u2,
                      uint64_t *rays);

#endif
