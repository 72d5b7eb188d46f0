/* RGB float images and their files (OpenEXR, PNG, PFM).
 * Pixels are linear RGB, row-major, top row first, 3 floats per pixel. */
#ifndef CDL_IMAGE_H
#define CDL_IMAGE_H

#include <stddef.h>

#include "core/error.h"

typedef struct cdl_image {
    int width, height;
    float *rgb; /* 3*w*h floats, row-major, top row first */
} cdl_image;

typedef struct cdl_kv {
    const char *key;
    const char *value;
} cdl_kv; /* string metadata */

/* The largest image read or made: 2^28 pixels (16384 x 16384, 3 GiB of
 * floats), so that a hostile file header cannot ask for more. */
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
#define CDL_MAX_PIXELS (1ull << 22) /* 20 s per input under ASan */
#else
#define CDL_MAX_PIXELS (1ull << 28)
#endif

/* Zero-filled image; w, h > 0 and w h <= CDL_MAX_PIXELS. */
int cdl_image_alloc(cdl_image *img, int w, int h, cdl_error *err);
/* Checks an 8-bit or Radiance image's header (read by stb_image) before it
 * is decoded: the size must be within CDL_MAX_PIXELS, since a 30-byte TGA
 * can declare 750 million RLE pixels. */
int cdl_image_check_stb(const char *path, cdl_error *err);
/* Frees the pixels and zeroes the struct; safe on a zeroed image. */
void cdl_image_free(cdl_image *img);

/* Writes by extension (.exr, .png, .pfm, case-insensitive) to PATH.tmp-<pid>
 * and renames it over PATH, so a reader never sees a half-written file; on
 * failure the temp file is removed.
 * EXR: 32-bit float R,G,B, ZIP, scanline, meta as string attributes.
 * PNG: 8-bit sRGB of rgb * 2^exposure, clamped, NaN -> 0, meta as tEXt.
 * PFM: "PF", little-endian (scale -1), bottom row first; meta is dropped.
 * exposure only applies to PNG. */
int cdl_image_write(const char *path, const cdl_image *img, const cdl_kv *meta,
                    int nmeta, float exposure, cdl_error *err);

/* Reads EXR (half/float/uint; R,G,B or Y as grey; scanline or tiled, level 0;
 * the image is the data window), PFM (PF/Pf, either endianness) or PNG
 * (8/16 bit, sRGB decoded to linear, alpha dropped). The format is found
 * from the file's magic bytes. On error img is left zeroed. */
/* An extra EXR layer: channels "name.R/G/B", or "name.Y" when grey. */
typedef struct cdl_layer {
    const char *name;
    const cdl_image *img;
    int grey;
} cdl_layer;

/* Like cdl_image_write for .exr, with extra layers after the RGB image. */
int cdl_image_write_layers(const char *path, const cdl_image *img, const cdl_layer *layers,
                           int nlayers, const cdl_kv *meta, int nmeta, cdl_error *err);
int cdl_image_read(const char *path, cdl_image *img, cdl_error *err);

/* One string attribute of an EXR header into buf (truncated to n-1 chars);
 * CDL_ERR_INPUT if absent or not a string. */
int cdl_image_exr_attr(const char *path, const char *key, char *buf, size_t n,
                       cdl_error *err);

/* 1 if path ends in ext (e.g. ".exr"), case-insensitive. */
int cdl_image_has_ext(const char *path, const char *ext);

/* The sRGB transfer curve (IEC 61966-2-1), for values in [0,1]. */
float cdl_srgb_encode(float linear);
float cdl_srgb_decode(float encoded);

#endif
