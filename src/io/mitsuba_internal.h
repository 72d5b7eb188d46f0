/* State shared by the parts of the Mitsuba reader: mitsuba_loader.c (files,
 * includes, defaults, ids, sensor and integrator),
 * mitsuba_values.c (property values, transforms), mitsuba_shapes.c and
 * mitsuba_materials.c (bsdfs, textures, emitters).
 * Not a public interface.
 *
 * Mitsuba 0.6 and Mitsuba 3 name the same properties in camelCase and
 * snake_case (toWorld / to_world, intIOR / int_ior): names are compared
 * after folding camelCase into snake_case. */
#ifndef CDL_MITSUBA_INTERNAL_H
#define CDL_MITSUBA_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "core/transform.h"
#include "io/settings.h"
#include "io/xml.h"

#define CDL_MTS_MAX_INCLUDE 16

typedef enum cdl_mts_kind { CDL_MTS_BSDF, CDL_MTS_TEXTURE, CDL_MTS_OTHER, CDL_MTS_SHAPEGROUP } cdl_mts_kind;

/* An object declared with an id, for <ref id="..."/>. */
typedef struct cdl_mts_id {
    char *id;
    cdl_mts_kind kind;
    int32_t mat;    /* bsdf: scene material, or -1 for a surface that is not there (null) */
    int tex;        /* texture: scene texture or -1 for a constant; shapegroup: the scene's shape group */
    cdl_vec3 value; /* texture: constant value or the bitmap's scale */
} cdl_mts_id;

typedef struct cdl_mts_var {
    char *name, *value;
    int given; /* from the command line (-D), not a <default> */
    int used;  /* a $name referred to it */
} cdl_mts_var;

#define CDL_MTS_MAX_PATHS 16

typedef struct cdl_mts_ctx {
    cdl_scene *s;
    cdl_scene_settings *set;
    cdl_error *err;
    const char *main_path;  /* relative file names resolve against its directory */
    const char *file;       /* the XML file being read (main or include) */
    int depth;              /* include depth */
    cdl_mts_var *vars;
    int nvars, capvars;
    cdl_mts_id *ids;
    int nids, capids;
    int32_t default_mat;    /* Mitsuba's default bsdf (diffuse 0.5), made on first use, or -1 */
    char paths[CDL_MTS_MAX_PATHS][1024]; /* <path> folders, searched last given first */
    int npaths;
    int saw_sensor;
    uint32_t nshapes;
    int in_group;           /* reading the shapes of a shapegroup */
    int in_twosided;        /* reading the bsdf a twosided wrapper holds */
    int said_one_sided;     /* the one-sided approximation was warned of (once per file) */
    int legacy;             /* the main file's version is 0.x: Mitsuba 0.6's conventions where they differ */
    float *sky_rgb;         /* the daylight emitters' image, added as the environment light at the end */
    int sky_w, sky_h, sky_line;
    cdl_vec3 sky_axes[3];
    char sky_file[1024];
    char buf[4096];         /* an attribute after $variable substitution */
    cdl_xml_node *roots[CDL_MTS_MAX_INCLUDE + 1]; /* the open documents, outermost first */
} cdl_mts_ctx;

/* Error / warning at file:line of the current file (errors return CDL_ERR_INPUT). */
int cdl_mts_error(cdl_mts_ctx *c, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
void cdl_mts_warn(cdl_mts_ctx *c, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* A scene call failed: give its message the element's place. */
int cdl_mts_scene_rc(cdl_mts_ctx *c, int line, int rc);

/* Attribute attr of n after $variable substitution (c->buf; valid until the
 * next call), or NULL when absent; *rc is set on an undefined variable. */
const char *cdl_mts_attr(cdl_mts_ctx *c, const cdl_xml_node *n, const char *attr, int *rc);
/* The plugin type of n ("type" attribute), substituted; an error when absent. */
int cdl_mts_type(cdl_mts_ctx *c, const cdl_xml_node *n, char *out, size_t cap);
/* 1 when a and b name the same property (camelCase folded). */
int cdl_mts_same_name(const char *a, const char *b);
/* The property child of n called name (any tag), marked used; NULL if absent. */
cdl_xml_node *cdl_mts_prop(cdl_mts_ctx *c, cdl_xml_node *n, const char *name);
/* Warns once per property child of n that nothing used (what: "bsdf \"diffuse\""). */
void cdl_mts_warn_unused(cdl_mts_ctx *c, cdl_xml_node *n, const char *what);
/* File name resolved against the main scene file's directory; an error if
 * it is not a regular file. */
int cdl_mts_path(cdl_mts_ctx *c, int line, const char *name, char *out, size_t n);

/* mitsuba_values.c: typed properties (default when absent), validated. */
int cdl_mts_float(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double *out);
int cdl_mts_int(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, long def, long *out);
int cdl_mts_bool(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, int def, int *out);
/* A string property copied to out (def may be NULL: out becomes ""). */
int cdl_mts_string(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, const char *def, char *out, size_t cap);
/* A color from <rgb>, <srgb>, <spectrum> or <float>; a node, not a name. */
int cdl_mts_color_node(cdl_mts_ctx *c, cdl_xml_node *p, cdl_vec3 *out);
/* <point>/<vector> property; *found tells whether it was there. */
int cdl_mts_vec(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_vec3 def, cdl_vec3 *out, int *found);
/* <transform name=...>, identity when absent. */
int cdl_mts_transform(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_mat4 *out);
/* An object declared with id (ids are unique). */
int cdl_mts_add_id(cdl_mts_ctx *c, const cdl_xml_node *n, const cdl_mts_id *v);
/* <default name value>: defines name unless it is defined already. */
int cdl_mts_default(cdl_mts_ctx *c, const cdl_xml_node *n);
/* Defines $name (name[0..len)) unless it is: given = from the command line. */
int cdl_mts_define(cdl_mts_ctx *c, const char *name, size_t len, const char *value, int given);
/* <path value>: a folder (relative to the file it is in) searched for
 * relative file names before the main file's folder, as Mitsuba's file
 * resolver does. */
int cdl_mts_add_path(cdl_mts_ctx *c, const cdl_xml_node *n);
const cdl_mts_id *cdl_mts_find_id(cdl_mts_ctx *c, const char *id);
/* The top-level element with this id in any open document, declared before
 * or after (innermost document first), or NULL. */
cdl_xml_node *cdl_mts_find_decl(cdl_mts_ctx *c, const char *id);

/* mitsuba_shapes.c */
int cdl_mts_shape(cdl_mts_ctx *c, cdl_xml_node *n);

/* mitsuba_materials.c */
/* A <bsdf> element (declared at the top level or nested): its material
 * (-1: a null bsdf, no surface). */
int cdl_mts_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat);
/* The first nested <bsdf> or <ref> to a bsdf among n's children (*found
 * 0 when none); strict: a <ref> to anything else is an error (shapes),
 * else skipped (a wrapper's texture). */
int cdl_mts_child_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, int strict, int32_t *mat, int *found);
/* Colour property `name` of n (def when absent): a value, a nested
 * <texture> or a <ref> to one; tex (NULL: values only, a texture warns and
 * gives its scale) receives the texture or -1. Negative values fail. */
int cdl_mts_color_prop(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_vec3 def, cdl_vec3 *out, int *tex);
/* Adds material m (warns where it reads a mesh attribute in a slot that
 * cannot: only reflectances and blend weights are read at the hit). */
int cdl_mts_add_material(cdl_mts_ctx *c, int line, const cdl_material *m, uint32_t *idx);
/* A top-level or nested <texture>: scene texture (or -1) and value. */
int cdl_mts_texture(cdl_mts_ctx *c, cdl_xml_node *n, int *tex, cdl_vec3 *value);
/* An <emitter type="area"> inside a shape: the scene emitter. */
int cdl_mts_area(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *emit);
/* A non-area <emitter> (point, spot, directional, constant, envmap, sunsky, sky, sun). */
int cdl_mts_emitter(cdl_mts_ctx *c, cdl_xml_node *n);
/* A lat-long environment light in Mitsuba's frame and texel layout: axes are
 * the world images of the map's local x, y (up) and z; the radiance is the
 * image file path times scale, or (path NULL) the w x h texels rgb, taken
 * over (freed on failure). envmap and the daylight emitters both come here. */
int cdl_mts_latlong_light(cdl_mts_ctx *c, int line, const cdl_vec3 axes[3], const char *path, float scale, int w,
                          int h, float *rgb);

/* mitsuba_sunsky.c */
/* <emitter type="sunsky|sky|sun">: rasterized into the pending daylight image. */
int cdl_mts_sunsky(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, const cdl_mat4 *to_world);
/* Adds the pending daylight image as the environment light (after reading). */
int cdl_mts_sky_finish(cdl_mts_ctx *c);
/* Mitsuba's default surface, diffuse 0.5, made on first use. */
int cdl_mts_default_material(cdl_mts_ctx *c, int32_t *mat);

/* mitsuba_textures.c */
/* A texture plugin other than the constant ones of cdl_mts_texture
 * (bitmap, checkerboard, scale, rawconstant): the scene texture. */
int cdl_mts_texture_plugin(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, int *tex, cdl_vec3 *value);
/* A float property that may be a texture (*tex >= 0; its scalar value). */
int cdl_mts_float_or_texture(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double *out, int *tex);
/* bumpmap / normalmap: a copy of the nested bsdf's material with the map. */
int cdl_mts_perturbed_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, int32_t *mat);
/* eta and k of a named conductor ("Al", "a-C"...) in RGB; -1 if unknown. */
int cdl_mts_named_conductor(const char *name, cdl_vec3 *eta, cdl_vec3 *k);

#endif
