#include "scene/envmap.h"

#include <math.h>
#include <stb_image.h>
#include <stdlib.h>
#include <string.h>

#include "film/image.h"

static float clampf(float x, float lo, float hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

void cdl_envmap_free(cdl_envmap *m)
{
    free(m->rgb);
    free(m->func);
    free(m->cdf_row);
    free(m->cdf_col);
    memset(m, 0, sizeof *m);
}

/* Running sums of f[0..n) into cdf[0..n], normalized to end at 1; returns
 * the sum (a zero sum gives a uniform cdf). */
static double build_cdf(const float *f, int n, float *cdf)
{
    double sum = 0.0;
    cdf[0] = 0.0f;
    for (int i = 0; i < n; i++) {
        sum += f[i];
        cdf[i + 1] = (float)sum;
    }
    for (int i = 1; i <= n; i++)
        cdf[i] = sum > 0.0 ? (float)(cdf[i] / sum) : (float)i / (float)n;
    cdf[n] = 1.0f;
    return sum;
}

/* The index i with cdf[i] <= u < cdf[i + 1], skipping empty bins. */
static int find(const float *cdf, int n, float u)
{
    int lo = 0, hi = n;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    while (lo < n - 1 && !(cdf[lo + 1] > cdf[lo]))
        lo++;
    return lo;
}

cdl_vec3 cdl_equal_area_square_to_sphere(float pu, float pv)
{
    float u = 2.0f * pu - 1.0f, v = 2.0f * pv - 1.0f, up = fabsf(u), vp = fabsf(v);
    float sd = 1.0f - (up + vp), d = fabsf(sd), r = 1.0f - d;
    float phi = (r == 0.0f ? 1.0f : (vp - up) / r + 1.0f) * 0.25f * CDL_PI;
    float z = copysignf(1.0f - r * r, sd);
    float cp = copysignf(cosf(phi), u), sp = copysignf(sinf(phi), v);
    float s = r * sqrtf(fmaxf(0.0f, 2.0f - r * r));
    return cdl_v3(cp * s, sp * s, z);
}

void cdl_equal_area_sphere_to_square(cdl_vec3 d, float *pu, float *pv)
{
    float x = fabsf(d.x), y = fabsf(d.y), z = fabsf(d.z);
    float r = sqrtf(fmaxf(0.0f, 1.0f - z));
    float a = fmaxf(x, y), b = fminf(x, y);
    b = a == 0.0f ? 0.0f : b / a;
    float phi = atanf(b) * 2.0f * CDL_INV_PI;
    if (x < y)
        phi = 1.0f - phi;
    float v = phi * r, u = r - v;
    if (d.z < 0.0f) {
        float t = u;
        u = 1.0f - v;
        v = 1.0f - t;
    }
    u = copysignf(u, d.x);
    v = copysignf(v, d.y);
    *pu = 0.5f * (u + 1.0f);
    *pv = 0.5f * (v + 1.0f);
}

/* Mitsuba's interpolation cell (x, y) (nodes x, x + 1 mod w and y, y + 1):
 * the texel indices of its corners, 00 10 01 11. */
static void cell_corners(const cdl_envmap *m, int x, int y, size_t k[4])
{
    size_t x1 = x + 1 < m->w ? (size_t)x + 1 : 0, r0 = (size_t)y * (size_t)m->w, r1 = r0 + (size_t)m->w;
    k[0] = r0 + (size_t)x;
    k[1] = r0 + x1;
    k[2] = r1 + (size_t)x;
    k[3] = r1 + x1;
}

static cdl_vec3 texel_rgb(const cdl_envmap *m, size_t i)
{
    return cdl_v3(m->rgb[3 * i], m->rgb[3 * i + 1], m->rgb[3 * i + 2]);
}

/* The sampling function of grid cell (x, y) (luminance x sin(theta) at the
 * row's middle) and the cell's radiance integrated over its solid angle. */
static float grid_cell(const cdl_envmap *m, int x, int y, cdl_vec3 *flux)
{
    int rows = m->rows;
    float th0 = CDL_PI * (float)y / (float)rows, th1 = CDL_PI * (float)(y + 1) / (float)rows;
    if (m->layout == CDL_ENVMAP_EQUAL_AREA) {
        size_t i = (size_t)y * (size_t)m->w + (size_t)x;
        cdl_vec3 L = texel_rgb(m, i);
        *flux = cdl_scale(L, 4.0f * CDL_PI / (float)((size_t)m->w * (size_t)m->h));
        return cdl_maxf(cdl_luminance(L), 0.0f);
    }
    float sin_c = sinf(0.5f * (th0 + th1)), c0 = cosf(th0), c1 = cosf(th1);
    float dphi = 2.0f * CDL_PI / (float)m->cols;
    if (m->layout == CDL_ENVMAP_EQUIRECT) {
        cdl_vec3 L = texel_rgb(m, (size_t)y * (size_t)m->w + (size_t)x);
        *flux = cdl_scale(L, dphi * (c0 - c1));
        return cdl_maxf(cdl_luminance(L), 0.0f) * sin_c;
    }
    /* bilinear: each node row weighs half the cell in phi and, in theta,
     * the integral of its hat function times sin(theta) */
    size_t k[4];
    cell_corners(m, x, y, k);
    float dth = th1 - th0, i1 = (sinf(th1) - sinf(th0)) / dth - c1, i0 = (c0 - c1) - i1;
    cdl_vec3 top = cdl_add(texel_rgb(m, k[0]), texel_rgb(m, k[1]));
    cdl_vec3 bottom = cdl_add(texel_rgb(m, k[2]), texel_rgb(m, k[3]));
    *flux = cdl_scale(cdl_add(cdl_scale(top, i0), cdl_scale(bottom, i1)), 0.5f * dphi);
    float lum = 0.0f;
    for (int j = 0; j < 4; j++)
        lum += cdl_maxf(cdl_luminance(texel_rgb(m, k[j])), 0.0f);
    return 0.25f * lum * sin_c;
}

int cdl_envmap_init(cdl_envmap *m, int w, int h, float *rgb, const cdl_vec3 frame[3], int layout, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    if (layout != CDL_ENVMAP_EQUIRECT && layout != CDL_ENVMAP_EQUAL_AREA && layout != CDL_ENVMAP_MITSUBA)
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "unknown environment map layout %d", layout);
    if (layout == CDL_ENVMAP_EQUAL_AREA && w != h)
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "an equal-area environment map must be square, not %dx%d",
                             w, h);
    if (layout == CDL_ENVMAP_MITSUBA && (w < 2 || h < 3))
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "the environment map must be at least 2x3 texels, not %dx%d",
                             w, h);
    if (w < 1 || h < 1)
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "the environment map is empty (%dx%d)", w, h);
    m->w = w;
    m->h = h;
    m->layout = layout;
    m->cols = w;
    m->rows = layout == CDL_ENVMAP_MITSUBA ? h - 1 : h;
    m->rgb = rgb;
    /* an orthonormal frame from the transform's axes, keeping a mirror's
     * handedness (Mitsuba's lat-long map is pbrt's mirrored) */
    m->ez = cdl_normalize(frame[2]);
    m->ex = cdl_normalize(cdl_sub(frame[0], cdl_scale(m->ez, cdl_dot(frame[0], m->ez))));
    m->ey = cdl_cross(m->ez, m->ex);
    if (cdl_dot(m->ey, frame[1]) < 0.0f)
        m->ey = cdl_scale(m->ey, -1.0f);
    if (!cdl_is_finite3(m->ex) || !cdl_is_finite3(m->ez) || !(cdl_length(m->ex) > 0.5f)) {
        m->rgb = NULL;
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "environment map transform is degenerate");
    }
    int cols = m->cols, nrows = m->rows;
    size_t n = (size_t)cols * (size_t)nrows;
    m->func = malloc(sizeof(float) * n);
    m->cdf_row = malloc(sizeof(float) * ((size_t)nrows + 1));
    m->cdf_col = malloc(sizeof(float) * (size_t)nrows * ((size_t)cols + 1));
    float *rows = malloc(sizeof(float) * (size_t)nrows);
    if (!m->func || !m->cdf_row || !m->cdf_col || !rows) {
        free(rows);
        m->rgb = NULL;
        cdl_envmap_free(m);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a %dx%d environment map", w, h);
    }
    double total = 0.0;
    cdl_vec3 flux = cdl_v3(0.0f, 0.0f, 0.0f);
    for (int y = 0; y < nrows; y++) {
        for (int x = 0; x < cols; x++) {
            cdl_vec3 f;
            m->func[(size_t)y * (size_t)cols + (size_t)x] = grid_cell(m, x, y, &f);
            flux = cdl_add(flux, f);
        }
        rows[y] = (float)build_cdf(m->func + (size_t)y * (size_t)cols, cols,
                                   m->cdf_col + (size_t)y * ((size_t)cols + 1));
        total += rows[y];
    }
    build_cdf(rows, nrows, m->cdf_row);
    free(rows);
    m->flux = flux;
    m->mean = (float)(total / (double)n);
    return 0;
}

int cdl_envmap_load(cdl_envmap *m, const char *path, cdl_vec3 scale, const cdl_vec3 frame[3], int layout,
                    cdl_error *err)
{
    memset(m, 0, sizeof *m);
    cdl_image img = {0};
    int rc = 0;
    if (cdl_image_has_ext(path, ".hdr")) {
        rc = cdl_image_check_stb(path, err);
        if (rc)
            return rc;
        int w, h, n;
        float *px = stbi_loadf(path, &w, &h, &n, 3);
        if (!px)
            return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot read the Radiance HDR image (%s)",
                                 stbi_failure_reason());
        rc = cdl_image_alloc(&img, w, h, err);
        if (!rc)
            memcpy(img.rgb, px, sizeof(float) * 3 * (size_t)w * (size_t)h);
        stbi_image_free(px);
    } else {
        rc = cdl_image_read(path, &img, err);
    }
    if (rc) {
        if (err && !err->file[0]) /* the allocation's error names no file */
            snprintf(err->file, sizeof err->file, "%s", path);
        return rc;
    }
    size_t n = (size_t)img.width * (size_t)img.height;
    for (size_t i = 0; i < 3 * n; i++) {
        float s = i % 3 == 0 ? scale.x : i % 3 == 1 ? scale.y : scale.z;
        float v = img.rgb[i] * s;
        if (!isfinite(v) || v < 0.0f) {
            cdl_image_free(&img);
            return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                                 "texel (%zu, %zu) is negative, NaN or infinite: not a radiance", (i / 3) % (size_t)img.width,
                                 (i / 3) / (size_t)img.width);
        }
        img.rgb[i] = v;
    }
    rc = cdl_envmap_init(m, img.width, img.height, img.rgb, frame, layout, err);
    if (rc) {
        cdl_image_free(&img);
        if (err && !err->file[0])
            snprintf(err->file, sizeof err->file, "%s", path);
    }
    return rc;
}

/* (u, v) in [0,1)^2 of world direction w. */
static void to_uv(const cdl_envmap *m, cdl_vec3 w, float *u, float *v)
{
    float x = cdl_dot(w, m->ex), y = cdl_dot(w, m->ey), z = cdl_dot(w, m->ez);
    if (m->layout == CDL_ENVMAP_EQUAL_AREA) {
        cdl_equal_area_sphere_to_square(cdl_v3(x, y, z), u, v);
        return;
    }
    float th = atan2f(sqrtf(x * x + y * y), z); /* acos(z) loses the poles to rounding */
    float ph = atan2f(y, x);
    if (ph < 0.0f)
        ph += 2.0f * CDL_PI;
    *u = ph * (0.5f * CDL_INV_PI);
    *v = th * CDL_INV_PI;
}

/* The sampling-grid cell of (u, v), and the position within it in [0,1]^2
 * (Mitsuba's cells start half a texel to the right of u = 0 and wrap). */
static size_t grid_at(const cdl_envmap *m, float u, float v, float *fx, float *fy)
{
    float gx = u * (float)m->cols, gy = v * (float)m->rows;
    if (m->layout == CDL_ENVMAP_MITSUBA) {
        gx -= 0.5f;
        if (gx < 0.0f)
            gx += (float)m->cols;
    }
    int x = (int)floorf(gx), y = (int)floorf(gy);
    x = x < 0 ? 0 : x >= m->cols ? m->cols - 1 : x;
    y = y < 0 ? 0 : y >= m->rows ? m->rows - 1 : y;
    *fx = clampf(gx - (float)x, 0.0f, 1.0f);
    *fy = clampf(gy - (float)y, 0.0f, 1.0f);
    return (size_t)y * (size_t)m->cols + (size_t)x;
}

/* The radiance at position (fx, fy) of grid cell i. */
static cdl_vec3 cell_radiance(const cdl_envmap *m, size_t i, float fx, float fy)
{
    if (m->layout != CDL_ENVMAP_MITSUBA)
        return texel_rgb(m, i);
    size_t k[4];
    cell_corners(m, (int)(i % (size_t)m->cols), (int)(i / (size_t)m->cols), k);
    cdl_vec3 top = cdl_add(cdl_scale(texel_rgb(m, k[0]), 1.0f - fx), cdl_scale(texel_rgb(m, k[1]), fx));
    cdl_vec3 bottom = cdl_add(cdl_scale(texel_rgb(m, k[2]), 1.0f - fx), cdl_scale(texel_rgb(m, k[3]), fx));
    return cdl_add(cdl_scale(top, 1.0f - fy), cdl_scale(bottom, fy));
}

cdl_vec3 cdl_envmap_eval(const cdl_envmap *m, cdl_vec3 w)
{
    float u, v, fx, fy;
    to_uv(m, w, &u, &v);
    size_t i = grid_at(m, u, v, &fx, &fy);
    return cell_radiance(m, i, fx, fy);
}

float cdl_envmap_pdf(const cdl_envmap *m, cdl_vec3 w)
{
    float u, v, fx, fy;
    to_uv(m, w, &u, &v);
    size_t i = grid_at(m, u, v, &fx, &fy);
    if (m->layout == CDL_ENVMAP_EQUAL_AREA) /* the square's density over the sphere's 4 pi */
        return m->mean > 0.0f ? m->func[i] / m->mean / (4.0f * CDL_PI) : 0.0f;
    float s = sinf(v * CDL_PI);
    if (!(m->mean > 0.0f) || !(s > 0.0f))
        return 0.0f;
    return m->func[i] / m->mean / (2.0f * CDL_PI * CDL_PI * s);
}

cdl_vec3 cdl_envmap_sample(const cdl_envmap *m, float u1, float u2, cdl_vec3 *w, float *pdf)
{
    *pdf = 0.0f;
    if (!(m->mean > 0.0f))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    int y = find(m->cdf_row, m->rows, u2);
    const float *cc = m->cdf_col + (size_t)y * ((size_t)m->cols + 1);
    int x = find(cc, m->cols, u1);
    /* the position within the cell, by the remainders of u1 and u2, kept
     * off the cell's edges (a 2e-4 share of it), where rounding would put
     * the direction into the neighbour */
    float dy = m->cdf_row[y + 1] - m->cdf_row[y], dx = cc[x + 1] - cc[x];
    float fy = dy > 0.0f ? (u2 - m->cdf_row[y]) / dy : 0.5f, fx = dx > 0.0f ? (u1 - cc[x]) / dx : 0.5f;
    fx = clampf(fx, 0.0f, 1.0f);
    fy = clampf(fy, 0.0f, 1.0f);
    float gx = (float)x + 1e-4f + 0.9998f * fx, gy = (float)y + 1e-4f + 0.9998f * fy;
    if (m->layout == CDL_ENVMAP_MITSUBA) {
        gx += 0.5f;
        if (gx >= (float)m->cols)
            gx -= (float)m->cols;
        fx = 1e-4f + 0.9998f * fx;
        fy = 1e-4f + 0.9998f * fy;
    }
    float u = gx / (float)m->cols, v = gy / (float)m->rows;
    size_t i = (size_t)y * (size_t)m->cols + (size_t)x;
    cdl_vec3 l;
    if (m->layout == CDL_ENVMAP_EQUAL_AREA) {
        l = cdl_equal_area_square_to_sphere(u, v);
        *pdf = m->func[i] / m->mean / (4.0f * CDL_PI);
    } else {
        float th = v * CDL_PI, ph = u * 2.0f * CDL_PI, st = sinf(th);
        if (!(st > 0.0f))
            return cdl_v3(0.0f, 0.0f, 0.0f);
        l = cdl_v3(st * cosf(ph), st * sinf(ph), cosf(th));
        *pdf = m->func[i] / m->mean / (2.0f * CDL_PI * CDL_PI * st);
    }
    *w = cdl_add(cdl_add(cdl_scale(m->ex, l.x), cdl_scale(m->ey, l.y)), cdl_scale(m->ez, l.z));
    return cell_radiance(m, i, fx, fy);
}
