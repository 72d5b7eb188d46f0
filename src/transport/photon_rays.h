/* Photon rays for splatting (Herzog et al. 2007, §4.2): every segment
 * x_{i-1} -> x_i of a light subpath from the shared tracer, with the power
 * it carries and a bandwidth from the path's clamped density:
 *
 *   p~(x_1) = p_e(x_0, x_1) / D(x_0, x_1),
 *   p~(x_{i+1}) = p~(x_i) p_s^perp(x_{i-1}, x_i, x_{i+1}) / D(x_i, x_{i+1})   (eq. 4.8)
 *   D(x, y) = max(D~^2, |x - y|^2),
 *   h(x_i) = C / M^(1/6) w / sqrt(p~(x_i)^S),  h(x_0) = 0                   (eq. 4.9)
 *   w = m0 mu_C / mean(1 / sqrt(p~^S)),  mu_C = a mean|x_i - x_{i-1}|       (eq. 4.10-4.11)
 *
 * (densities per projected solid angle; a = 0.2, m0 = 10^(5/6); the means
 * from a pilot set of paths), clamped to the mean C m0 mu_C / M^(1/6) times
 * [R, 1/R] (the report prints the bounds without m0, which would put the
 * mean bandwidth above the upper bound). A ray
 * stores h0 = min(h(x_i), h(x_{i-1})) and dh = max(0, h(x_i) - h(x_{i-1})) /
 * |x_i - x_{i-1}|. Lengths are in scene units throughout: mu_C and D~ come
 * from the scene, so the report's metre convention needs no conversion.
 *
 * Paths from lights at infinity start on the disk covering the scene
 * (the shared tracer): their first ray is not stored (its direct light
 * comes by light sampling; the disk point is no scene point), and
 * p~(x_1) is the direction's density times the disk's 1 / (pi R^2).
 *
 * Rays fall into three budgets: direct (i = 1), caustic (every bounce
 * before x_i specular) and indirect (the rest). Paths are traced in index
 * order until each budget is full; a budget's rays carry power / N_c, N_c
 * the paths traced until it filled. A budget that fills far slower than
 * the others stops with the paths traced so far (still unbiased).
 * Deterministic per (seed, pass) on any number of threads. */
#ifndef CDL_PHOTON_RAYS_H
#define CDL_PHOTON_RAYS_H

#include "transport/subpath.h"

enum { CDL_PRAY_DIRECT, CDL_PRAY_INDIRECT, CDL_PRAY_CAUSTIC, CDL_PRAY_CATS };

/* A specular bounce's density per projected solid angle: a Dirac, taken
 * as a lobe of about one degree so caustic paths get narrow kernels. */
#define CDL_PRAY_DELTA_PDF 1000.0f

typedef struct cdl_photon_ray {
    cdl_vec3 o, d;  /* origin x_{i-1}, unit direction */
    cdl_vec3 on;    /* origin's normal on the side the ray leaves; zero at a point light */
    cdl_vec3 flux;  /* power carried, divided by the budget's paths */
    float len, h0, dh;
    float pdf;      /* p~(x_i), for pictures of the bandwidth */
    uint16_t depth; /* i */
    uint8_t cat;
} cdl_photon_ray;

typedef struct cdl_pray_params {
    uint32_t target[CDL_PRAY_CATS]; /* rays per budget; 0: none of that kind */
    float C, S, R;
    float d2_clamp;                  /* D~^2 */
    float w, mu;                     /* from the pilot (cdl_pray_pilot) */
    double bw_scale;                 /* every bandwidth times this (the progressive schedule); 0: 1 */
    uint64_t max_paths;
} cdl_pray_params;

typedef struct cdl_pray_set {
    cdl_photon_ray *r;
    uint32_t n, cap;
    uint64_t paths[CDL_PRAY_CATS]; /* N_c */
    uint32_t count[CDL_PRAY_CATS];
    uint64_t traced, rays;
} cdl_pray_set;

/* The pilot: n_paths paths (seeded apart from every pass) give mu_C and w. */
int cdl_pray_pilot(const cdl_scene *s, const cdl_walk *walk, cdl_sampler_kind kind, uint64_t seed,
                   uint32_t n_paths, float S, float d2_clamp, float *w, float *mu, cdl_error *err);

/* Fills set (cleared first) for pass `pass`. */
int cdl_pray_trace(const cdl_scene *s, const cdl_walk *walk, const cdl_pray_params *pp, cdl_sampler_kind kind,
                   uint64_t seed, uint32_t pass, cdl_pray_set *set, cdl_error *err);
void cdl_pray_free(cdl_pray_set *set);

#endif
