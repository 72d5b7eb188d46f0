/* The scene: one triangle soup in one Embree geometry (primID = triangle
 * index), analytic spheres, instances of shape groups (instance.h),
 * materials, textures and lights. Loaders fill it through the
 * cdl_scene_add_* calls, then cdl_scene_commit validates it and builds
 * the BVH, the light list and the light-selection table. */
#ifndef CDL_SCENE_H
#define CDL_SCENE_H

#include <embree3/rtcore.h>
#include <float.h>
#include <stdint.h>

#include "core/alias.h"
#include "core/error.h"
#include "film/filter.h"
#include "scene/bsdf.h"
#include "scene/envmap.h"
#include "scene/light.h"
#include "scene/material.h"
#include "scene/texture.h"

/* Coordinates beyond this are rejected as absurd: float spacing there is
 * larger than any sensible scene detail. */
#define CDL_MAX_COORD 1e20f

/* Emission attached to shapes (an MTL Ke, a pbrt AreaLightSource). */
typedef struct cdl_emitter {
    cdl_vec3 L;   /* radiance */
    int twosided; /* triangles: both faces emit; otherwise the CCW front face */
    int32_t tex;  /* radiance texture (scaled by L) over the triangles' uv, or -1 */
} cdl_emitter;

/* A parameter of the file's integrator block, as text, for the method's
 * table to read (api/resolve.c) or warn about. */
#define CDL_MAX_SCENE_PARAMS 32
typedef struct cdl_scene_param {
    char name[32];
    char value[96];
    char file[256];
    int line;
} cdl_scene_param;

/* What a scene file says about rendering; the command line overrides it. */
typedef struct cdl_scene_settings {
    int has_camera;                 /* eye/right/up/fwd/fov are set */
    cdl_vec3 eye, right, up, fwd;   /* world images of camera origin and axes (pbrt) */
    float fov;                      /* degrees, on the shorter image axis */
    int ortho;                      /* orthographic camera (Mitsuba): the extent below, no fov */
    float ortho_half_w, ortho_near; /* half height: half_w * height / width */
    int has_filter;                 /* the file's pixel filter (else candela's box) */
    cdl_filter filter;
    char filter_file[256];          /* where it was given */
    int filter_line;
    int width, height;              /* 0 = not given */
    int spp;                        /* 0 = not given */
    int maxdepth;                   /* -1 = not given */
    char integrator[32];            /* the file's integrator (a candela name or not), "" = not given */
    char integrator_file[256];      /* where it was given */
    int integrator_line;
    char filename[1024];            /* the file's output image name, "" = not given */
    cdl_scene_param params[CDL_MAX_SCENE_PARAMS]; /* the integrator block's other parameters */
    int nparams;
} cdl_scene_settings;


typedef struct cdl_group cdl_group;       /* scene/instance.h */
typedef struct cdl_attr cdl_attr;         /* scene/attr.h */
typedef struct cdl_instance cdl_instance;

/* Also the public API's scene handle (candela.h). */
typedef struct cdl_scene {
    RTCDevice device;
    RTCScene rtc;

    uint32_t nverts, ntris, cap_verts, cap_tris;
    float *pos;        /* 3 per vertex, padded for Embree's 16-byte loads */
    float *nrm;        /* 3 per vertex (zero where the mesh had none) */
    float *uv;         /* 2 per vertex */
    uint32_t *idx;     /* 3 per triangle */
    uint32_t *tri_mat; /* material per triangle */
    int32_t *tri_emit; /* emitter per triangle or -1 */
    uint8_t *tri_flags;
    cdl_vec3 *face_n;  /* unit CCW normal per triangle (after commit) */
    int32_t *tri_light; /* light index per triangle or -1 (after commit) */

    /* analytic spheres, geometry 1 of the Embree scene */
    uint32_t nspheres, cap_spheres;
    float *sph;          /* x, y, z, radius per sphere (Embree's layout) */
    uint32_t *sph_mat;
    int32_t *sph_emit;
    uint8_t *sph_inward; /* ReverseOrientation: normals (and emission) point inwards */
    int32_t *sph_light;  /* after commit */

    /* shape groups (object space; their vertices live in pos/nrm/uv) and
     * their instances, geometries CDL_GEOM_INSTANCE0 + i (instance.h) */
    cdl_group *groups;
    uint32_t ngroups, cap_groups;
    int32_t open_group; /* the group shapes are added to, or -1 */
    cdl_instance *insts;
    uint32_t ninsts, cap_insts;

    cdl_emitter *emitters;
    uint32_t nemitters, cap_emitters;

    cdl_material *mats;
    uint32_t nmats, cap_mats;
    cdl_texture *texs;
    uint32_t ntexs, cap_texs;
    cdl_attr *attrs;   /* mesh attributes the textures read (scene/attr.h) */
    uint32_t nattrs, cap_attrs;
    cdl_light *lights;
    uint32_t nlights, cap_lights;
    cdl_alias light_select;
    int light_select_uniform; /* choose emitters uniformly (Mitsuba), a mesh's triangles by area, not by power */

    int32_t env_light;   /* index of the infinite light or -1 (after commit) */
    cdl_envmap *envmap;  /* its radiance map, or NULL */
    cdl_vec3 bmin, bmax; /* bounds of the geometry (after commit) */
    float eps;           /* ray offset scale (after commit) */
    char path[1024];     /* file the scene came from, for messages */
    cdl_scene_settings settings; /* what the file says about rendering (cdl_scene_open) */
} cdl_scene;

enum { CDL_TRI_HAS_N = 1, CDL_TRI_HAS_UV = 2 };

int cdl_scene_init(cdl_scene *s, const char *path, cdl_error *err);
void cdl_scene_free(cdl_scene *s);

/* Appends vertices (uv and n may be NULL); returns the first new index
 * through *first. */
int cdl_scene_add_vertices(cdl_scene *s, uint32_t n, const float *p, const float *nrm,
                           const float *uv, uint32_t *first, cdl_error *err);
/* emit: emitter index or -1. Degenerate triangles are dropped silently. */
int cdl_scene_add_triangle(cdl_scene *s, uint32_t a, uint32_t b, uint32_t c,
                           uint32_t mat, int32_t emit, uint8_t flags, cdl_error *err);
int cdl_scene_add_emitter(cdl_scene *s, cdl_vec3 L, int twosided, int32_t *id, cdl_error *err);
/* An analytic sphere; inward flips its normal (pbrt's ReverseOrientation). */
int cdl_scene_add_sphere(cdl_scene *s, cdl_vec3 c, float radius, uint32_t mat, int32_t emit,
                         int inward, cdl_error *err);
int cdl_scene_add_material(cdl_scene *s, const cdl_material *m, uint32_t *id, cdl_error *err);
int cdl_scene_add_texture(cdl_scene *s, const char *path, int *id, cdl_error *err);
/* A texture made by the caller, taken over (freed on error too); its
 * sub-texture indices must name textures added before. */
int cdl_scene_add_texture_data(cdl_scene *s, cdl_texture *t, int *id, cdl_error *err);
/* I is the intensity in W/sr. */
int cdl_scene_add_point_light(cdl_scene *s, cdl_vec3 p, cdl_vec3 I, cdl_error *err);
/* A spot (spot_linear: Mitsuba's) or projector light built by a reader: p,
 * the unit frame (ax, ay, n), L, the cone or the image's tangents and
 * tex_id (-1: none) are checked here. */
int cdl_scene_add_light(cdl_scene *s, const cdl_light *l, cdl_error *err);
/* Spot at p pointing along dir; cone angles in degrees (pbrt's coneangle, conedelta). */
int cdl_scene_add_spot_light(cdl_scene *s, cdl_vec3 p, cdl_vec3 dir, cdl_vec3 I, float cone_deg,
                             float delta_deg, cdl_error *err);
/* Radiance L arriving from direction -dir (dir: the way the light travels). */
int cdl_scene_add_distant_light(cdl_scene *s, cdl_vec3 dir, cdl_vec3 L, cdl_error *err);
/* Constant radiance L from every direction (at most one). */
int cdl_scene_add_infinite_light(cdl_scene *s, cdl_vec3 L, cdl_error *err);
/* An infinite light with radiance map (malloc'd, taken over, freed on error
 * too; NULL: constant L). */
int cdl_scene_add_env_light(cdl_scene *s, cdl_vec3 L, cdl_envmap *map, cdl_error *err);
int cdl_scene_commit(cdl_scene *s, cdl_error *err);

/* ---- ray queries ---- */

/* Geometry ids in the top-level Embree scene (and, for the first two,
 * in each group's scene); instance i is CDL_GEOM_INSTANCE0 + i. */
enum { CDL_GEOM_TRIANGLES = 0, CDL_GEOM_SPHERES = 1, CDL_GEOM_INSTANCE0 = 2 };
#define CDL_NO_INST UINT32_MAX

typedef struct cdl_hit {
    float t, b1, b2; /* distance and barycentrics of vertices 1 and 2 */
    uint32_t prim;   /* triangle or sphere index (in the group, for an instance) */
    uint32_t geom;   /* CDL_GEOM_TRIANGLES or CDL_GEOM_SPHERES */
    uint32_t inst;   /* instance index or CDL_NO_INST */
    cdl_vec3 ng;     /* Embree's unnormalized geometric normal (object space in an instance) */
    cdl_vec3 d;      /* the ray's direction (a view-dependent shading frame reads it) */
} cdl_hit;

typedef struct cdl_surface {
    cdl_vec3 p, ng, ns; /* world space; ng: unit CCW normal; ns: shading normal (after bump/normal maps) */
    cdl_vec3 ts;        /* shading tangent along dp/du (perpendicular to ns), or zero: any */
    cdl_vec3 nb;        /* shading normal before bump/normal maps (== ns without) */
    cdl_vec3 dpdu, dpdv; /* partials of p over (u, v), zero without uv */
    float u, v;
    uint32_t prim, geom, mat;
    int32_t light;      /* index of the area light on this shape, or -1 */
    cdl_vec3 kdh;       /* reflectance factor decided at the hit (material hit_kd; scene/attr.h) */
} cdl_surface;

static inline struct RTCIntersectContext cdl_context(void)
{
    struct RTCIntersectContext c;
    rtcInitIntersectContext(&c);
    c.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    return c;
}

/* Closest hit along o + t d, t in (0, tmax); returns 0 on a miss. */
static inline int cdl_intersect(const cdl_scene *s, cdl_vec3 o, cdl_vec3 d, float tmax,
                                cdl_hit *h)
{
    struct RTCIntersectContext ctx = cdl_context();
    struct RTCRayHit rh;
    rh.ray.org_x = o.x;
    rh.ray.org_y = o.y;
    rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x;
    rh.ray.dir_y = d.y;
    rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tmax;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.flags = 0;
    rh.ray.time = 0.0f;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(s->rtc, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return 0;
    h->t = rh.ray.tfar;
    h->b1 = rh.hit.u;
    h->b2 = rh.hit.v;
    h->prim = rh.hit.primID;
    h->geom = rh.hit.geomID;
    h->inst = rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID ? CDL_NO_INST : rh.hit.instID[0] - CDL_GEOM_INSTANCE0;
    h->ng = cdl_v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    h->d = d;
    return 1;
}

/* Occlusion queries carry this extended context: a shadow ray aimed at a
 * point on an analytic sphere ignores that sphere, whose grazing
 * intersections are too ill-conditioned to end the ray just short of it. */
typedef struct cdl_shadow_ctx {
    struct RTCIntersectContext ctx;
    uint32_t skip_sphere; /* sphere index or UINT32_MAX */
} cdl_shadow_ctx;

/* 1 if anything other than sphere skip_sphere blocks o + t d, t in (0, tmax). */
static inline int cdl_occluded_skip(const cdl_scene *s, cdl_vec3 o, cdl_vec3 d, float tmax,
                                    uint32_t skip_sphere)
{
    cdl_shadow_ctx sc;
    rtcInitIntersectContext(&sc.ctx);
    sc.ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    sc.skip_sphere = skip_sphere;
    struct RTCRay r;
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = tmax;
    r.mask = 0xFFFFFFFFu;
    r.flags = 0;
    r.time = 0.0f;
    rtcOccluded1(s->rtc, &sc.ctx, &r);
    return r.tfar < 0.0f;
}

static inline int cdl_occluded(const cdl_scene *s, cdl_vec3 o, cdl_vec3 d, float tmax)
{
    return cdl_occluded_skip(s, o, d, tmax, UINT32_MAX);
}

/* Closest hits of n <= 16 coherent rays (a block of camera rays) as one
 * Embree packet; found[i] = 0 where ray i misses. Scenes with instances
 * trace them one by one (coherent queries through Embree 3's instances can
 * be very slow). */
void cdl_intersect_packet(const cdl_scene *s, int n, const cdl_vec3 *o, const cdl_vec3 *d,
                          cdl_hit *h, uint8_t *found);

/* Occlusion of n <= 16 coherent shadow rays (from neighbouring points to
 * one light) as one Embree packet where they skip the same sphere (else,
 * and with instances, one by one): blocked[i] = 1 where ray i is blocked. */
void cdl_occluded_packet(const cdl_scene *s, int n, const cdl_vec3 *o, const cdl_vec3 *d,
                         const float *tmax, const uint32_t *skip, uint8_t *blocked);

/* A bundle of shadow rays traced together as an Embree ray stream
 * (coherent when they share an end point, as the point-light methods'
 * bundles do). Sets hit[i] = 1 where ray i is blocked. */
void cdl_occluded_bundle(const cdl_scene *s, uint32_t n, const cdl_vec3 *o,
                         const cdl_vec3 *d, const float *tmax, uint32_t skip_sphere,
                         uint8_t *blocked);

/* A triangle's point and unit shading normal (face_n without vertex
 * normals) at barycentrics (b1, b2); t: its vertex indices. The position
 * is barycentric: closer to the surface than o + t d. */
static inline void cdl_triangle_point(const cdl_scene *s, const uint32_t *t, uint8_t fl, cdl_vec3 face_n, float b1,
                                      float b2, cdl_vec3 *p, cdl_vec3 *ns)
{
    float b0 = 1.0f - b1 - b2;
    const float *p0 = s->pos + 3 * (size_t)t[0], *p1 = s->pos + 3 * (size_t)t[1], *p2 = s->pos + 3 * (size_t)t[2];
    *p = cdl_v3(b0 * p0[0] + b1 * p1[0] + b2 * p2[0], b0 * p0[1] + b1 * p1[1] + b2 * p2[1],
                b0 * p0[2] + b1 * p1[2] + b2 * p2[2]);
    *ns = face_n;
    if (fl & CDL_TRI_HAS_N) {
        const float *n0 = s->nrm + 3 * (size_t)t[0], *n1 = s->nrm + 3 * (size_t)t[1],
                    *n2 = s->nrm + 3 * (size_t)t[2];
        cdl_vec3 n = cdl_v3(b0 * n0[0] + b1 * n1[0] + b2 * n2[0], b0 * n0[1] + b1 * n1[1] + b2 * n2[1],
                            b0 * n0[2] + b1 * n1[2] + b2 * n2[2]);
        float len = cdl_length(n);
        if (len > 1e-12f && isfinite(len))
            *ns = cdl_scale(n, 1.0f / len);
    }
}

/* The surface at a hit, its shading frame perturbed by the material's bump
 * or normal map (seen along h->d) as every method sees it: every hit
 * (_any), and inline a plain material on the scene's triangles without uv
 * (path does this at every vertex: the call cost as much as the work). */
void cdl_surface_at_any(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf);
static inline void cdl_surface_at(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf)
{
    if (h->inst == CDL_NO_INST && h->geom == CDL_GEOM_TRIANGLES) {
        uint32_t prim = h->prim;
        uint8_t fl = s->tri_flags[prim];
        const cdl_material *m = &s->mats[s->tri_mat[prim]];
        if (!(fl & CDL_TRI_HAS_UV) && m->type != CDL_MAT_BLEND && !m->hit_kd &&
            !cdl_mat_uses_tangent(&m->maps, m->alpha_x, m->alpha_y)) {
            cdl_vec3 p, ns, zero = cdl_v3(0.0f, 0.0f, 0.0f);
            cdl_triangle_point(s, s->idx + 3 * (size_t)prim, fl, s->face_n[prim], h->b1, h->b2, &p, &ns);
            sf->p = p;
            sf->ng = s->face_n[prim];
            sf->ns = sf->nb = ns;
            sf->ts = sf->dpdu = sf->dpdv = zero;
            sf->u = sf->v = 0.0f;
            sf->prim = prim;
            sf->geom = CDL_GEOM_TRIANGLES;
            sf->mat = s->tri_mat[prim];
            sf->light = s->tri_light[prim];
            sf->kdh = cdl_v3(1.0f, 1.0f, 1.0f);
            return;
        }
    }
    cdl_surface_at_any(s, h, sf);
}
/* The tangent frame and bump/normal map of sf's material applied to sf
 * (sf->ns, nb and ts), for a viewer in direction wo (scene/shading.c). */
void cdl_surface_shade(const cdl_scene *s, cdl_surface *sf, cdl_vec3 wo);
/* Texture lookup folded in; the frame is sf's ns and ts. */
void cdl_scene_bsdf_any(const cdl_scene *s, const cdl_surface *sf, cdl_bsdf *b);
/* The same, a plain Lambertian material (no texture, map or tangent
 * frame) built inline: every vertex of path builds one. */
static inline void cdl_scene_bsdf(const cdl_scene *s, const cdl_surface *sf, cdl_bsdf *b)
{
    const cdl_material *m = &s->mats[sf->mat];
    if (m->type != CDL_MAT_DIFFUSE || m->hit_kd || m->kd_tex >= 0 || m->maps.on || (m->masked && m->opacity_tex >= 0) ||
        !cdl_is_black(sf->ts)) {
        cdl_scene_bsdf_any(s, sf, b);
        return;
    }
    cdl_bsdf_init_common(b, m, m->kd, sf->ns, sf->ng);
}

/* Origin for a ray leaving p in direction d: pushed off the surface along
 * ng to the side d goes to, so the ray cannot hit the surface it left. */
static inline cdl_vec3 cdl_offset(const cdl_scene *s, cdl_vec3 p, cdl_vec3 ng, cdl_vec3 d)
{
    float m = cdl_maxf(fabsf(p.x), cdl_maxf(fabsf(p.y), fabsf(p.z)));
    float e = s->eps + m * 1e-5f;
    return cdl_madd(p, ng, cdl_dot(d, ng) < 0.0f ? -e : e);
}

/* Length of a shadow ray from cdl_offset(p, ...) towards a light point at
 * distance dist: shortened by twice the offset as well as relatively, so
 * that far from the origin (large offsets) it still stops short of the
 * light's own surface. FLT_MAX stays FLT_MAX (lights at infinity). */
static inline float cdl_shadow_tmax(const cdl_scene *s, cdl_vec3 p, float dist)
{
    if (!(dist < FLT_MAX))
        return FLT_MAX;
    float m = cdl_maxf(fabsf(p.x), cdl_maxf(fabsf(p.y), fabsf(p.z))) + dist;
    float t = dist * (1.0f - 1e-4f) - 2.0f * (s->eps + m * 1e-5f);
    return t > 0.0f ? t : 0.0f;
}

/* 1 if nothing blocks the segment from surface point p (geometric normal
 * ng) to the point of light sample ls on light l. */
static inline int cdl_light_sample_visible(const cdl_scene *s, const cdl_light *l, cdl_vec3 p, cdl_vec3 ng,
                                           const cdl_light_sample *ls)
{
    cdl_vec3 o = cdl_offset(s, p, ng, ls->wi);
    uint32_t skip = l->type == CDL_LIGHT_SPHERE ? l->prim : UINT32_MAX;
    return !cdl_occluded_skip(s, o, ls->wi, cdl_shadow_tmax(s, p, ls->dist), skip);
}

#endif
