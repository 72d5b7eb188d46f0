/* RGB float images: memory, format dispatch, PFM and PNG (EXR is in exr.c). */
#define _POSIX_C_SOURCE 200809L /* getpid */

#include "film/image.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <png.h>
#include <stb_image.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "film/exr.h"

int cdl_image_alloc(cdl_image *img, int w, int h, cdl_error *err)
{
    img->width = img->height = 0;
    img->rgb = NULL;
    if (w <= 0 || h <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, NULL, 0,
                             "bad image size %dx%d", w, h);
    if ((uint64_t)w * (uint64_t)h > CDL_MAX_PIXELS)
        return cdl_error_set(err, CDL_ERR_INPUT, NULL, 0,
                             "image size %dx%d is larger than candela handles (2^28 pixels)", w, h);
    img->rgb = calloc((size_t)w * (size_t)h * 3, sizeof(float));
    if (!img->rgb)
        return cdl_error_set(err, CDL_ERR_SYSTEM, NULL, 0,
                             "out of memory for a %dx%d image", w, h);
    img->width = w;
    img->height = h;
    return 0;
}

void cdl_image_free(cdl_image *img)
{
    free(img->rgb);
    img->rgb = NULL;
    img->width = img->height = 0;
}

int cdl_image_check_stb(const char *path, cdl_error *err)
{
    int w, h, n;
    if (!stbi_info(path, &w, &h, &n))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot read image: %s", stbi_failure_reason());
    if (w <= 0 || h <= 0 || (uint64_t)w * (uint64_t)h > CDL_MAX_PIXELS)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "image size %dx%d out of range (at most 2^%d pixels)",
                             w, h, CDL_MAX_PIXELS == (1ull << 28) ? 28 : 22);
    return 0;
}

int cdl_image_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    if (m > n)
        return 0;
    for (size_t i = 0; i < m; i++)
        if (tolower((unsigned char)path[n - m + i]) !=
            tolower((unsigned char)ext[i]))
            return 0;
    return 1;
}

float cdl_srgb_encode(float v)
{
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

float cdl_srgb_decode(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* ---- PFM -------------------------------------------------------------- */

/* PFM is little-endian here regardless of the host, so bytes are shuffled
 * explicitly rather than trusting the host's float layout. */
static void put_le32(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    p[0] = (unsigned char)u;
    p[1] = (unsigned char)(u >> 8);
    p[2] = (unsigned char)(u >> 16);
    p[3] = (unsigned char)(u >> 24);
}

static float get32(const unsigned char *p, int little)
{
    uint32_t u = little ? (uint32_t)p[0] | (uint32_t)p[1] << 8 |
                              (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24
                        : (uint32_t)p[3] | (uint32_t)p[2] << 8 |
                              (uint32_t)p[1] << 16 | (uint32_t)p[0] << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static int pfm_write(const char *file, const char *name, const cdl_image *img,
                     cdl_error *err)
{
    FILE *f = fopen(file, "wb");
    if (!f)
        return cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "cannot create: %s",
                             strerror(errno));
    size_t rowlen = (size_t)img->width * 3;
    unsigned char *row = malloc(rowlen * 4);
    int ok = row && fprintf(f, "PF\n%d %d\n-1.0\n", img->width, img->height) > 0;
    for (int y = img->height - 1; ok && y >= 0; y--) { /* bottom row first */
        const float *src = img->rgb + (size_t)y * rowlen;
        for (size_t i = 0; i < rowlen; i++)
            put_le32(row + 4 * i, src[i]);
        ok = fwrite(row, 4, rowlen, f) == rowlen;
    }
    int werr = errno;
    free(row);
    if (fclose(f) != 0 && ok) {
        ok = 0;
        werr = errno;
    }
    return ok ? 0
              : cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "write failed: %s",
                              strerror(werr));
}

/* Reads one whitespace-delimited header token; consumes the single
 * whitespace character after it, which is exactly what PFM requires before
 * the pixel data. */
static int pfm_token(FILE *f, char *buf, size_t n)
{
    int c;
    size_t len = 0;
    while ((c = fgetc(f)) != EOF && isspace(c))
        ;
    while (c != EOF && !isspace(c) && len + 1 < n) {
        buf[len++] = (char)c;
        c = fgetc(f);
    }
    buf[len] = '\0';
    return len > 0 && c != EOF && isspace(c);
}

static int pfm_read(const char *path, FILE *f, cdl_image *img, cdl_error *err)
{
    char magic[8], ws[16], hs[16], ss[64], *end;
    if (!pfm_token(f, magic, sizeof magic) || !pfm_token(f, ws, sizeof ws) ||
        !pfm_token(f, hs, sizeof hs) || !pfm_token(f, ss, sizeof ss))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "bad PFM header");
    int nch = strcmp(magic, "PF") == 0 ? 3 : strcmp(magic, "Pf") == 0 ? 1 : 0;
    long w = strtol(ws, &end, 10);
    int bad = *end != '\0';
    long h = strtol(hs, &end, 10);
    bad |= *end != '\0';
    double scale = strtod(ss, &end);
    bad |= *end != '\0' || scale == 0.0 || !isfinite(scale);
    if (!nch || bad || w <= 0 || h <= 0 || w > (1L << 20) || h > (1L << 20))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "bad PFM header '%s %s %s %s'", magic, ws, hs, ss);

    /* Check the size before allocating, so a truncated or lying header
     * fails cleanly instead of reading garbage. */
    long start = ftell(f);
    size_t rowlen = (size_t)w * nch;
    if (start < 0 || fseek(f, 0, SEEK_END) != 0)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot seek");
    long size = ftell(f);
    double need = (double)rowlen * 4.0 * (double)h;
    if (size < 0 || (double)(size - start) < need)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "truncated PFM: %dx%d needs %.0f data bytes, "
                             "file has %ld", (int)w, (int)h, need,
                             size - start);
    if (fseek(f, start, SEEK_SET) != 0)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot seek");

    unsigned char *row = malloc(rowlen * 4);
    if (!row || cdl_image_alloc(img, (int)w, (int)h, err)) {
        free(row);
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0,
                             "out of memory for a %ldx%ld image", w, h);
    }
    int little = scale < 0;
    for (long y = h - 1; y >= 0; y--) { /* bottom row first */
        if (fread(row, 4, rowlen, f) != rowlen) {
            free(row);
            cdl_image_free(img);
            return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                                 "read failed in PFM pixel data");
        }
        float *dst = img->rgb + (size_t)y * w * 3;
        for (long x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                dst[3 * x + c] =
                    get32(row + 4 * ((size_t)x * nch + (nch == 3 ? c : 0)),
                          little);
    }
    free(row);
    return 0;
}

/* ---- PNG -------------------------------------------------------------- */

/* libpng reports errors by longjmp; keep the message for our error instead
 * of letting libpng print it. */
static void on_png_error(png_structp png, png_const_charp msg)
{
    char *buf = png_get_error_ptr(png);
    snprintf(buf, 200, "%s", msg);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static unsigned char to_srgb8(float v, float scale)
{
    v *= scale;
    if (!(v > 0.0f)) /* also NaN */
        return 0;
    if (v >= 1.0f)
        return 255;
    return (unsigned char)lrintf(cdl_srgb_encode(v) * 255.0f);
}

static int png_write(const char *file, const char *name, const cdl_image *img,
                     const cdl_kv *meta, int nmeta, float exposure,
                     cdl_error *err)
{
    char msg[200] = "";
    FILE *f = fopen(file, "wb");
    if (!f)
        return cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "cannot create: %s",
                             strerror(errno));
    unsigned char *row = malloc((size_t)img->width * 3);
    png_text *text = calloc((size_t)nmeta + 1, sizeof *text);
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, msg,
                                              on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    int failed = !row || !text || !info;
    /* setjmp may only stand alone in a condition (C11 7.13.1.1). */
    if (!failed && setjmp(png_jmpbuf(png)))
        failed = 1;
    if (failed) {
        png_destroy_write_struct(png ? &png : NULL, info ? &info : NULL);
        fclose(f);
        free(row);
        free(text);
        return cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "PNG write failed: %s",
                             msg[0] ? msg : "out of memory");
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, img->width, img->height, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    for (int i = 0; i < nmeta; i++) {
        text[i].compression = PNG_TEXT_COMPRESSION_NONE;
        text[i].key = (png_charp)meta[i].key;
        text[i].text = (png_charp)meta[i].value;
    }
    if (nmeta > 0)
        png_set_text(png, info, text, nmeta);
    png_write_info(png, info);
    float scale = exp2f(exposure);
    for (int y = 0; y < img->height; y++) {
        const float *src = img->rgb + (size_t)y * img->width * 3;
        for (int i = 0; i < img->width * 3; i++)
            row[i] = to_srgb8(src[i], scale);
        png_write_row(png, row);
    }
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    free(row);
    free(text);
    if (fclose(f) != 0)
        return cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "write failed: %s",
                             strerror(errno));
    return 0;
}

static int png_read(const char *path, FILE *f, cdl_image *img, cdl_error *err)
{
    char msg[200] = "";
    /* Changed after setjmp and needed in the error path: must be volatile. */
    unsigned char *volatile buf = NULL;
    png_bytep *volatile rows = NULL;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, msg,
                                             on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    int failed = !info;
    if (!failed && setjmp(png_jmpbuf(png)))
        failed = 1;
    if (failed) {
        png_destroy_read_struct(png ? &png : NULL, info ? &info : NULL, NULL);
        free(buf);
        free(rows);
        cdl_image_free(img);
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "bad or truncated PNG: %s",
                             msg[0] ? msg : "out of memory");
    }
    png_init_io(png, f);
    png_read_info(png, info);
    /* Normalize every PNG flavour to 8- or 16-bit RGB. */
    png_set_expand(png);
    png_set_strip_alpha(png);
    png_set_gray_to_rgb(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    png_uint_32 w = png_get_image_width(png, info);
    png_uint_32 h = png_get_image_height(png, info);
    int depth = png_get_bit_depth(png, info);
    size_t rowbytes = png_get_rowbytes(png, info);
    if (png_get_channels(png, info) != 3 || (depth != 8 && depth != 16) ||
        w > INT32_MAX / 4 || h > INT32_MAX / 4)
        png_error(png, "unsupported PNG layout");
    if (cdl_image_alloc(img, (int)w, (int)h, err))
        png_error(png, "out of memory");
    buf = malloc(rowbytes * h);
    rows = malloc(sizeof *rows * h);
    if (!buf || !rows)
        png_error(png, "out of memory");
    for (png_uint_32 y = 0; y < h; y++)
        rows[y] = buf + (size_t)y * rowbytes;
    png_read_image(png, rows);
    png_read_end(png, NULL);

    float lut[256]; /* 8-bit files: decode each code once */
    for (int i = 0; i < 256; i++)
        lut[i] = cdl_srgb_decode(i / 255.0f);
    for (png_uint_32 y = 0; y < h; y++) {
        const unsigned char *p = rows[y];
        float *dst = img->rgb + (size_t)y * w * 3;
        for (size_t i = 0; i < (size_t)w * 3; i++, p += depth / 8)
            dst[i] = depth == 8 ? lut[p[0]] /* 16-bit is big-endian */
                                : cdl_srgb_decode((p[0] << 8 | p[1]) / 65535.0f);
    }
    png_destroy_read_struct(&png, &info, NULL);
    free(buf);
    free(rows);
    return 0;
}

/* ---- dispatch --------------------------------------------------------- */

static int write_any(const char *path, const cdl_image *img, const cdl_layer *layers, int nlayers,
                     const cdl_kv *meta, int nmeta, float exposure, cdl_error *err)
{
    enum { EXR, PNG, PFM } fmt;
    if (cdl_image_has_ext(path, ".exr"))
        fmt = EXR;
    else if (cdl_image_has_ext(path, ".png"))
        fmt = PNG;
    else if (cdl_image_has_ext(path, ".pfm"))
        fmt = PFM;
    else
        return cdl_error_set(err, CDL_ERR_USAGE, path, 0,
                             "unknown image extension (want .exr, .png or .pfm)");
    if (!img->rgb || img->width <= 0 || img->height <= 0)
        return cdl_error_set(err, CDL_ERR_USAGE, path, 0, "empty image");

    char tmp[4096];
    if (snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid()) >=
        (int)sizeof tmp)
        return cdl_error_set(err, CDL_ERR_USAGE, path, 0, "path too long");
    if (nlayers && fmt != EXR)
        return cdl_error_set(err, CDL_ERR_USAGE, path, 0, "layers need an .exr file");
    int status = fmt == EXR ? cdl_exr_write(tmp, path, img, layers, nlayers, meta, nmeta, err)
                 : fmt == PNG
                     ? png_write(tmp, path, img, meta, nmeta, exposure, err)
                     : pfm_write(tmp, path, img, err);
    if (status == 0 && rename(tmp, path) != 0)
        status = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0,
                               "cannot rename %s into place: %s", tmp,
                               strerror(errno));
    if (status)
        remove(tmp);
    return status;
}

int cdl_image_write(const char *path, const cdl_image *img, const cdl_kv *meta,
                    int nmeta, float exposure, cdl_error *err)
{
    return write_any(path, img, NULL, 0, meta, nmeta, exposure, err);
}

int cdl_image_write_layers(const char *path, const cdl_image *img, const cdl_layer *layers,
                           int nlayers, const cdl_kv *meta, int nmeta, cdl_error *err)
{
    for (int i = 0; i < nlayers; i++)
        if (!layers[i].img || layers[i].img->width != img->width || layers[i].img->height != img->height)
            return cdl_error_set(err, CDL_ERR_USAGE, path, 0, "layer %s does not match the image", layers[i].name);
    return write_any(path, img, layers, nlayers, meta, nmeta, 0.0f, err);
}

int cdl_image_read(const char *path, cdl_image *img, cdl_error *err)
{
    unsigned char magic[8] = {0};
    img->width = img->height = 0;
    img->rgb = NULL;
    FILE *f = fopen(path, "rb");
    if (!f)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot open: %s",
                             strerror(errno));
    size_t got = fread(magic, 1, sizeof magic, f);
    rewind(f);
    int status;
    if (got >= 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 &&
        magic[3] == 0x01) {
        fclose(f); /* OpenEXRCore opens the file itself */
        return cdl_exr_read(path, img, err);
    } else if (got >= 3 && magic[0] == 'P' && (magic[1] == 'F' || magic[1] == 'f') &&
               isspace(magic[2])) {
        status = pfm_read(path, f, img, err);
    } else if (got == 8 && png_sig_cmp(magic, 0, 8) == 0) {
        status = png_read(path, f, img, err);
    } else {
        /* Name the format the user expected from the extension. */
        const char *want = cdl_image_has_ext(path, ".exr")   ? "an OpenEXR"
                           : cdl_image_has_ext(path, ".png") ? "a PNG"
                           : cdl_image_has_ext(path, ".pfm") ? "a PFM"
                               : "an OpenEXR, PNG or PFM";
        status = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "not %s file%s", want,
                               got == 0 ? " (empty)" : "");
    }
    fclose(f);
    return status;
}
