/* Textures: RGB images (map_Kd, Mitsuba's bitmap, pbrt's imagemap),
 * checkerboards, products, mixes and constants. Images are stored linear; sRGB 8-bit files are
 * decoded through the sRGB curve unless raw.
 *
 * Surface uv is candela's (OBJ's, pbrt's): v = 0 at the bottom of the
 * image. A texture maps it affinely to image coordinates (s, t) in [0, 1]
 * with t = 0 at the top row: (u, 1 - v) for OBJ and pbrt; Mitsuba's uv is
 * (u, 1 - v) too (its OBJ reader flips v), followed by the texture's to_uv.
 * A checkerboard's cells are laid out over the same affine map of (u, v). */
#ifndef CDL_TEXTURE_H
#define CDL_TEXTURE_H

#include "core/error.h"
#include "core/vec.h"

typedef enum cdl_tex_type {
    CDL_TEX_BITMAP,  /* an image */
    CDL_TEX_CHECKER, /* checkerboard of a (color0, pbrt's tex1) and b (color1, tex2) */
    CDL_TEX_CONST,   /* the constant a */
    CDL_TEX_SCALE,   /* sub[0] (or a) times sub[1] (or b) times scale */
    CDL_TEX_MIX,     /* (1 - t) sub[0] (or a) + t sub[1] (or b), t = amount_tex (or amount) */
    CDL_TEX_ATTRIBUTE /* Mitsuba's mesh_attribute `attr` times scale: read at a hit (scene/attr.h),
                       * not at a uv */
} cdl_tex_type;

#define CDL_ATTR_NAME 48 /* longest attribute name + 1 */

/* Outside the image: repeat, mirror, clamp to the edge, or black texels
 * (pbrt's "black"). */
typedef enum cdl_tex_wrap { CDL_WRAP_REPEAT, CDL_WRAP_MIRROR, CDL_WRAP_CLAMP, CDL_WRAP_BLACK } cdl_tex_wrap;

typedef struct cdl_texture {
    cdl_tex_type type;
    int w, h;
    float *rgb;      /* bitmap: 3*w*h, top row first */
    int legacy;      /* bitmap read by the OBJ/pbrt readers: their original lookup */
    int wrap;        /* cdl_tex_wrap */
    int nearest;     /* nearest texel instead of bilinear */
    float m[6];      /* (s, t) = (m0 u + m1 v + m2, m3 u + m4 v + m5) */
    cdl_vec3 a, b;   /* checker colors, constant, scale and mix operands */
    int sub[2];      /* textures in place of a and b (-1: the constants) */
    float scale;
    char attr[CDL_ATTR_NAME]; /* attribute: its name */
    int attr_key;             /* and the scene's attribute of that name, or -1 (after commit) */
    int unit_cells;  /* checker: pbrt's cells, a where floor(s) + floor(t) is even (colour
                      * and scalar alike); else Mitsuba's half cells */
    int amount_tex;  /* mix: the weight of b as a texture's scalar value, or -1: amount */
    float amount;
} cdl_texture;

/* An OBJ/pbrt image texture (repeating, bilinear, sRGB decoded). */
int cdl_texture_load(cdl_texture *t, const char *path, cdl_error *err);
/* An image at its defaults (repeat, bilinear, uv (u, 1 - v)); raw keeps
 * 8-bit values undecoded. EXR (and 16-bit PNG) through film/image. */
int cdl_texture_load_image(cdl_texture *t, const char *path, int raw, cdl_error *err);
/* A non-image texture at its defaults (uv (u, 1 - v), no sub-textures). */
void cdl_texture_init(cdl_texture *t, cdl_tex_type type);
void cdl_texture_free(cdl_texture *t);

/* Texture i of the array texs at surface (u, v): its color (Mitsuba's eval),
 * its scalar value (eval_1: the luminance of a color) and the gradient of
 * the scalar value over (u, v) (eval_1_grad: of the bilinear images it is
 * made of, through products and mixes; piecewise constants add 0). */
cdl_vec3 cdl_texture_eval(const cdl_texture *texs, int i, float u, float v);
float cdl_texture_eval1(const cdl_texture *texs, int i, float u, float v);
void cdl_texture_grad1(const cdl_texture *texs, int i, float u, float v, float grad[2]);

/* Mitsuba's luminance of linear sRGB. */
static inline float cdl_tex_luminance(cdl_vec3 c)
{
    return 0.212671f * c.x + 0.715160f * c.y + 0.072169f * c.z;
}

#endif
