/* Photon maps (Jensen 1996): stored photons in a balanced kd-tree and the
 * density estimate of reflected radiance over the k nearest. Photons come
 * from the shared light-subpath tracer (transport/photons.c); this file
 * only stores and queries them. */
#ifndef CDL_PHOTON_MAP_H
#define CDL_PHOTON_MAP_H

#include <stdint.h>

#include "core/error.h"
#include "core/octahedral.h"
#include "core/vec.h"
#include "scene/bsdf.h"
#include "spatial/pointkd.h"

enum {
    CDL_PH_PRIMARY = 1, /* came straight from its light (Keller & Wald §3 keep its id) */
    CDL_PH_CAUSTIC = 2  /* last scattered by a specular surface */
};

/* 32 bytes: position, flux, incoming direction (octahedral, 2 x 15 bits)
 * with two flag bits, surface normal (octahedral, 2 x 8 bits) and a tag:
 * a primary photon's light (0xffff past 65534 lights; only L_con asks),
 * any other photon's bounce count (maxdepth counts whole paths). */
typedef struct cdl_photon {
    float p[3];
    float power[3];
    uint32_t wi;     /* towards where the photon came from | flags << 30 */
    uint16_t n;      /* geometric normal on the side the photon arrived from */
    uint16_t tag;
} cdl_photon;

#define CDL_PH_NO_LIGHT 0xffffu
static inline uint32_t cdl_photon_flags(const cdl_photon *ph) { return ph->wi >> 30; }
static inline uint32_t cdl_photon_light(const cdl_photon *ph)
{
    return (cdl_photon_flags(ph) & CDL_PH_PRIMARY) ? ph->tag : CDL_PH_NO_LIGHT;
}
/* Surfaces the photon's path met, its own included (1 = primary). */
static inline uint32_t cdl_photon_depth(const cdl_photon *ph)
{
    return (cdl_photon_flags(ph) & CDL_PH_PRIMARY) ? 1u : ph->tag;
}

/* Octahedral encoding (Meyer et al. 2010) with `bits` per coordinate. */
static inline cdl_vec3 cdl_photon_wi(const cdl_photon *ph) { return cdl_oct_decode_bits(ph->wi & 0x3fffffffu, 15); }
static inline cdl_vec3 cdl_photon_n(const cdl_photon *ph) { return cdl_oct_decode_bits(ph->n, 8); }


typedef struct cdl_photon_map {
    cdl_photon *ph;
    uint32_t n, cap;
    cdl_kdtree kd;
    int built;
} cdl_photon_map;

typedef enum { CDL_KERNEL_BOX, CDL_KERNEL_CONE, CDL_KERNEL_EPANECHNIKOV } cdl_kernel;

void cdl_pmap_init(cdl_photon_map *m);
void cdl_pmap_free(cdl_photon_map *m);
void cdl_pmap_clear(cdl_photon_map *m); /* keeps the memory */
int cdl_pmap_append(cdl_photon_map *m, const cdl_photon *ph, uint32_t n, cdl_error *err);
/* Multiplies every stored flux by s (normalization by the number of paths). */
void cdl_pmap_scale(cdl_photon_map *m, float s);
int cdl_pmap_build(cdl_photon_map *m, cdl_error *err);
size_t cdl_pmap_bytes(const cdl_photon_map *m);

/* Optional visibility test between a query point x (normal nx, on the
 * side being estimated) and stored points p (normal np). Estimates leave
 * hidden photons out, so that light does not leak through a wall standing
 * on a floor that runs under it. A query first moves x off its surface
 * (origin: back along wx, where the ray that found x came from, then by
 * up to `lift` along nx, less where something is nearer), then tests the
 * segment from there to each photon, moved back along its own arrival
 * direction wp (fn: 1 if nothing blocks it). Both ends move along paths
 * that light or the eye took, and the lift is tested, so a photon counts
 * only if a free path joins it to x: none from a room that no light path
 * can enter, even where a wall of zero thickness meets another surface.
 * The spatial layer knows no geometry; the caller supplies the tests. */
typedef struct cdl_vis {
    cdl_vec3 (*origin)(const void *ctx, cdl_vec3 x, cdl_vec3 nx, cdl_vec3 wx, float lift);
    int (*fn)(const void *ctx, cdl_vec3 o, cdl_vec3 p, cdl_vec3 wp);
    const void *ctx;
} cdl_vis;
/* The lift of a query of radius r: a quarter of it, so that the segment
 * to a photon of the same convex surface clears it (the surface falls
 * d^2 / (2 rho) below the tangent plane at distance d, under d / 4 for
 * d < rho / 2). */
#define CDL_VIS_LIFT 0.25f

/* A radiance query: k nearest within max_r2; photons with any of the
 * skip flags, or that vis (if set) finds hidden, are left out of the sum
 * (but still fix the radius, so the estimate is that of the remaining
 * subset). scratch must hold k.
 *
 * shrink (in (0, 1]) scales the squared radius the k nearest give before
 * the estimate: only photons within sqrt(shrink) r_k count, over that
 * smaller disc. Given r_k the k - 1 photons inside are spread as the
 * density is, so for a locally uniform density the expectation is that
 * of the k-NN estimate, (k - 1) / (pi r_k^2), while the kernel's blur (the
 * bias) shrinks with the radius: progressive photon mapping's radius
 * reduction (Knaus & Zwicker 2011) with a radius that still adapts to the
 * photon density as Jensen's does. 1: Jensen's estimate. */
typedef struct cdl_pm_query {
    uint32_t k;
    float max_r2;
    cdl_kernel kernel;
    uint32_t skip;
    uint32_t *idx;
    float *d2;
    cdl_vis vis;
    uint32_t max_depth; /* photons of deeper bounces left out as skipped ones; 0: none */
    float *guess;       /* coherent queries (pixel after pixel): the radius^2 to try first
                         * (cdl_kd_knn_guess), updated by each query; NULL: a k-NN heap */
    uint32_t cap;       /* entries idx and d2 hold (>= k) */
    float shrink;       /* squared-radius factor in (0, 1]; 0 counts as 1 */
} cdl_pm_query;

/* Reflected radiance at x towards wo: sum of f(wo, wi_p) flux_p w(d_p)
 * over the nearest photons, divided by the kernel's area. */
cdl_vec3 cdl_pmap_radiance(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, cdl_vec3 wo,
                           const cdl_bsdf *b);


/* Stochastic progressive photon mapping's statistics at a visible point
 * (Hachisuka & Jensen 2009): over the photons within sqrt(r2) of x that q
 * does not leave out (skip, max_depth, vis; k, kernel and shrink unused)
 * and that arrived on the side wo is on, the sum of f(wo, wi_p) flux_p
 * into *phi (not divided by the disc's area); returns their number. */
uint32_t cdl_pmap_flux(const cdl_photon_map *m, const cdl_pm_query *q, float r2, cdl_vec3 x, cdl_vec3 wo,
                       const cdl_bsdf *b, cdl_vec3 *phi);

/* Precomputed irradiance (Christensen 1999): the irradiance from both
 * maps at 1 in m global photons, so that a final-gathering ray that
 * lands on a Lambertian surface costs one small lookup instead of a
 * k-nearest density estimate. */
typedef struct cdl_irr_point {
    float p[3];
    float E[3];
    uint32_t n;  /* octahedral normal, 2 x 16 bits */
    float r2;    /* squared radius of the point's estimate (after shrink) */
    uint32_t wi; /* its photon's arrival direction, octahedral 2 x 16 bits */
} cdl_irr_point;

typedef struct cdl_irr_map {
    cdl_irr_point *pt;
    uint32_t n;
    cdl_kdtree kd;
    /* the global photons that carry no point, scaled to the full flux: where
     * a lookup finds no point, an estimate from all photons would be low (the
     * miss says the point photons are absent there); from these it is not */
    cdl_photon_map est;
} cdl_irr_map;

/* Irradiance at x on a surface with normal n from the photons of m
 * arriving from n's side (photons of surfaces facing elsewhere left out);
 * visibility tests start from x moved along n. */
cdl_vec3 cdl_pmap_irradiance(const cdl_photon_map *m, const cdl_pm_query *q, cdl_vec3 x, cdl_vec3 n);
/* Irradiance at 1 in `every` (>= 2) global photons, estimated from the
 * other global photons (kept in im->est) and the caustic map with the
 * query q describes (its idx, d2 and skip are not used). */
int cdl_irr_build(cdl_irr_map *im, const cdl_photon_map *global, const cdl_photon_map *caustic,
                  uint32_t every, const cdl_pm_query *q, cdl_error *err);
void cdl_irr_free(cdl_irr_map *im);
/* Irradiance of the nearest point within sqrt(max_r2) whose normal is
 * within about 25 degrees of n (and that vis, if set, finds visible from
 * x, found by a ray arriving along -wx); 0 if there is none among the 8
 * nearest (*found = 0). With own_radius a point serves only within the
 * radius of its own estimate: the lookup's blur then shrinks with the
 * estimates' (progressive radius reduction). */
cdl_vec3 cdl_irr_lookup(const cdl_irr_map *im, cdl_vec3 x, cdl_vec3 n, cdl_vec3 wx, float max_r2, int own_radius,
                        cdl_vis vis, int *found);
static inline size_t cdl_irr_bytes(const cdl_irr_map *im)
{
    return (size_t)im->n * sizeof(cdl_irr_point) + cdl_kd_bytes(&im->kd) + cdl_pmap_bytes(&im->est);
}

#endif
