/* The state of the splat integrator (Herzog et al. 2007): owned by
 * splat.c (eye pass, photon rays, the pass, the report), which creates and
 * frees it; the parts it calls (maps.h, cache.h, mask.h, occlusion.h,
 * filter.h) read and fill their fields of it and call no part above them.
 * Eye samples live in the eye-sample tree's order. */
#ifndef CDL_SPLAT_STATE_H
#define CDL_SPLAT_STATE_H

#include "core/sh.h"
#include "integrators/integrator.h"
#include "scene/bsdf_sh.h"
#include "spatial/splatkd.h"
#include "transport/photon_rays.h"

#define SPLAT_STRATA 20 /* icosahedron faces */
#define SPLAT_BW 6       /* aov bandwidth: weighted bandwidth and weight at depth 2, 3, any */
#define SPLAT_LAMBERT UINT32_MAX
#define SPLAT_BAND_SLOTS (1u << 20) /* eye samples per band with gather */

/* An eye sample (§3): what the final step needs besides the tree's
 * position and normal. */
typedef struct splat_eye {
    cdl_vec3 kd;     /* the BSDF's reflectance (all a Lambertian sample needs) */
    cdl_vec3 weight; /* the specular chain's weight / eye samples per pixel */
    cdl_vec3 wo;     /* towards the camera */
    cdl_frame f;     /* shading normal on the seen side; t towards wo (SH tables) */
    uint32_t pixel, mat;
    float pw;        /* a pixel's width in the world at the sample (along its chain) */
    uint32_t bsdf;   /* slot of its BSDF in splat_state.sb, SPLAT_LAMBERT for a Lambertian one */
} splat_eye;

typedef struct splat_stats {
    double t_ray, t_light, t_build, t_solve, t_cache, t_brdf, t_filter, t_occl, t_total;
    uint64_t rays_stored, splats, tested, nodes, samples, passes, segments;
    uint64_t records, cache_passes, ray_refs, mask_tested, masked, rasterized, mask_occ;
    uint64_t mask_buffers; /* photon rays with a visibility mask; mask_occ: occluders over the passes */
    uint64_t mask_planar;  /* those whose occluders lie on few planes (a plane per cell) */
    uint64_t occluded, occl_rays; /* occlusion: splats dropped, shadow rays traced */
    size_t peak_bytes;
} splat_stats;

typedef struct splat_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    cdl_pray_params pp;
    int have_pilot;
    int at_infinity; /* the scene has distant or infinite lights: their direct light by light sampling */
    int no_photons;  /* only lights at infinity and maxdepth 1: no photon rays at all */
    cdl_pray_set rays; /* in Morton order of their ends */
    /* eye samples: slots per pixel sample while tracing, then tree order */
    cdl_vec3 *sp, *sn;
    uint8_t *sflags, *svalid;
    splat_eye *slot, *eye;
    /* The BSDFs of the non-Lambertian samples, by slot (written only
     * there: 264 bytes a sample would be most of the memory and of the
     * gather into tree order), and gathered by glossy index (gb[gloss[q]]) */
    cdl_bsdf *sb, *gb;
    uint32_t nslots, neye;
    uint32_t G;       /* eye samples per camera sample: gather rays, or 1 */
    int band_rows;    /* rows per band (the whole image without gather) */
    cdl_vec3 *base;   /* per pixel: emission seen and direct light sampled, this pass */
    float *dz;        /* discontinuity buffer, per pixel: view depth of its first eye sample (0: none) */
    cdl_vec3 *dn;     /* and the normal of the side seen */
    cdl_vec3 *pix;    /* per pixel: this pass's image */
    cdl_skd tree;
    cdl_skd_params kp;
    /* Per eye sample in tree order (16 floats of padding: the leaf loop
     * runs 16 lanes): irradiance E (RGB, one array per channel), the sum
     * of kernel weights and of 1 / z (for filtering and caching). A
     * Lambertian sample needs nothing else in any mode (its BSDF is one
     * constant: kd / pi E; its SH table holds only the DC term); the others
     * (gloss[q] != SPLAT_LAMBERT) get K x 3 floats in gmap. */
    float *E[3], *izsum, *nsum; /* splats received: sum of 1 / z (the cache's), count */
    uint32_t *gloss;  /* index into gmap, or SPLAT_LAMBERT */
    uint32_t *gbits;  /* bit q % 32 of word q / 32: gloss[q] != SPLAT_LAMBERT (words to spare past the end) */
    float *gmap;      /* histogram: [stratum][glossy sample][3]; SH: [glossy sample][k][3]; direct: [g][3] */
    uint32_t nglossy, gcap; /* gmap and gb have room for gcap */
    uint32_t K;       /* 1 (direct), 20 (histogram), 16 (SH) */
    float *bw;        /* aov bandwidth only: SPLAT_BW floats per sample */
    struct splat_cache *cache; /* cache: radiance caching (cache.c) */
    struct splat_mask *mask;   /* visibility_mask (mask.c) */
    struct splat_occl *occl;   /* occlusion (occlusion.c) */
    int want_bw;
    cdl_vec3 strata[SPLAT_STRATA];
    cdl_sh_rot rot;
    cdl_bsdf_sh *tables; /* per material (SH mode) */
    splat_stats st;
    atomic_int *cancel; /* the film's, set by each pass */
} splat_state;

/* A photon ray as the eye-sample tree's frustum queries take it. */
static inline cdl_splat_ray splat_ray_of(const splat_state *s, const cdl_photon_ray *r)
{
    /* samples on the origin's own surface (the other side of a two-sided
     * sheet the ray left: they face it) lie within a hit point's offset
     * (cdl_offset) of its tangent plane; a point light has no surface */
    float m = cdl_maxf(fabsf(r->o.x), cdl_maxf(fabsf(r->o.y), fabsf(r->o.z)));
    float tol = s->scene->eps + m * 1e-5f, zmin = cdl_is_black(r->on) ? 0.0f : tol;
    return (cdl_splat_ray){r->o, r->d, r->on, r->len, r->h0, r->dh, s->opt.splat.cap, zmin, tol};
}
/* RGB of entry k (stratum or coefficient) of glossy sample g. */
static inline float *splat_gmap_at(const splat_state *s, uint32_t g, int k)
{
    size_t i = s->opt.splat.mode == CDL_SPLAT_HISTOGRAM ? (size_t)k * s->nglossy + g : (size_t)g * s->K + (size_t)k;
    return &s->gmap[3 * i];
}

#endif
