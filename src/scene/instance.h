/* Shape groups and their instances (Mitsuba's shapegroup/instance, pbrt's
 * ObjectBegin/ObjectInstance) as Embree instances: each group is one
 * Embree scene in object space, each instance an Embree instance geometry
 * of the top-level scene with its own transform, so N instances cost N
 * small records, not N copies of the geometry.
 *
 * A loader opens a group, adds shapes with the usual cdl_scene_add_* calls
 * (they land at the end of the scene's arrays), and closes it: the shapes
 * since the opening move from the top level into the group. Vertices stay
 * in the scene's arrays, shared by all instances. Groups do not emit
 * (pbrt-v4 and Mitsuba do not instance area lights): their triangles' and
 * spheres' emitters are dropped; the loaders warn. */
#ifndef CDL_INSTANCE_H
#define CDL_INSTANCE_H

#include <stdint.h>

#include "core/error.h"
#include "core/transform.h"
#include "scene/scene.h"

struct cdl_group {
    uint32_t ntris, nspheres;
    uint32_t *idx;       /* 3 per triangle, into the scene's vertex arrays */
    uint32_t *tri_mat;
    uint8_t *tri_flags;  /* CDL_TRI_* */
    cdl_vec3 *face_n;    /* unit CCW normal per triangle, object space */
    float *sph;          /* x, y, z, radius per sphere, object space */
    uint32_t *sph_mat;
    uint8_t *sph_inward;
    cdl_vec3 bmin, bmax; /* object-space bounds */
    RTCScene rtc;        /* after commit, when instanced */
    uint32_t first_tri, first_sph; /* while open: where its shapes start in the scene's arrays */
};

struct cdl_instance {
    uint32_t group;
    float xf[12]; /* object to world, 3 x 4 row-major (Embree's FLOAT3X4_ROW_MAJOR) */
    float nm[9];  /* normals: inverse transpose of the linear part, row-major */
};

/* Opens a new (empty) group; its index goes to *id. Groups do not nest. */
int cdl_scene_group_begin(cdl_scene *s, uint32_t *id, cdl_error *err);
/* Closes the open group: what was added since cdl_scene_group_begin is its. */
int cdl_scene_group_end(cdl_scene *s, cdl_error *err);
/* An instance of group `group` (closed) placed by xf (object to world). */
int cdl_scene_add_instance(cdl_scene *s, uint32_t group, const cdl_mat4 *xf, cdl_error *err);

/* ---- used by scene.c ---- */

/* World bounds of the instances grown into *lo, *hi. */
void cdl_instances_bounds(const cdl_scene *s, cdl_vec3 *lo, cdl_vec3 *hi);
/* Builds the groups' Embree scenes and attaches the instances to s->rtc. */
int cdl_instances_commit(cdl_scene *s, cdl_error *err);
void cdl_instances_free(cdl_scene *s);
/* The world-space surface at a hit inside instance h->inst. */
void cdl_instance_surface(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf);

/* scene.c's surface routines, on arrays that may be a group's. */
void cdl_triangle_surface(const cdl_scene *s, const uint32_t *t, uint8_t flags, cdl_vec3 face_n, float b1, float b2,
                          cdl_surface *sf);
void cdl_sphere_surface(const float *q, int inward, cdl_vec3 ng, cdl_surface *sf);

#endif
