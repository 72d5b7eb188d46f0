/* Mesh attributes (Mitsuba's "vertex_color", "face_weight", read by
 * mesh_attribute textures) and the materials decided at a hit: a blend of
 * two BSDFs (Mitsuba's blendbsdf) and reflectance from an attribute.
 *
 * The scene keeps an attribute only if a texture names it when its mesh is
 * added (Mitsuba declares textures before the shapes that use them). What
 * a hit decides is carried by the surface (cdl_surface.mat, .kdh) and by
 * the vertex store, so that every method rebuilds the same BSDF. */
#ifndef CDL_ATTR_H
#define CDL_ATTR_H

#include <stdint.h>

#include "core/error.h"
#include "scene/mesh.h"
#include "scene/scene.h"

/* An attribute as the scene keeps it: values for the scene's triangles
 * (per face) or vertices (per vertex) [first, first + count). */
struct cdl_attr {
    char name[CDL_ATTR_NAME];
    int per_face, dim;
    int key;       /* index of the first attribute of this name */
    uint32_t first, count;
    float *data;   /* dim per value */
};

/* Keeps m's referenced attributes: vertices from first_vert, triangles as
 * tri_of (scene triangle of mesh triangle t, or UINT32_MAX: dropped). */
int cdl_scene_add_attrs(cdl_scene *s, const cdl_mesh *m, uint32_t first_vert, const uint32_t *tri_of,
                        const char *file, int line, cdl_error *err);
/* The name of an attribute that material mat reads (reflectance, blend
 * weights) and mesh m (NULL: a shape without attributes) lacks, or NULL;
 * *face: whether m has it per face (not kept inside a shape group). */
const char *cdl_material_missing_attr(const cdl_scene *s, uint32_t mat, const cdl_mesh *m, int *face);
/* Whether some texture of s reads attribute `name`. */
int cdl_scene_attr_wanted(const cdl_scene *s, const char *name);
void cdl_attrs_free(cdl_scene *s);
/* Binds the mesh_attribute textures to the attributes and marks the
 * materials whose reflectance is decided at a hit (cdl_scene_commit). */
void cdl_attrs_commit(cdl_scene *s);

/* The material of the surface at hit h (sf filled but for the material):
 * blends resolved, sf->kdh set for materials that take it. */
void cdl_surface_material(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf);

#endif
