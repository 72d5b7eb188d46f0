/* Lights, behind one interface for next-event estimation (sample a point
 * towards a receiver, and its density) and for light paths (sample an
 * emitted ray). Area lights are triangles and analytic spheres; point,
 * spot and projector lights are delta in position, distant lights in
 * direction; the infinite light is constant radiance from all directions. */
#ifndef CDL_LIGHT_H
#define CDL_LIGHT_H

#include <stdint.h>

#include "core/sampling.h"
#include "core/vec.h"

typedef enum cdl_light_type {
    CDL_LIGHT_TRIANGLE,
    CDL_LIGHT_SPHERE,
    CDL_LIGHT_POINT,
    CDL_LIGHT_SPOT,
    CDL_LIGHT_DISTANT,
    CDL_LIGHT_INFINITE,
    CDL_LIGHT_PROJECTOR /* Mitsuba's projector: a pinhole projecting an image */
} cdl_light_type;

struct cdl_envmap;
struct cdl_texture;

typedef struct cdl_light {
    cdl_light_type type;
    cdl_vec3 p;      /* triangle vertex 0; sphere centre; point/spot position;
                        distant/infinite: centre of the scene's bounding sphere */
    cdl_vec3 e1, e2; /* triangle edges p1 - p0, p2 - p0 */
    cdl_vec3 n;      /* triangle front (CCW) unit normal; spot axis; distant:
                        unit direction the light travels in */
    float area;      /* triangle or sphere surface area */
    float radius;    /* sphere radius; distant/infinite: scene bounding radius */
    float cos_total, cos_falloff; /* spot cone (pbrt-v3 falloff) */
    cdl_vec3 L;      /* radiance (area, distant, infinite) or intensity W/sr (point, spot);
                        projector: pi scale times its constant irradiance (or 1, textured) */
    int twosided;    /* triangle: emits from both faces */
    int inward;      /* sphere: emits towards its inside (ReverseOrientation) */
    uint32_t prim;   /* triangle or sphere index in the scene */
    const struct cdl_envmap *map; /* infinite: its radiance map (NULL: constant L) */
    /* Mitsuba's spot: intensity linear in the angle from cutoff (0) to
     * beam (1), instead of pbrt-v3's smooth falloff over the cosines */
    int spot_linear;
    float cutoff, beam; /* radians */
    /* spot and projector: unit frame (ax, ay, n) and the tangents of the
     * image's half extents at distance 1; a spot's uv spans its cutoff cone */
    cdl_vec3 ax, ay;
    float tan_x, tan_y;
    /* a texture on the light (spot: projected; projector: its irradiance;
     * triangle: radiance over its uv); tex_id indexes the scene's textures
     * and tex points there after the scene is committed */
    int32_t tex_id;
    const struct cdl_texture *tex;
    cdl_vec3 tex_mean;   /* the texture's mean (light selection) */
    float uv[6];         /* triangle: uv at its three vertices */
} cdl_light;

typedef struct cdl_light_sample {
    cdl_vec3 p;    /* point on the light (far away for distant/infinite) */
    cdl_vec3 wi;   /* unit direction from the receiver to p */
    float dist;    /* distance receiver to p; shadow rays go up to it */
    cdl_vec3 Li;   /* radiance (area, infinite), intensity / dist^2 (point, spot), radiance (distant) */
    float pdf;     /* solid angle density at the receiver; 1 for delta lights */
    int delta;
} cdl_light_sample;

typedef struct cdl_light_emit {
    cdl_vec3 p, n, d; /* origin, normal there (0 for points), direction */
    cdl_vec3 Le;      /* radiance (area, distant, infinite) or intensity (point, spot) along d */
    float pdf_pos;    /* area density of p (1 for points) */
    float pdf_dir;    /* solid angle density of d (1 for distant) */
} cdl_light_emit;

/* Point, spot and projector: delta in position, intensity L * factor. */
static inline int cdl_light_is_delta_pos(const cdl_light *l)
{
    return l->type == CDL_LIGHT_POINT || l->type == CDL_LIGHT_SPOT || l->type == CDL_LIGHT_PROJECTOR;
}

static inline int cdl_light_is_delta(const cdl_light *l)
{
    return cdl_light_is_delta_pos(l) || l->type == CDL_LIGHT_DISTANT;
}

/* Distant and infinite lights: outside the scene, reached along directions. */
static inline int cdl_light_at_infinity(const cdl_light *l)
{
    return l->type == CDL_LIGHT_DISTANT || l->type == CDL_LIGHT_INFINITE;
}

/* Triangle light l's point at barycentrics (b1, b2). */
static inline cdl_vec3 cdl_light_triangle_at(const cdl_light *l, float b1, float b2)
{
    return cdl_add(l->p, cdl_add(cdl_scale(l->e1, b1), cdl_scale(l->e2, b2)));
}

/* The direction, distance and density towards point p (radiance Le) of
 * triangle light l seen from ref; 0 from behind its emitting face. */
static inline int cdl_light_triangle_li(const cdl_light *l, cdl_vec3 ref, cdl_vec3 p, cdl_vec3 Le,
                                        cdl_light_sample *s)
{
    s->p = p;
    cdl_vec3 d = cdl_sub(s->p, ref);
    float d2 = cdl_dot(d, d);
    if (!(d2 > 0.0f))
        return 0;
    s->dist = sqrtf(d2);
    s->wi = cdl_scale(d, 1.0f / s->dist);
    float cos_l = -cdl_dot(s->wi, l->n);
    if (l->twosided)
        cos_l = fabsf(cos_l);
    if (cos_l <= 0.0f)
        return 0; /* receiver behind the emitting face */
    s->Li = Le;
    s->pdf = d2 / (cos_l * l->area);
    s->delta = 0;
    return 1;
}

/* Every light; cdl_light_sample_li does an untextured triangle inline
 * (every vertex of path calls it: the call cost as much as the work). */
int cdl_light_sample_li_any(const cdl_light *l, cdl_vec3 ref, float u1, float u2, cdl_light_sample *s);

/* Returns 0 if the sample carries no light (back face, outside a cone). */
static inline int cdl_light_sample_li(const cdl_light *l, cdl_vec3 ref, float u1, float u2,
                                      cdl_light_sample *s)
{
    if (l->type != CDL_LIGHT_TRIANGLE || l->tex) {
        cdl_light_sample t = {0}; /* a copy keeps *s in registers (see cdl_bsdf_sample_inline) */
        int ok = cdl_light_sample_li_any(l, ref, u1, u2, &t);
        *s = t;
        return ok;
    }
    float b1, b2;
    cdl_sample_triangle(u1, u2, &b1, &b2);
    return cdl_light_triangle_li(l, ref, cdl_light_triangle_at(l, b1, b2), l->L, s);
}

/* Solid-angle density of cdl_light_sample_li choosing direction wi that
 * reaches the light at distance dist (area and infinite lights; 0 for delta). */
float cdl_light_pdf_li(const cdl_light *l, cdl_vec3 ref, cdl_vec3 wi, float dist);
/* Radiance an area light emits at a point with geometric normal ng
 * towards direction wo; 0 from a back face. A textured light gives its
 * untextured scale here; cdl_light_Le_uv takes the point's uv. */
cdl_vec3 cdl_light_Le(const cdl_light *l, cdl_vec3 ng, cdl_vec3 wo);
cdl_vec3 cdl_light_Le_uv(const cdl_light *l, cdl_vec3 ng, cdl_vec3 wo, float u, float v);
/* A delta-position light's intensity towards unit direction w (leaving
 * the light) is L times this factor: 1 (point), the cone's falloff and the
 * projected texture (spot), irradiance / cos^3 inside the image (projector). */
cdl_vec3 cdl_light_I_factor(const cdl_light *l, cdl_vec3 w);
/* Solid-angle density of the direction cdl_light_sample_le chooses for a
 * spot or projector (0 outside its cone or image). */
float cdl_light_pdf_emit_dir(const cdl_light *l, cdl_vec3 w);
int cdl_light_sample_le(const cdl_light *l, float u1, float u2, float u3, float u4,
                        cdl_light_emit *e);
/* Radiance of an infinite light arriving from world direction w (unit,
 * pointing away from the scene): its map's, or the constant L. */
cdl_vec3 cdl_light_env_Le(const cdl_light *l, cdl_vec3 w);
/* Emitted flux (RGB), for power-proportional light selection. */
cdl_vec3 cdl_light_power(const cdl_light *l);

#endif
