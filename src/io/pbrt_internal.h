/* State shared by the parts of the pbrt reader: pbrt_loader.c (directives,
 * graphics state, camera and settings), pbrt_lights.c, pbrt_shapes.c
 * (shapes, instancing), pbrt_materials.c (materials) and pbrt_textures.c
 * (textures). Not a public interface. */
#ifndef CDL_PBRT_INTERNAL_H
#define CDL_PBRT_INTERNAL_H

#include <stdint.h>

#include "core/transform.h"
#include "io/settings.h"
#include "scene/mesh.h"
#include "io/pbrt_lexer.h"
#include "io/pbrt_params.h"

#define CDL_PBRT_MAX_INCLUDE 32

/* Material slot of the graphics state: a scene material index, or these. */
enum { CDL_PBRT_MAT_DEFAULT = -1, /* pbrt's default: matte 0.5, made on first use */
       CDL_PBRT_MAT_NONE = -2 };  /* Material "" / "none" / "interface": no surface */

typedef enum cdl_pbrt_block { CDL_PBRT_ATTR, CDL_PBRT_XFORM, CDL_PBRT_OBJECT } cdl_pbrt_block;

typedef struct cdl_pbrt_gstate {
    cdl_mat4 ctm;
    int reverse;           /* ReverseOrientation */
    int32_t mat;           /* scene material or CDL_PBRT_MAT_* */
    int area;              /* AreaLightSource "diffuse" active */
    cdl_vec3 area_L;
    int area_twosided;
    cdl_pbrt_block kind;   /* what pushed this state (on the stack) */
    int line;              /* where it was pushed */
    char file[1024];
} cdl_pbrt_gstate;

typedef struct cdl_pbrt_shape {
    int sphere;     /* 1: analytic sphere of this radius; 0: mesh */
    int quads;      /* the mesh's triangles are bilinear patches split in two */
    double radius;
    cdl_mesh mesh; /* in object space, validated */
} cdl_pbrt_shape;

typedef struct cdl_pbrt_object {
    char *name;
    uint32_t group; /* the scene's shape group */
} cdl_pbrt_object;

/* A pbrt texture: a constant, a scene texture that evaluates to pbrt's
 * value, or a class candela lacks (its definition warned). */
typedef enum cdl_pbrt_tex_kind { CDL_PBRT_TEX_CONST, CDL_PBRT_TEX_SCENE, CDL_PBRT_TEX_OTHER } cdl_pbrt_tex_kind;

typedef struct cdl_pbrt_tex {
    char *name;
    int is_float;
    cdl_pbrt_tex_kind kind;
    cdl_vec3 value; /* CONST: the value; SCENE: its mean (for parameters that take only
                     * constants); OTHER: the grey that stands for it */
    int tex_id;     /* SCENE: the scene texture, else -1 */
} cdl_pbrt_tex;

/* One scene copy of an image per distinct use (file, decoding, mapping). */
typedef struct cdl_pbrt_image {
    char *key;
    int tex_id;
    cdl_vec3 mean;
} cdl_pbrt_image;

typedef struct cdl_pbrt_named {
    char *name;
    int32_t mat;
} cdl_pbrt_named;

typedef struct cdl_pbrt_coordsys {
    char *name;
    cdl_mat4 m;
} cdl_pbrt_coordsys;

typedef struct cdl_pbrt_ctx {
    cdl_scene *s;
    cdl_scene_settings *set;
    cdl_error *err;
    const char *main_path;     /* relative file names resolve against its directory (pbrt-v3) */
    cdl_pbrt_lexer files[CDL_PBRT_MAX_INCLUDE + 1];
    int nfiles;
    const char *file;          /* file of the current directive */
    int line;                  /* its line */
    cdl_pbrt_params ps;

    cdl_pbrt_gstate gs;
    cdl_pbrt_gstate *stack;
    int nstack, capstack;
    int in_world, world_done, saw_camera;
    int active_end;            /* ActiveTransform EndTime: transforms are ignored */

    cdl_pbrt_named *named;
    int nnamed, capnamed;
    cdl_pbrt_tex *texs;
    int ntexs, captexs;
    cdl_pbrt_image *imgs;
    int nimgs, capimgs;
    int32_t *variants;         /* pairs (material, its variant displacing the partials) */
    int nvariants, capvariants;
    cdl_pbrt_coordsys *cs;
    int ncs, capcs;
    cdl_pbrt_object *objs;
    int nobjs, capobjs;
    int cur_obj;               /* object being defined or -1 */
    int32_t default_mat;       /* scene index of pbrt's default material or -1 */
    int32_t black_mat;         /* an emitter's surface under Material "none", or -1 */
    uint32_t nshapes;          /* shapes that produced geometry */
    int warned_none, warned_inst_light;
} cdl_pbrt_ctx;

/* Error at file:line of the current file (always returns CDL_ERR_INPUT). */
int cdl_pbrt_error(cdl_pbrt_ctx *c, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void cdl_pbrt_warn(cdl_pbrt_ctx *c, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* A scene call failed: give its message the current directive's place. */
int cdl_pbrt_scene_rc(cdl_pbrt_ctx *c, int rc);
/* name resolved against the main scene file's directory. */
void cdl_pbrt_resolve(const cdl_pbrt_ctx *c, const char *name, char *out, size_t n);
/* 0 if path is a regular file; else an error at the directive's line. */
int cdl_pbrt_check_file(cdl_pbrt_ctx *c, const char *what, const char *path);

/* pbrt_shapes.c */
int cdl_pbrt_shape_directive(cdl_pbrt_ctx *c, const char *type);
/* ObjectBegin name / ObjectEnd: the shapes between become a scene shape
 * group; ObjectInstance places it under the current transform. */
int cdl_pbrt_object_begin(cdl_pbrt_ctx *c, const char *name);
int cdl_pbrt_object_end(cdl_pbrt_ctx *c);
int cdl_pbrt_object_instance(cdl_pbrt_ctx *c, const char *name);
void cdl_pbrt_shape_free(cdl_pbrt_shape *sh);

/* pbrt_lights.c */
int cdl_pbrt_light(cdl_pbrt_ctx *c, const char *type);
int cdl_pbrt_area_light(cdl_pbrt_ctx *c, const char *type);

/* pbrt_materials.c */
/* Makes the scene material of a Material / MakeNamedMaterial directive;
 * *mat may come back as CDL_PBRT_MAT_NONE. */
int cdl_pbrt_material(cdl_pbrt_ctx *c, const char *type, const char *name, int32_t *mat);
/* The current material, creating pbrt's default on first use. */
int cdl_pbrt_current_material(cdl_pbrt_ctx *c, int32_t *mat);
/* The material a shape uses: mat itself, or its variant whose bump map
 * displaces pbrt's shading frame of meshes with vertex normals
 * (cdl_bump_frame) when vnormals, else the surface partials. */
int cdl_pbrt_shape_material(cdl_pbrt_ctx *c, uint32_t mat, int vnormals, uint32_t *out);

/* pbrt_textures.c */
int cdl_pbrt_texture(cdl_pbrt_ctx *c, const char *name, const char *type, const char *cls);
/* The texture a "texture" parameter names (its type's table first). */
int cdl_pbrt_texture_ref(cdl_pbrt_ctx *c, const cdl_pbrt_param *p, int is_float, const cdl_pbrt_tex **out);
/* pbrt-v4's "string normalmap": the image as a scene texture. */
int cdl_pbrt_normal_map(cdl_pbrt_ctx *c, const cdl_pbrt_param *p, int *tex);
void cdl_pbrt_textures_free(cdl_pbrt_ctx *c);

#endif
