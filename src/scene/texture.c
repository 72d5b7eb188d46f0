#include "scene/texture.h"

#include <math.h>
#include <stb_image.h>
#include <stdlib.h>
#include <string.h>

#include "film/image.h"

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

void cdl_texture_init(cdl_texture *t, cdl_tex_type type)
{
    memset(t, 0, sizeof *t);
    t->type = type;
    t->wrap = CDL_WRAP_REPEAT;
    /* (s, t) = (u, 1 - v) */
    t->m[0] = 1.0f;
    t->m[4] = -1.0f;
    t->m[5] = 1.0f;
    t->a = t->b = cdl_v3(1.0f, 1.0f, 1.0f);
    t->sub[0] = t->sub[1] = -1;
    t->scale = 1.0f;
    t->attr_key = -1;
    t->amount_tex = -1;
    t->amount = 0.5f;
}

int cdl_texture_load_image(cdl_texture *t, const char *path, int raw, cdl_error *err)
{
    cdl_texture_init(t, CDL_TEX_BITMAP);
    if (cdl_image_has_ext(path, ".exr") || cdl_image_has_ext(path, ".pfm")) {
        /* linear float images: never sRGB decoded */
        cdl_image img;
        int rc = cdl_image_read(path, &img, err);
        if (rc)
            return rc;
        t->w = img.width;
        t->h = img.height;
        t->rgb = img.rgb;
        return 0;
    }
    int rc = cdl_image_check_stb(path, err);
    if (rc)
        return rc;
    int w, h, n;
    unsigned char *px = stbi_load(path, &w, &h, &n, 3);
    if (!px)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot read texture: %s",
                             stbi_failure_reason());
    if (w <= 0 || h <= 0 || (size_t)w * (size_t)h > ((size_t)1 << 28)) {
        stbi_image_free(px);
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "texture size %dx%d out of range", w, h);
    }
    float lut[256];
    for (int i = 0; i < 256; i++)
        lut[i] = raw ? (float)i / 255.0f : srgb_to_linear((float)i / 255.0f);
    t->rgb = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    if (!t->rgb) {
        stbi_image_free(px);
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    }
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++)
        t->rgb[i] = lut[px[i]];
    stbi_image_free(px);
    t->w = w;
    t->h = h;
    return 0;
}

int cdl_texture_load(cdl_texture *t, const char *path, cdl_error *err)
{
    if (cdl_image_has_ext(path, ".exr") || cdl_image_has_ext(path, ".pfm"))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot read texture: not an 8-bit image");
    int rc = cdl_texture_load_image(t, path, 0, err);
    t->legacy = 1;
    return rc;
}

void cdl_texture_free(cdl_texture *t)
{
    free(t->rgb);
    t->rgb = NULL;
}

static cdl_vec3 texel(const cdl_texture *t, int x, int y)
{
    x %= t->w;
    y %= t->h;
    if (x < 0)
        x += t->w;
    if (y < 0)
        y += t->h;
    const float *p = t->rgb + 3 * ((size_t)y * (size_t)t->w + (size_t)x);
    return cdl_v3(p[0], p[1], p[2]);
}

/* The OBJ/pbrt readers' original lookup: bilinear, repeating; (u,v) as in
 * OBJ: v = 0 is the bottom row. */
static cdl_vec3 legacy_lookup(const cdl_texture *t, float u, float v)
{
    if (!isfinite(u) || !isfinite(v))
        return texel(t, 0, 0);
    float x = (u - floorf(u)) * (float)t->w - 0.5f;
    float y = (1.0f - (v - floorf(v))) * (float)t->h - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    float ax = x - fx, ay = y - fy;
    int ix = (int)fx, iy = (int)fy;
    cdl_vec3 a = cdl_add(cdl_scale(texel(t, ix, iy), 1.0f - ax), cdl_scale(texel(t, ix + 1, iy), ax));
    cdl_vec3 b = cdl_add(cdl_scale(texel(t, ix, iy + 1), 1.0f - ax), cdl_scale(texel(t, ix + 1, iy + 1), ax));
    return cdl_add(cdl_scale(a, 1.0f - ay), cdl_scale(b, ay));
}

/* An integer texel index brought into [0, n) as Dr.Jit's textures do:
 * repeat, mirror (0 1 .. n-1 n-1 .. 0 0 1 ..) or clamp (black: the
 * caller has taken the texels outside). */
static int wrap_index(int i, int n, int mode)
{
    if (mode == CDL_WRAP_CLAMP || mode == CDL_WRAP_BLACK)
        return i < 0 ? 0 : (i >= n ? n - 1 : i);
    if (mode == CDL_WRAP_MIRROR) {
        int p = i % (2 * n);
        if (p < 0)
            p += 2 * n;
        return p < n ? p : 2 * n - 1 - p;
    }
    int p = i % n;
    return p < 0 ? p + n : p;
}

static cdl_vec3 pixel(const cdl_texture *t, int x, int y)
{
    if (t->wrap == CDL_WRAP_BLACK && (x < 0 || x >= t->w || y < 0 || y >= t->h))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    x = wrap_index(x, t->w, t->wrap);
    y = wrap_index(y, t->h, t->wrap);
    const float *p = t->rgb + 3 * ((size_t)y * (size_t)t->w + (size_t)x);
    return cdl_v3(p[0], p[1], p[2]);
}

/* Image coordinates of surface (u, v); the texel index range stays far
 * from int overflow. */
static void image_st(const cdl_texture *t, float u, float v, float *s, float *tt)
{
    *s = t->m[0] * u + t->m[1] * v + t->m[2];
    *tt = t->m[3] * u + t->m[4] * v + t->m[5];
    if (!isfinite(*s) || fabsf(*s) > 1e6f)
        *s = 0.0f;
    if (!isfinite(*tt) || fabsf(*tt) > 1e6f)
        *tt = 0.0f;
}

/* The four texels around (s, t) and the bilinear weights of the far ones
 * (texel centres at (i + 0.5) / w). */
static void bilinear_fetch(const cdl_texture *t, float s, float tt, cdl_vec3 f[4], float *wx, float *wy)
{
    float x = s * (float)t->w - 0.5f, y = tt * (float)t->h - 0.5f;
    float fx = floorf(x), fy = floorf(y);
    int ix = (int)fx, iy = (int)fy;
    *wx = x - fx;
    *wy = y - fy;
    f[0] = pixel(t, ix, iy);
    f[1] = pixel(t, ix + 1, iy);
    f[2] = pixel(t, ix, iy + 1);
    f[3] = pixel(t, ix + 1, iy + 1);
}

static cdl_vec3 bitmap_eval(const cdl_texture *t, float u, float v)
{
    if (t->legacy)
        return legacy_lookup(t, u, v);
    float s, tt;
    image_st(t, u, v, &s, &tt);
    if (t->nearest)
        return pixel(t, (int)floorf(s * (float)t->w), (int)floorf(tt * (float)t->h));
    cdl_vec3 f[4];
    float wx, wy;
    bilinear_fetch(t, s, tt, f, &wx, &wy);
    cdl_vec3 a = cdl_add(cdl_scale(f[0], 1.0f - wx), cdl_scale(f[1], wx));
    cdl_vec3 b = cdl_add(cdl_scale(f[2], 1.0f - wx), cdl_scale(f[3], wx));
    return cdl_add(cdl_scale(a, 1.0f - wy), cdl_scale(b, wy));
}

/* Whether a checkerboard shows a (else b) at (u, v). Mitsuba's: the
 * parity of the half cells of to_uv(uv), its color lookup taking color0
 * where both halves agree, its scalar lookup (the legacy convention
 * Mitsuba keeps) where they differ. pbrt's (unit_cells): tex1 where
 * floor(s) + floor(t) is even, for both (its negative cells too: C++'s
 * -1 % 2 is -1, not 0). */
static int checker_first(const cdl_texture *t, float u, float v, int scalar)
{
    float s = t->m[0] * u + t->m[1] * v + t->m[2];
    float tt = t->m[3] * u + t->m[4] * v + t->m[5];
    if (t->unit_cells) {
        if (!isfinite(s) || !isfinite(tt))
            return 1;
        /* the parity of the sum, exact while the cells are integers in float */
        float h = 0.5f * (floorf(s) + floorf(tt));
        return h == floorf(h);
    }
    int mx = s - floorf(s) > 0.5f, my = tt - floorf(tt) > 0.5f;
    return scalar ? mx != my : mx == my;
}

#define MAX_TEX_DEPTH 8

/* The scalar of a constant operand: exact for a grey (a pbrt float). */
static float scalar_of(cdl_vec3 c)
{
    return c.x == c.y && c.y == c.z ? c.x : cdl_tex_luminance(c);
}

/* A checker's constant as a scalar: Mitsuba's luminance, pbrt's float. */
static float checker_const1(const cdl_texture *t, int k)
{
    cdl_vec3 c = k == 0 ? t->a : t->b;
    return t->unit_cells ? scalar_of(c) : cdl_tex_luminance(c);
}

static cdl_vec3 eval_depth(const cdl_texture *texs, int i, float u, float v, int depth);
static float eval1_depth(const cdl_texture *texs, int i, float u, float v, int depth);

/* Operand k of a checker, scale or mix: its texture or its constant. */
static cdl_vec3 operand(const cdl_texture *texs, const cdl_texture *t, int k, float u, float v, int depth)
{
    if (t->sub[k] >= 0 && depth < MAX_TEX_DEPTH)
        return eval_depth(texs, t->sub[k], u, v, depth + 1);
    return k == 0 ? t->a : t->b;
}

static float operand1(const cdl_texture *texs, const cdl_texture *t, int k, float u, float v, int depth)
{
    if (t->sub[k] >= 0 && depth < MAX_TEX_DEPTH)
        return eval1_depth(texs, t->sub[k], u, v, depth + 1);
    return scalar_of(k == 0 ? t->a : t->b);
}

static float mix_amount(const cdl_texture *texs, const cdl_texture *t, float u, float v, int depth)
{
    if (t->amount_tex >= 0 && depth < MAX_TEX_DEPTH)
        return eval1_depth(texs, t->amount_tex, u, v, depth + 1);
    return t->amount;
}

static cdl_vec3 eval_depth(const cdl_texture *texs, int i, float u, float v, int depth)
{
    const cdl_texture *t = &texs[i];
    switch (t->type) {
    case CDL_TEX_BITMAP:
        return bitmap_eval(t, u, v);
    case CDL_TEX_CHECKER:
        return operand(texs, t, checker_first(t, u, v, 0) ? 0 : 1, u, v, depth);
    case CDL_TEX_SCALE: {
        cdl_vec3 c = t->sub[0] >= 0 && depth < MAX_TEX_DEPTH ? eval_depth(texs, t->sub[0], u, v, depth + 1) : t->a;
        if (t->sub[1] >= 0 || t->b.x != 1.0f || t->b.y != 1.0f || t->b.z != 1.0f)
            c = cdl_mul(c, operand(texs, t, 1, u, v, depth));
        return cdl_scale(c, t->scale);
    }
    case CDL_TEX_MIX: {
        float w = mix_amount(texs, t, u, v, depth);
        return cdl_add(cdl_scale(operand(texs, t, 0, u, v, depth), 1.0f - w),
                       cdl_scale(operand(texs, t, 1, u, v, depth), w));
    }
    default:
        return t->a;
    }
}

static float eval1_depth(const cdl_texture *texs, int i, float u, float v, int depth)
{
    const cdl_texture *t = &texs[i];
    if (t->type == CDL_TEX_CHECKER) {
        int k = checker_first(t, u, v, 1) ? 0 : 1;
        if (t->sub[k] >= 0 && depth < MAX_TEX_DEPTH)
            return eval1_depth(texs, t->sub[k], u, v, depth + 1);
        return checker_const1(t, k);
    }
    if (t->type == CDL_TEX_SCALE && t->sub[1] >= 0)
        return t->scale * operand1(texs, t, 0, u, v, depth) * operand1(texs, t, 1, u, v, depth);
    if (t->type == CDL_TEX_SCALE && t->sub[0] >= 0 && depth < MAX_TEX_DEPTH)
        return t->scale * scalar_of(t->b) * eval1_depth(texs, t->sub[0], u, v, depth + 1);
    if (t->type == CDL_TEX_MIX) {
        float w = mix_amount(texs, t, u, v, depth);
        return (1.0f - w) * operand1(texs, t, 0, u, v, depth) + w * operand1(texs, t, 1, u, v, depth);
    }
    return cdl_tex_luminance(eval_depth(texs, i, u, v, depth));
}

cdl_vec3 cdl_texture_eval(const cdl_texture *texs, int i, float u, float v)
{
    return eval_depth(texs, i, u, v, 0);
}

float cdl_texture_eval1(const cdl_texture *texs, int i, float u, float v)
{
    return eval1_depth(texs, i, u, v, 0);
}

/* Mitsuba's eval_1_grad of a bilinear bitmap: the derivative of the
 * interpolant over the image coordinates, taken back to (u, v) through
 * the uv map (its transpose). */
static void bitmap_grad1(const cdl_texture *t, float u, float v, float grad[2])
{
    grad[0] = grad[1] = 0.0f;
    if (t->nearest)
        return;
    const float *m = t->m;
    float s, tt;
    image_st(t, u, v, &s, &tt);
    cdl_vec3 f[4];
    float wx, wy;
    bilinear_fetch(t, s, tt, f, &wx, &wy);
    float f00 = cdl_tex_luminance(f[0]), f10 = cdl_tex_luminance(f[1]), f01 = cdl_tex_luminance(f[2]),
          f11 = cdl_tex_luminance(f[3]);
    /* per unit of s and t */
    float ds = (float)t->w * ((1.0f - wy) * (f10 - f00) + wy * (f11 - f01));
    float dt = (float)t->h * ((1.0f - wx) * (f01 - f00) + wx * (f11 - f10));
    grad[0] = m[0] * ds + m[3] * dt;
    grad[1] = m[1] * ds + m[4] * dt;
}

/* The scalar value of texture i and its gradient: bitmaps by their
 * interpolant, products and mixes by the product rule, a checker by the
 * operand it shows (its cell edges have no derivative); constants add 0. */
static float grad1_depth(const cdl_texture *texs, int i, float u, float v, int depth, float g[2])
{
    const cdl_texture *t = &texs[i];
    g[0] = g[1] = 0.0f;
    if (depth >= MAX_TEX_DEPTH)
        return eval1_depth(texs, i, u, v, depth);
    switch (t->type) {
    case CDL_TEX_BITMAP:
        bitmap_grad1(t, u, v, g);
        return eval1_depth(texs, i, u, v, depth);
    case CDL_TEX_CHECKER: {
        int k = checker_first(t, u, v, 1) ? 0 : 1;
        if (t->sub[k] >= 0)
            return grad1_depth(texs, t->sub[k], u, v, depth + 1, g);
        return checker_const1(t, k);
    }
    case CDL_TEX_SCALE:
    case CDL_TEX_MIX: {
        float f[2], gk[2][2] = {{0.0f, 0.0f}, {0.0f, 0.0f}};
        for (int k = 0; k < 2; k++)
            f[k] = t->sub[k] >= 0 ? grad1_depth(texs, t->sub[k], u, v, depth + 1, gk[k]) : scalar_of(k ? t->b : t->a);
        if (t->type == CDL_TEX_SCALE) {
            for (int d = 0; d < 2; d++)
                g[d] = t->scale * (gk[0][d] * f[1] + f[0] * gk[1][d]);
            return t->scale * f[0] * f[1];
        }
        float gw[2] = {0.0f, 0.0f}, w = t->amount;
        if (t->amount_tex >= 0)
            w = grad1_depth(texs, t->amount_tex, u, v, depth + 1, gw);
        for (int d = 0; d < 2; d++)
            g[d] = (1.0f - w) * gk[0][d] + w * gk[1][d] + (f[1] - f[0]) * gw[d];
        return (1.0f - w) * f[0] + w * f[1];
    }
    default:
        return eval1_depth(texs, i, u, v, depth);
    }
}

void cdl_texture_grad1(const cdl_texture *texs, int i, float u, float v, float grad[2])
{
    grad1_depth(texs, i, u, v, 0, grad);
}
