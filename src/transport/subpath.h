/* Subpath tracing shared by every bidirectional and density-estimation
 * method: light subpaths (start on a light, vertices with flux-like
 * throughput) and eye subpaths (start at the camera). Each vertex records
 * the forward and reverse area densities MIS needs (Veach 1997, ch. 10). */
#ifndef CDL_SUBPATH_H
#define CDL_SUBPATH_H

#include "core/sampler.h"
#include "scene/camera.h"
#include "transport/vertex_store.h"

typedef struct cdl_walk {
    int maxdepth; /* bounces: a subpath has at most maxdepth + 1 vertices past its start */
    int rr_depth; /* Russian roulette by albedo after this many bounces */
    int env_vertex; /* eye paths that leave the scene end on a vertex at infinity
                     * (CDL_V_INFINITE) when the scene has an infinite light (bdpt) */
} cdl_walk;

/* Appends a light subpath (y_0 on a light, then y_1, ...) to vs, which must
 * have room for walk->maxdepth + 2 more vertices. Returns the number of
 * vertices appended (0 if the light sample failed). */
uint32_t cdl_trace_light_subpath(const cdl_scene *s, const cdl_walk *walk, cdl_sampler *smp,
                                 cdl_vertex_store *vs, uint64_t *rays);

/* How a light subpath left the scene, if it did: the ray from its last
 * vertex that hit nothing (photon ray splatting splats it too). */
typedef struct cdl_escape {
    int escaped;
    cdl_vec3 d, beta; /* direction, and the power it carries */
    float pdf_dir;    /* solid-angle density it was sampled with (0: specular) */
} cdl_escape;

/* The same, telling in esc whether the path ended by leaving the scene;
 * with first_diffuse it ends at its first vertex that scattered
 * non-specularly (the vertices up to there are the whole path's). */
uint32_t cdl_trace_light_subpath_esc(const cdl_scene *s, const cdl_walk *walk, cdl_sampler *smp,
                                     cdl_vertex_store *vs, uint64_t *rays, cdl_escape *esc, int first_diffuse);

/* Appends an eye subpath through raster point (px, py): x_0 at the camera,
 * then x_1, ... Same room needed (one more with walk->env_vertex); returns
 * the number of vertices. */
uint32_t cdl_trace_eye_subpath(const cdl_scene *s, const cdl_camera *cam, float px, float py,
                               const cdl_walk *walk, cdl_sampler *smp, cdl_vertex_store *vs,
                               uint64_t *rays);

/* Area density of choosing point b from a (solid-angle density pdf_sa at
 * a), when b lies on a surface with normal nb (nb = 0: not a surface). */
static inline float cdl_pdf_to_area(float pdf_sa, cdl_vec3 a, cdl_vec3 b, cdl_vec3 nb)
{
    cdl_vec3 d = cdl_sub(b, a);
    float d2 = cdl_dot(d, d);
    if (!(d2 > 0.0f))
        return 0.0f;
    float c = cdl_is_black(nb) ? 1.0f : fabsf(cdl_dot(nb, d)) / sqrtf(d2);
    return pdf_sa * c / d2;
}

/* Solid-angle density of a light emitting from y_0 (vertex i of vs) in
 * unit direction w; 0 outside its emission. */
float cdl_light_pdf_dir(const cdl_light *l, cdl_vec3 n, cdl_vec3 w);
/* Area (or, for delta lights, discrete) density of y_0 as a light-path
 * start: selection probability times position density. */
float cdl_light_pdf_origin(const cdl_scene *s, int32_t light);
/* Lights at infinity: the solid-angle density of light arriving from
 * direction w (pointing to the light), weighted by its selection
 * probability (pbrt-v3's InfiniteLightDensity: the infinite light's;
 * distant lights, delta in direction, add nothing). */
float cdl_light_pdf_infinite(const cdl_scene *s, cdl_vec3 w);
/* The density of a light path's disk point for light l at infinity
 * (uniform on the disk covering the scene), projected onto a surface of
 * normal n hit along w (n = 0: none). */
float cdl_light_pdf_disk(const cdl_light *l, cdl_vec3 w, cdl_vec3 n);

#endif
