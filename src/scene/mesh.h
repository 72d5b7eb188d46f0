/* A triangle mesh in its own space, as every mesh reader (PLY, Mitsuba's
 * serialized, pbrt's trianglemesh, generated shapes) hands it over, and its
 * insertion into the scene under a transform. */
#ifndef CDL_MESH_H
#define CDL_MESH_H

#include <stdint.h>

#include "core/error.h"
#include "core/transform.h"
#include "scene/scene.h"

/* A named per-vertex or per-triangle attribute (Mitsuba's mesh
 * attributes: "vertex_color", "face_weight"), read by mesh_attribute
 * textures. */
typedef struct cdl_mesh_attr {
    char name[CDL_ATTR_NAME];
    int per_face; /* one value per triangle, else per vertex */
    int dim;      /* 1 or 3 floats per value */
    float *data;
} cdl_mesh_attr;

typedef struct cdl_mesh {
    uint32_t nverts, ntris;
    float *pos;    /* 3 per vertex */
    float *nrm;    /* 3 per vertex, or NULL */
    float *uv;     /* 2 per vertex, or NULL */
    uint32_t *idx; /* 3 per triangle, each < nverts */
    cdl_mesh_attr *attrs;
    int nattrs;
} cdl_mesh;

/* Allocates the arrays (nrm, uv only when asked); errors name file:line. */
int cdl_mesh_alloc(cdl_mesh *m, uint32_t nverts, uint32_t ntris, int has_n, int has_uv, const char *file,
                   int line, cdl_error *err);
/* Frees the arrays and zeroes m; safe on a zeroed or freed mesh. */
void cdl_mesh_free(cdl_mesh *m);
/* Appends an attribute of n * dim zeroed floats (n = ntris or nverts);
 * returns it, or NULL when out of memory. */
cdl_mesh_attr *cdl_mesh_add_attr(cdl_mesh *m, const char *name, int per_face, int dim);

/* A sphere of radius r about the origin, normals outwards (inwards when
 * flip), pbrt's (u, v): for spheres a transform cannot keep analytic. */
int cdl_mesh_sphere(cdl_mesh *m, double r, int flip, const char *file, int line, cdl_error *err);

/* pbrt's disk (an annulus of radii ri < r at z = h, up to angle phimax in
 * radians) and cylinder (radius r from zmin to zmax) as nseg-segment
 * meshes without shading normals: a disk faces +z, a cylinder outwards
 * (counter-clockwise), so cdl_scene_add_mesh's rule orients them as pbrt
 * does; pbrt's (u, v). */
int cdl_mesh_disk(cdl_mesh *m, double h, double r, double ri, double phimax, int nseg, const char *file, int line,
                  cdl_error *err);
int cdl_mesh_cylinder(cdl_mesh *m, double r, double zmin, double zmax, double phimax, int nseg, const char *file,
                      int line, cdl_error *err);

/* Adds m transformed by xf with pbrt-v3's orientation rule (its attributes
 * with it, see cdl_scene_attr): a triangle
 * faces its shading normals when the mesh has them, otherwise its CCW
 * normal flipped by reverse XOR a handedness-swapping xf. Errors (a
 * singular xf, vertices beyond CDL_MAX_COORD) name file:line. */
int cdl_scene_add_mesh(cdl_scene *s, const cdl_mesh *m, const cdl_mat4 *xf, int reverse, uint32_t mat,
                       int32_t emit, const char *file, int line, cdl_error *err);

#endif
