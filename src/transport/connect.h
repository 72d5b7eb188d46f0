/* Connecting an eye subpath and a light subpath: the contribution of one
 * bidirectional strategy (s, t) with its MIS weight. Shared by bdpt and
 * the point-light methods (ir, rigi). */
#ifndef CDL_CONNECT_H
#define CDL_CONNECT_H

#include "core/sampler.h"
#include "film/film.h"
#include "scene/camera.h"
#include "transport/mis.h"
#include "transport/vertex_store.h"

typedef struct cdl_connect_ctx {
    const cdl_scene *scene;
    const cdl_camera *cam;
    cdl_mis_kind mis;
    float threshold;            /* stratification heuristic's t */
    const cdl_mis_counts *counts;
    int resample_s1;            /* s = 1 samples the light point as next-event estimation does */
} cdl_connect_ctx;

/* s = 0: the eye path's vertex t-1 lies on a light; Le there, weighted. */
cdl_vec3 cdl_connect_eye_only(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t);

/* s >= 1, t >= 2: eye vertex t-1 (of evs, from index 0) to light vertex
 * s-1 (of lvs, path starting at index l0), shadow ray included. */
cdl_vec3 cdl_connect(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t,
                     const cdl_vertex_store *lvs, uint32_t l0, uint32_t s, uint64_t *rays);

/* t = 1, s >= 2: light vertex s-1 seen by the camera; returns the value to
 * splat at raster (*x, *y) (already weighted), or black. */
cdl_vec3 cdl_connect_camera(const cdl_connect_ctx *cx, const cdl_vertex_store *lvs, uint32_t l0,
                            uint32_t s, float *x, float *y, uint64_t *rays);

/* s = 1 by resampling a light point for eye vertex t-1 (pbrt-v3 does the
 * same): next-event estimation's sampling (solid angle for spheres) gives
 * far less noise than the light subpath's y_0. smp's dimensions 2t..2t+3
 * are used (the same at the same depth in every pass: they stay
 * stratified); tmp holds the temporary vertex (room for one).
 * only_infinite: lights at infinity alone (shared light paths' y_0 cover
 * the others). Weighted as cx says, shadow ray included. */
cdl_vec3 cdl_connect_resampled(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t,
                               cdl_sampler *smp, cdl_vertex_store *tmp, int only_infinite, uint64_t *rays);

/* Every strategy of one eye subpath (evs[0 .. ne)) against one light
 * subpath (lvs[l0 .. l0 + nl)) with at most maxdepth bounces: s = 0 when
 * with_eye_only, light tracing (t = 1) when splats is given (splatted
 * through cx->cam's filter, scaled by splat_scale), s = 1 by resampling
 * the light when resample is given (tmp: its vertex), else from y_0 (not
 * for lights at infinity, whose y_0 is no point). bdpt's inner loop, and
 * vcm's connections. Returns the sum for the eye path's pixel. */
cdl_vec3 cdl_connect_all(const cdl_connect_ctx *cx, int maxdepth, const cdl_vertex_store *evs, uint32_t ne,
                         const cdl_vertex_store *lvs, uint32_t l0, uint32_t nl, int with_eye_only,
                         cdl_splats *splats, float splat_scale, cdl_sampler *resample, cdl_vertex_store *tmp,
                         uint64_t *rays);

/* Vertex merging: the MIS weight of merging eye vertex t-1 (of evs, t >=
 * 2, its BSDF b) with light vertex s-1 of the light path at l0 of lvs
 * (s >= 2, within the merge radius): the full path is the eye subpath up
 * to t-1 and the light subpath below s-1, the two merged vertices one.
 * cx->counts->merge is eta (mis.h). */
float cdl_merge_weight(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t t, const cdl_bsdf *b,
                       const cdl_vertex_store *lvs, uint32_t l0, uint32_t s);

/* The partial sums of cdl_mis_merge_partials (mis.h) along an eye
 * subpath evs[0 .. ne): for each k in [1, ne), b1[k], b2[k] of merging
 * at z_k, and ge[k] = |cos| / d^2 at z_{k-1} seen from z_k (1 / d^2 at
 * the camera), which turns the merge's solid-angle density towards
 * z_{k-1} into pl(z_{k-1}). */
void cdl_merge_partials_eye(const cdl_connect_ctx *cx, const cdl_vertex_store *evs, uint32_t ne, float *b1,
                            float *b2, float *ge);
/* The same along a light subpath lvs[l0 .. l0 + nl): for each depth a in
 * [1, nl), a1[a], a2[a] of merging at y_a, and gl[a] turning the merge's
 * solid-angle density towards y_{a-1} into pe(y_{a-1}) (1 when y_{a-1} is
 * at infinity, whose densities stay in solid angle). */
void cdl_merge_partials_light(const cdl_connect_ctx *cx, const cdl_vertex_store *lvs, uint32_t l0, uint32_t nl,
                              float *a1, float *a2, float *gl);

/* Normal of vertex i for cosines and densities: zero for the camera and
 * for point and spot lights. */
cdl_vec3 cdl_vertex_normal(const cdl_vertex_store *vs, uint32_t i);

/* Solid-angle density of vertex i (reached from position `from`; ignored
 * for the camera and lights) sampling the unit direction w: the camera's,
 * the light's emission or the BSDF's. */
float cdl_vertex_pdf_sa(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i, cdl_vec3 from,
                        cdl_vec3 w);
/* The same with the vertex's BSDF already built (b: unused at the camera
 * and at a light-path start): for callers that evaluate one vertex often. */
float cdl_vertex_pdf_sa_bsdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                             const cdl_bsdf *b, cdl_vec3 from, cdl_vec3 w);
/* The same as an area density at `to` (normal nt; zero: a point). */
float cdl_vertex_pdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i, cdl_vec3 from,
                     cdl_vec3 to, cdl_vec3 nt);

/* f at vertex i for light arriving from position `from` and leaving to
 * `to`: eye vertices in radiance mode, light vertices (light_side) in
 * importance mode with Veach's shading-normal correction, y_0 the light's
 * emission distribution. */
cdl_vec3 cdl_vertex_f(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                      cdl_vec3 from, cdl_vec3 to, int light_side);
/* The same with the vertex's BSDF already built (unused at a light-path start). */
cdl_vec3 cdl_vertex_f_bsdf(const cdl_connect_ctx *cx, const cdl_vertex_store *vs, uint32_t i,
                           const cdl_bsdf *b, cdl_vec3 from, cdl_vec3 to, int light_side);

/* G = |cos a| |cos b| / d^2 with geometric... shading normals na, nb
 * (zero normal: a point, cosine 1). */
static inline float cdl_geometry(cdl_vec3 pa, cdl_vec3 na, cdl_vec3 pb, cdl_vec3 nb)
{
    cdl_vec3 d = cdl_sub(pb, pa);
    float d2 = cdl_dot(d, d);
    if (!(d2 > 0.0f))
        return 0.0f;
    float inv = 1.0f / sqrtf(d2);
    float ca = cdl_is_black(na) ? 1.0f : fabsf(cdl_dot(na, d)) * inv;
    float cb = cdl_is_black(nb) ? 1.0f : fabsf(cdl_dot(nb, d)) * inv;
    return ca * cb / d2;
}

/* 1 if nothing blocks the segment between two vertices (offset off their
 * surfaces; a zero normal marks a point that needs no offset). skip_sphere:
 * the sphere light pb lies on, or UINT32_MAX. */
int cdl_visible(const cdl_scene *s, cdl_vec3 pa, cdl_vec3 na, cdl_vec3 pb, cdl_vec3 nb,
                uint32_t skip_sphere);

/* The fraction of a light's emission y_0 sends towards unit w: 1 or 0
 * for diffuse area lights; for point, spot and projector lights the
 * direction's factor of their intensity (cdl_light_I_factor). */
cdl_vec3 cdl_light_emit_factor(const cdl_light *l, cdl_vec3 n, cdl_vec3 w);

#endif
