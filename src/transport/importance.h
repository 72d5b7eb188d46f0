/* Visual importance from importons (Peter & Pietrek 1998, as used by
 * Keller & Wald 2000, §2.3): eye subpaths from the shared tracer, their
 * non-specular vertices kept in a kd-tree; the importance at x is their
 * weighted density there, and the photon deposition probability is
 * p(x) = min(1, f I(x)) with f = 1 / (least importance seen by test rays
 * from the camera), so p = 1 wherever the camera looks directly. */
#ifndef CDL_IMPORTANCE_H
#define CDL_IMPORTANCE_H

#include "spatial/pointkd.h"
#include "transport/subpath.h"

#define CDL_IMPORTON_K 32 /* importons per density estimate */

typedef struct cdl_importance {
    float *pts;         /* x, y, z, weight per importon */
    uint32_t n;
    uint64_t paths;     /* importon paths traced */
    cdl_kdtree kd;
    float max_r2;       /* query radius cap */
    float f;            /* scale: p = min(1, f I) */
    float min_test;     /* least importance of the test rays (1 / f) */
    uint32_t tests;     /* test rays that found a surface */
} cdl_importance;

/* Traces `paths` importon paths through the image of cam (deterministic
 * per seed), builds the map and calibrates f with `tests` test rays. */
int cdl_importance_build(cdl_importance *imp, const cdl_scene *s, const cdl_camera *cam,
                         const cdl_walk *walk, uint64_t paths, uint32_t tests, float max_radius,
                         cdl_sampler_kind kind, uint64_t seed, cdl_error *err);
void cdl_importance_free(cdl_importance *imp);
/* Importance density at x (weight per unit area, per importon path). */
float cdl_importance_at(const cdl_importance *imp, cdl_vec3 x);
/* Deposition probability min(1, f I(x)). */
static inline float cdl_importance_p(const cdl_importance *imp, cdl_vec3 x)
{
    float p = imp->f * cdl_importance_at(imp, x);
    return p < 1.0f ? p : 1.0f;
}
static inline size_t cdl_importance_bytes(const cdl_importance *imp)
{
    return (size_t)imp->n * 4u * sizeof(float) + cdl_kd_bytes(&imp->kd);
}

#endif
