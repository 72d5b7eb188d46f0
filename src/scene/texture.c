#include "scene/texture.h"

#include <math.h>
#include <stb_image.h>
#include <stdlib.h>

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

int cdl_texture_load(cdl_texture *t, const char *path, cdl_error *err)
{
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
        lut[i] = srgb_to_linear((float)i / 255.0f);
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

cdl_vec3 cdl_texture_lookup(const cdl_texture *t, float u, float v)
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
