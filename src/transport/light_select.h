/* Direct light with many lights (Keller & Wald 2000, §3). Primary photons
 * keep the index of their light; the lights among the primary photons
 * near a shading point form L_con, the probably visible ones. Shadow rays
 * go to L_con (stratified by power when there are enough for each), and
 * one ray to a uniformly chosen light of the rest, weighted by the size
 * of the rest (eq. 1), keeps the estimate unbiased; the biased variant
 * omits it. The baseline picks every light in proportion to its power. */
#ifndef CDL_LIGHT_SELECT_H
#define CDL_LIGHT_SELECT_H

#include "core/sampler.h"
#include "scene/scene.h"
#include "spatial/photon_map.h"

/* NONE: no direct light at all (indirect light alone, for comparisons) */
typedef enum { CDL_DIRECT_POWER, CDL_DIRECT_LCON, CDL_DIRECT_LCON_BIASED, CDL_DIRECT_NONE } cdl_direct_kind;

/* Per-thread scratch: a mark and a slot per light. */
typedef struct cdl_lcon_scratch {
    uint8_t *mark;
    uint32_t *ids;
} cdl_lcon_scratch;

int cdl_lcon_scratch_init(cdl_lcon_scratch *sc, uint32_t nlights);
void cdl_lcon_scratch_free(cdl_lcon_scratch *sc);

/* L_con at x: the lights of the primary photons of `direct` within
 * sqrt(r2), plus the lights that emit no photons (distant, infinite) and
 * those past the 65534 a photon can name, in
 * increasing order into sc->ids. Returns |L_con|. */
uint32_t cdl_lcon_query(const cdl_scene *s, const cdl_photon_map *direct, cdl_vec3 x, float r2,
                        cdl_lcon_scratch *sc);

typedef struct cdl_direct_cfg {
    cdl_direct_kind kind;
    uint32_t shadow_rays;        /* S: rays to L_con (or in all, for power) */
    const cdl_photon_map *direct; /* the primary photons (lcon) */
    float r2;                    /* L_con query radius squared */
} cdl_direct_cfg;

/* f L cos / pdf of one point on light li (one shadow ray), not divided by
 * the light's selection probability. */
cdl_vec3 cdl_sample_light(const cdl_scene *s, uint32_t li, const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo,
                          cdl_sampler *smp, uint64_t *rays);

/* Direct light from every light at infinity (distant, infinite): one
 * sample each (maps importance-sampled), one shadow ray each. Methods whose
 * light paths start on the disk covering the scene take that light this
 * way: the disk point is no point in the scene to connect or splat from. */
cdl_vec3 cdl_direct_light_infinite(const cdl_scene *s, const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo,
                                   cdl_sampler *smp, uint64_t *rays);

/* Reflected direct light at a surface point towards wo. *nlcon gets |L_con|. */
cdl_vec3 cdl_direct_light(const cdl_scene *s, const cdl_direct_cfg *cfg, cdl_lcon_scratch *sc,
                          const cdl_surface *sf, const cdl_bsdf *b, cdl_vec3 wo, cdl_sampler *smp,
                          uint64_t *rays, uint32_t *nlcon);

#endif
