/* pbrt textures as scene textures (texture.h): constant, imagemap,
 * checkerboard, scale and mix, as pbrt-v3 (src/textures/) and pbrt-v4
 * (textures.cpp) define them, with their uv mapping (s, t) = (su u + du,
 * sv v + dv); and the texture references of material parameters. A
 * texture's scene copy evaluates to pbrt's value, its scale included. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "film/image.h"
#include "io/pbrt_internal.h"

/* The largest uv scale or offset: beyond it a texture lookup loses every
 * digit of (u, v) (texture.c treats |s| > 1e6 as invalid). */
#define MAX_UV_MAP 1e6

static const cdl_pbrt_tex *find_tex(const cdl_pbrt_ctx *c, const char *name, int is_float)
{
    for (int i = c->ntexs; i-- > 0;)
        if (c->texs[i].is_float == is_float && !strcmp(c->texs[i].name, name))
            return &c->texs[i];
    return NULL;
}

int cdl_pbrt_texture_ref(cdl_pbrt_ctx *c, const cdl_pbrt_param *p, int is_float, const cdl_pbrt_tex **out)
{
    if (p->n != 1)
        return cdl_pbrt_error(c, p->line, "parameter \"texture %s\" expects one texture name", p->name);
    const char *name = cdl_pbrt_str(&c->ps, p, 0);
    /* pbrt looks in the table of the parameter's type; a float texture
     * where a spectrum is expected (or back) is taken as a grey */
    const cdl_pbrt_tex *t = find_tex(c, name, is_float);
    *out = t ? t : find_tex(c, name, !is_float);
    if (!*out)
        return cdl_pbrt_error(c, p->line, "texture \"%s\" (for \"%s\") is not defined", name, p->name);
    return 0;
}

/* An operand of a checkerboard, scale or mix: a texture reference (*sub,
 * or its constant) or a value of the operand's type. */
static int operand(cdl_pbrt_ctx *c, const char *pname, int is_float, cdl_vec3 def, int *sub, cdl_vec3 *value)
{
    cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, pname);
    *sub = -1;
    *value = def;
    if (!p)
        return 0;
    if (p->type == CDL_PT_TEXTURE) {
        const cdl_pbrt_tex *t;
        int rc = cdl_pbrt_texture_ref(c, p, is_float, &t);
        if (rc)
            return rc;
        *value = t->value; /* an unsupported class: the grey its definition warned of */
        if (t->kind == CDL_PBRT_TEX_SCENE)
            *sub = t->tex_id;
        return 0;
    }
    if (is_float) {
        if (p->type != CDL_PT_FLOAT && p->type != CDL_PT_INT)
            return cdl_pbrt_error(c, p->line, "parameter \"%s %s\" should be a float or a float texture", p->tname,
                                  p->name);
        if (p->n != 1)
            return cdl_pbrt_error(c, p->line, "parameter \"%s %s\" expects one value, got %zu", p->tname, p->name,
                                  p->n);
        float f = (float)cdl_pbrt_nums(&c->ps, p)[0];
        *value = cdl_v3(f, f, f);
        return 0;
    }
    return cdl_pbrt_param_spectrum(&c->ps, p, value, c->err);
}

static int add_texture(cdl_pbrt_ctx *c, cdl_texture *t, int *id)
{
    return cdl_pbrt_scene_rc(c, cdl_scene_add_texture_data(c->s, t, id, c->err));
}

/* pbrt's "mapping": uv (the others approximated by it, with a warning)
 * and its scale and offset. */
static int uv_mapping(cdl_pbrt_ctx *c, const char *cls, const char *name, double map[4])
{
    cdl_pbrt_params *ps = &c->ps;
    const char *mapping;
    int rc;
    if ((rc = cdl_pbrt_get_string(ps, "mapping", "uv", &mapping, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "uscale", 1.0, &map[0], c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "vscale", 1.0, &map[1], c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "udelta", 0.0, &map[2], c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "vdelta", 0.0, &map[3], c->err)))
        return rc;
    for (int i = 0; i < 4; i++)
        if (!(fabs(map[i]) <= MAX_UV_MAP))
            return cdl_pbrt_error(c, c->line, "%s \"%s\": uscale/vscale/udelta/vdelta %g out of range (|x| <= 1e6)",
                                  cls, name, map[i]);
    if (!strcmp(mapping, "spherical") || !strcmp(mapping, "cylindrical") || !strcmp(mapping, "planar")) {
        cdl_pbrt_warn(c, c->line, "%s \"%s\": mapping \"%s\" approximated by \"uv\"", cls, name, mapping);
        cdl_pbrt_find(ps, "v1");
        cdl_pbrt_find(ps, "v2");
    } else if (strcmp(mapping, "uv")) {
        return cdl_pbrt_error(c, c->line, "%s \"%s\": mapping \"%s\" must be uv, spherical, cylindrical or planar",
                              cls, name, mapping);
    }
    return 0;
}

/* ---- imagemap ---- */

enum { DECODE_LINEAR, DECODE_SRGB, DECODE_GAMMA };
/* what a texel becomes: the colour, or a float texture's value (pbrt-v3:
 * the luminance y() of the file's values, then decoded; pbrt-v4: the
 * first channel, decoded) */
enum { TEXEL_RGB, TEXEL_V3_Y, TEXEL_V4_R };

static float decode(float x, int mode, float g)
{
    if (mode == DECODE_SRGB) /* pbrt's InverseGammaCorrect, v4's sRGB encoding */
        return x <= 0.04045f ? x * (1.0f / 12.92f) : powf((x + 0.055f) * (1.0f / 1.055f), 2.4f);
    if (mode == DECODE_GAMMA)
        return x > 0.0f ? powf(x, g) : 0.0f;
    return x;
}

/* The cache key of an image texture: everything its texels and lookup
 * depend on (one copy per distinct use of a file). */
static void image_key(char *key, size_t n, const char *path, int texel, int dec, float g, float sc, int inv, int wrap,
                      const double map[4])
{
    snprintf(key, n, "%s|%d|%d|%a|%a|%d|%d|%a|%a|%a|%a", path, texel, dec, (double)g, (double)sc, inv, wrap, map[0],
             map[1], map[2], map[3]);
}

static int cache_find(const cdl_pbrt_ctx *c, const char *key)
{
    for (int i = 0; i < c->nimgs; i++)
        if (!strcmp(c->imgs[i].key, key))
            return i;
    return -1;
}

static int cache_add(cdl_pbrt_ctx *c, const char *key, int tex_id, cdl_vec3 mean)
{
    if (c->nimgs == c->capimgs) {
        int cap = c->capimgs ? 2 * c->capimgs : 8;
        cdl_pbrt_image *p = realloc(c->imgs, sizeof *p * (size_t)cap);
        if (!p)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        c->imgs = p;
        c->capimgs = cap;
    }
    if (!(c->imgs[c->nimgs].key = strdup(key)))
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
    c->imgs[c->nimgs].tex_id = tex_id;
    c->imgs[c->nimgs++].mean = mean;
    return 0;
}

/* Loads path undecoded (8-bit values / 255, float images as stored). */
static int load_raw(cdl_pbrt_ctx *c, const char *path, cdl_texture *t)
{
    int rc = cdl_texture_load_image(t, path, 1, c->err);
    if (rc) { /* name the directive; the image's own message follows */
        cdl_error sub = *c->err;
        cdl_texture_free(t);
        return cdl_error_set(c->err, sub.code, c->file, c->line, "texture \"%s\": %s", path, sub.msg);
    }
    return 0;
}

/* The texels as pbrt evaluates them: decoded, reduced to a float
 * texture's value, times scale, inverted (v4: max(0, 1 - v), here per
 * texel, which differs from pbrt's only where scale * v > 1). */
static int convert_texels(cdl_pbrt_ctx *c, cdl_texture *t, int texel, int dec, float g, float sc, int inv,
                          cdl_vec3 *mean)
{
    double sum[3] = {0.0, 0.0, 0.0};
    size_t n = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < n; i++) {
        float *p = t->rgb + 3 * i, v[3];
        if (texel == TEXEL_RGB) {
            for (int k = 0; k < 3; k++)
                v[k] = decode(p[k], dec, g);
        } else {
            float f = texel == TEXEL_V3_Y ? decode(cdl_tex_luminance(cdl_v3(p[0], p[1], p[2])), dec, g)
                                          : decode(p[0], dec, g);
            v[0] = v[1] = v[2] = f;
        }
        for (int k = 0; k < 3; k++) {
            v[k] *= sc;
            if (inv)
                v[k] = fmaxf(0.0f, 1.0f - v[k]);
            if (!isfinite(v[k]))
                return cdl_pbrt_error(c, c->line, "imagemap: texel %zu times scale %g is not finite", i, (double)sc);
            p[k] = v[k];
            sum[k] += v[k];
        }
    }
    *mean = cdl_v3((float)(sum[0] / (double)n), (float)(sum[1] / (double)n), (float)(sum[2] / (double)n));
    return 0;
}

static int image_texture(cdl_pbrt_ctx *c, cdl_pbrt_tex *t)
{
    cdl_pbrt_params *ps = &c->ps;
    const char *fn, *wrap, *enc = NULL;
    double sc, map[4];
    int inv, gamma = -1, rc;
    cdl_pbrt_param *pg = cdl_pbrt_find(ps, "gamma");
    if ((rc = cdl_pbrt_get_string(ps, "filename", NULL, &fn, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "scale", 1.0, &sc, c->err)) ||
        (rc = cdl_pbrt_get_bool(ps, "invert", 0, &inv, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "wrap", "repeat", &wrap, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "encoding", NULL, &enc, c->err)) ||
        (pg && (rc = cdl_pbrt_get_bool(ps, "gamma", 1, &gamma, c->err))) ||
        (rc = uv_mapping(c, "imagemap", t->name, map)))
        return rc;
    if (!fn)
        return cdl_pbrt_error(c, c->line, "imagemap texture \"%s\" needs \"string filename\"", t->name);
    /* pbrt-v4's texture filtering over the pixel footprint (and v3's
     * MIP-mapping) is not done: the image is looked up bilinearly */
    int v4 = enc != NULL || cdl_pbrt_find(ps, "invert") != NULL || cdl_pbrt_find(ps, "filter") != NULL;
    cdl_pbrt_find(ps, "filter");
    cdl_pbrt_find(ps, "maxanisotropy");
    cdl_pbrt_find(ps, "trilinear");
    int w;
    if (!strcmp(wrap, "repeat"))
        w = CDL_WRAP_REPEAT;
    else if (!strcmp(wrap, "clamp"))
        w = CDL_WRAP_CLAMP;
    else if (!strcmp(wrap, "black"))
        w = CDL_WRAP_BLACK;
    else if (!strcmp(wrap, "mirror")) {
        cdl_pbrt_warn(c, c->line, "imagemap \"%s\": wrap \"mirror\" is not pbrt's (v3 repeats, v4 rejects it): "
                                  "mirrored", t->name);
        w = CDL_WRAP_MIRROR;
    } else if (!strcmp(wrap, "octahedralsphere")) {
        cdl_pbrt_warn(c, c->line, "imagemap \"%s\": wrap \"octahedralsphere\" approximated by \"clamp\"", t->name);
        w = CDL_WRAP_CLAMP;
    } else {
        return cdl_pbrt_error(c, c->line, "imagemap \"%s\": wrap \"%s\" must be repeat, clamp or black", t->name,
                              wrap);
    }
    char path[1024];
    cdl_pbrt_resolve(c, fn, path, sizeof path);
    if ((rc = cdl_pbrt_check_file(c, "texture file", path)))
        return rc;
    /* 8-bit values: v4's encoding, else v3's gamma, else sRGB (both
     * versions' default for PNG and TGA); float images stay linear unless
     * v3's gamma says otherwise (v4 ignores the encoding there) */
    int is8 = !cdl_image_has_ext(path, ".exr") && !cdl_image_has_ext(path, ".pfm");
    int dec = is8 ? DECODE_SRGB : DECODE_LINEAR;
    float g = 1.0f;
    if (enc && !strcmp(enc, "linear"))
        dec = DECODE_LINEAR;
    else if (enc && !strcmp(enc, "sRGB"))
        dec = is8 ? DECODE_SRGB : DECODE_LINEAR;
    else if (enc) {
        double gv = 0.0;
        char extra;
        if (sscanf(enc, "gamma %lf %c", &gv, &extra) != 1 || !(gv > 0.0 && gv < 100.0))
            return cdl_pbrt_error(c, c->line, "imagemap \"%s\": encoding \"%s\" must be linear, sRGB or \"gamma g\"",
                                  t->name, enc);
        dec = is8 ? DECODE_GAMMA : DECODE_LINEAR;
        g = (float)gv;
    } else if (gamma >= 0) {
        dec = gamma ? DECODE_SRGB : DECODE_LINEAR;
    }
    int texel = !t->is_float ? TEXEL_RGB : v4 ? TEXEL_V4_R : TEXEL_V3_Y;
    char key[1400];
    image_key(key, sizeof key, path, texel, dec, g, (float)sc, inv, w, map);
    t->kind = CDL_PBRT_TEX_SCENE;
    int k = cache_find(c, key);
    if (k >= 0) {
        t->tex_id = c->imgs[k].tex_id;
        t->value = c->imgs[k].mean;
        return 0;
    }
    cdl_texture tex;
    if ((rc = load_raw(c, path, &tex)))
        return rc;
    if ((rc = convert_texels(c, &tex, texel, dec, g, (float)sc, inv, &t->value))) {
        cdl_texture_free(&tex);
        return rc;
    }
    tex.wrap = w;
    /* image (s, 1 - t): pbrt-v4 flips t, pbrt-v3 flips the image */
    tex.m[0] = (float)map[0];
    tex.m[1] = 0.0f;
    tex.m[2] = (float)map[2];
    tex.m[3] = 0.0f;
    tex.m[4] = (float)-map[1];
    tex.m[5] = (float)(1.0 - map[3]);
    if ((rc = add_texture(c, &tex, &t->tex_id)))
        return rc;
    return cache_add(c, key, t->tex_id, t->value);
}

int cdl_pbrt_normal_map(cdl_pbrt_ctx *c, const cdl_pbrt_param *p, int *tex)
{
    if (p->type != CDL_PT_STRING || p->n != 1)
        return cdl_pbrt_error(c, p->line, "parameter \"%s %s\" should be one string (an image file)", p->tname,
                              p->name);
    char path[1024], key[1100];
    cdl_pbrt_resolve(c, cdl_pbrt_str(&c->ps, p, 0), path, sizeof path);
    int rc = cdl_pbrt_check_file(c, "normal map", path);
    if (rc)
        return rc;
    snprintf(key, sizeof key, "%s|normalmap", path);
    int k = cache_find(c, key);
    if (k >= 0) {
        *tex = c->imgs[k].tex_id;
        return 0;
    }
    /* pbrt-v4 reads it linear (8-bit values / 255), repeats it and looks
     * it up bilinearly at (u, 1 - v): the image defaults of texture.h */
    cdl_texture t;
    if ((rc = load_raw(c, path, &t)) || (rc = add_texture(c, &t, tex)))
        return rc;
    return cache_add(c, key, *tex, cdl_v3(0.5f, 0.5f, 1.0f));
}

/* ---- checkerboard, scale, mix ---- */

static int checkerboard(cdl_pbrt_ctx *c, cdl_pbrt_tex *t)
{
    int dim, rc;
    double map[4];
    cdl_texture tex;
    cdl_texture_init(&tex, CDL_TEX_CHECKER);
    if ((rc = cdl_pbrt_get_int(&c->ps, "dimension", 2, &dim, c->err)))
        return rc;
    if (dim != 2 && dim != 3)
        return cdl_pbrt_error(c, c->line, "checkerboard \"%s\": dimension %d must be 2 or 3", t->name, dim);
    /* pbrt's defaults: tex1 1, tex2 0 */
    if ((rc = operand(c, "tex1", t->is_float, cdl_v3(1, 1, 1), &tex.sub[0], &tex.a)) ||
        (rc = operand(c, "tex2", t->is_float, cdl_v3(0, 0, 0), &tex.sub[1], &tex.b)))
        return rc;
    /* v3's closed-form antialiasing (v4 always filters) over the pixel
     * footprint is not done: the cells are point-sampled */
    cdl_pbrt_find(&c->ps, "aamode");
    t->value = cdl_scale(cdl_add(tex.a, tex.b), 0.5f);
    if (dim == 3) {
        cdl_pbrt_warn(c, c->line, "3D checkerboard \"%s\" approximated by the mean of tex1 and tex2", t->name);
        t->kind = CDL_PBRT_TEX_OTHER;
        for (size_t i = 0; i < c->ps.n; i++)
            c->ps.p[i].used = 1;
        return 0;
    }
    if ((rc = uv_mapping(c, "checkerboard", t->name, map)))
        return rc;
    /* pbrt's cells of (s, t) = (su u + du, sv v + dv), t not flipped */
    tex.unit_cells = 1;
    tex.m[0] = (float)map[0];
    tex.m[1] = 0.0f;
    tex.m[2] = (float)map[2];
    tex.m[3] = 0.0f;
    tex.m[4] = (float)map[1];
    tex.m[5] = (float)map[3];
    if (tex.sub[0] < 0 && tex.sub[1] < 0 && tex.a.x == tex.b.x && tex.a.y == tex.b.y && tex.a.z == tex.b.z) {
        t->kind = CDL_PBRT_TEX_CONST; /* one colour in every cell */
        return 0;
    }
    t->kind = CDL_PBRT_TEX_SCENE;
    return add_texture(c, &tex, &t->tex_id);
}

/* v3: tex1 * tex2; v4: tex * scale (a float, also for spectra). */
static int scale_texture(cdl_pbrt_ctx *c, cdl_pbrt_tex *t)
{
    cdl_texture tex;
    cdl_texture_init(&tex, CDL_TEX_SCALE);
    int v4 = cdl_pbrt_find(&c->ps, "tex") || cdl_pbrt_find(&c->ps, "scale"), rc;
    if ((rc = operand(c, v4 ? "tex" : "tex1", t->is_float, cdl_v3(1, 1, 1), &tex.sub[0], &tex.a)) ||
        (rc = operand(c, v4 ? "scale" : "tex2", v4 || t->is_float, cdl_v3(1, 1, 1), &tex.sub[1], &tex.b)))
        return rc;
    t->value = cdl_mul(tex.a, tex.b);
    if (tex.sub[0] < 0 && tex.sub[1] < 0) {
        t->kind = CDL_PBRT_TEX_CONST;
        return 0;
    }
    t->kind = CDL_PBRT_TEX_SCENE;
    return add_texture(c, &tex, &t->tex_id);
}

/* (1 - amount) tex1 + amount tex2 (pbrt's defaults 0, 1, 0.5). */
static int mix_texture(cdl_pbrt_ctx *c, cdl_pbrt_tex *t)
{
    cdl_texture tex;
    cdl_texture_init(&tex, CDL_TEX_MIX);
    cdl_vec3 amt;
    int rc;
    if ((rc = operand(c, "tex1", t->is_float, cdl_v3(0, 0, 0), &tex.sub[0], &tex.a)) ||
        (rc = operand(c, "tex2", t->is_float, cdl_v3(1, 1, 1), &tex.sub[1], &tex.b)) ||
        (rc = operand(c, "amount", 1, cdl_v3(0.5f, 0.5f, 0.5f), &tex.amount_tex, &amt)))
        return rc;
    tex.amount = amt.x;
    t->value = cdl_add(cdl_scale(tex.a, 1.0f - amt.x), cdl_scale(tex.b, amt.x));
    if (tex.sub[0] < 0 && tex.sub[1] < 0 && tex.amount_tex < 0) {
        t->kind = CDL_PBRT_TEX_CONST;
        return 0;
    }
    t->kind = CDL_PBRT_TEX_SCENE;
    return add_texture(c, &tex, &t->tex_id);
}

int cdl_pbrt_texture(cdl_pbrt_ctx *c, const char *name, const char *type, const char *cls)
{
    cdl_pbrt_tex t;
    memset(&t, 0, sizeof t);
    t.tex_id = -1;
    int rc = 0;
    if (!strcmp(type, "float"))
        t.is_float = 1;
    else if (strcmp(type, "spectrum") && strcmp(type, "color") && strcmp(type, "rgb"))
        return cdl_pbrt_error(c, c->line, "Texture \"%s\": type \"%s\" must be \"float\" or \"spectrum\"", name,
                              type);
    if (!(t.name = strdup(name)))
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
    if (!strcmp(cls, "imagemap")) {
        rc = image_texture(c, &t);
    } else if (!strcmp(cls, "constant")) {
        double f;
        t.kind = CDL_PBRT_TEX_CONST;
        if (t.is_float) {
            rc = cdl_pbrt_get_float(&c->ps, "value", 1.0, &f, c->err);
            t.value = cdl_v3((float)f, (float)f, (float)f);
        } else {
            rc = cdl_pbrt_get_spectrum(&c->ps, "value", cdl_v3(1, 1, 1), &t.value, NULL, c->err);
        }
    } else if (!strcmp(cls, "checkerboard")) {
        rc = checkerboard(c, &t);
    } else if (!strcmp(cls, "scale")) {
        rc = scale_texture(c, &t);
    } else if (!strcmp(cls, "mix")) {
        rc = mix_texture(c, &t);
    } else {
        cdl_pbrt_warn(c, c->line, "texture class \"%s\" is not supported: \"%s\" is grey 0.5", cls, name);
        t.kind = CDL_PBRT_TEX_OTHER;
        t.value = cdl_v3(0.5f, 0.5f, 0.5f);
        for (size_t i = 0; i < c->ps.n; i++)
            c->ps.p[i].used = 1;
    }
    if (!rc && c->ntexs == c->captexs) {
        int cap = c->captexs ? 2 * c->captexs : 16;
        cdl_pbrt_tex *p = realloc(c->texs, sizeof *p * (size_t)cap);
        if (!p)
            rc = cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        else {
            c->texs = p;
            c->captexs = cap;
        }
    }
    if (rc) {
        free(t.name);
        return rc;
    }
    c->texs[c->ntexs++] = t;
    return 0;
}

void cdl_pbrt_textures_free(cdl_pbrt_ctx *c)
{
    for (int i = 0; i < c->ntexs; i++)
        free(c->texs[i].name);
    free(c->texs);
    for (int i = 0; i < c->nimgs; i++)
        free(c->imgs[i].key);
    free(c->imgs);
}
