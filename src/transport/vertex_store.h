/* The shared store of path vertices (DESIGN.md, "Shared transport data"):
 * structure of arrays, indices instead of pointers. Light subpaths for
 * bdpt, the point lights of ir/rigi, photons, gkde's light vertices and
 * splat's photon rays all live here; so do eye subpaths. */
#ifndef CDL_VERTEX_STORE_H
#define CDL_VERTEX_STORE_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"
#include "scene/scene.h"

enum {
    CDL_V_DELTA = 1,    /* scattered by a specular (Dirac) BSDF: never connected to */
    CDL_V_CAMERA = 2,   /* the camera vertex x_0 of an eye path */
    CDL_V_LIGHT = 4,    /* the vertex y_0 on a light where a light path starts */
    CDL_V_DELTA_LIGHT = 8, /* y_0 of a point or spot light (delta position) */
    CDL_V_EMITTER = 16, /* an eye vertex lying on an area light (light >= 0) */
    CDL_V_INFINITE = 32 /* on a light at infinity: y_0 of its light path (on the disk
                         * covering the scene) or where an eye path left the scene;
                         * its densities are in solid angle, as pbrt-v3's */
};

typedef struct cdl_vertex_store {
    uint32_t n, cap;
    cdl_vec3 *p, *ns, *ng; /* position, shading and geometric normal */
    cdl_vec3 *ts, *nb;     /* shading tangent and unperturbed normal (cdl_surface's; zero: none) */
    cdl_vec3 *wi;          /* unit direction towards the previous vertex */
    cdl_vec3 *beta;        /* throughput up to and including this vertex */
    float *pdf_fwd;        /* area density of this vertex from its predecessor */
    float *pdf_rev;        /* area density of this vertex sampled from its successor */
    float *rr;             /* probability the walk went on past this vertex (Russian
                              roulette; 1 without): a method that uses the successor's
                              existence (gkde's footprints) divides by it */
    float *u, *v;          /* texture coordinates (to rebuild the BSDF) */
    cdl_vec3 *kdh;         /* the reflectance factor the hit decided (cdl_surface's) */
    int32_t *parent;       /* previous vertex of the same path, -1 at the start */
    uint32_t *mat;
    int32_t *light;        /* light a light path started on / an eye vertex lies on, or -1 */
    uint16_t *depth;       /* bounces from the path's start */
    uint8_t *flags;        /* CDL_V_* */
} cdl_vertex_store;

void cdl_vs_init(cdl_vertex_store *vs);
void cdl_vs_free(cdl_vertex_store *vs);
/* Capacity for at least n vertices in total; keeps the contents. */
int cdl_vs_reserve(cdl_vertex_store *vs, uint32_t n, cdl_error *err);
static inline void cdl_vs_clear(cdl_vertex_store *vs) { vs->n = 0; }
/* Appends src's vertices to dst, parent indices shifted to match. */
int cdl_vs_append(cdl_vertex_store *dst, const cdl_vertex_store *src, cdl_error *err);
/* Bytes held, for memory reports. */
size_t cdl_vs_bytes(const cdl_vertex_store *vs);

/* The BSDF at vertex i (surface vertices only). */
void cdl_vs_bsdf(const cdl_scene *s, const cdl_vertex_store *vs, uint32_t i, cdl_bsdf *b);

#endif
