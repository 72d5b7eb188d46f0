/* OpenEXR files through the OpenEXRCore C API. */
#include "film/exr.h"

#include <openexr.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* The library reports details (e.g. which chunk is truncated) only through
 * its error callback; keep the first message so our error can carry it
 * instead of the library printing to stderr. */
typedef struct exr_msg {
    char text[256];
} exr_msg;

static void on_exr_error(exr_const_context_t ctx, exr_result_t code,
                         const char *msg)
{
    void *ud = NULL;
    (void)code;
    if (exr_get_user_data(ctx, &ud) == EXR_ERR_SUCCESS && ud) {
        exr_msg *m = ud;
        if (!m->text[0])
            snprintf(m->text, sizeof m->text, "%s", msg ? msg : "");
    }
}

static exr_context_initializer_t exr_init(exr_msg *m)
{
    exr_context_initializer_t ci = EXR_DEFAULT_CONTEXT_INITIALIZER;
    ci.error_handler_fn = on_exr_error;
    ci.user_data = m;
    /* A damaged file should fail, not be half-guessed. */
    ci.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    return ci;
}

static int exr_fail(cdl_error *err, int code, const char *path,
                    const char *what, exr_result_t rv, const exr_msg *m)
{
    return cdl_error_set(err, code, path, 0, "%s: %s", what,
                         m->text[0] ? m->text
                                    : exr_get_default_error_message(rv));
}

/* Opens for reading; the header is parsed here, so a non-EXR file or a
 * damaged header fails now. */
static int exr_open(const char *path, exr_context_t *ctx, exr_msg *m,
                    cdl_error *err)
{
    exr_context_initializer_t ci = exr_init(m);
    *ctx = NULL;
    exr_result_t rv = exr_start_read(ctx, path, &ci);
    if (rv == EXR_ERR_SUCCESS)
        return 0;
    if (*ctx)
        exr_finish(ctx);
    if (rv == EXR_ERR_FILE_ACCESS)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot open file");
    return exr_fail(err, CDL_ERR_INPUT, path, "cannot read OpenEXR header", rv,
                    m);
}

/* ---- writing ---------------------------------------------------------- */

/* Where the pixels of channel `ch` ("R" or "layer.G") come from. */
static const float *channel_source(const char *ch, const cdl_image *img, const cdl_layer *layers,
                                   int nlayers)
{
    const char *dot = strrchr(ch, '.');
    const cdl_image *src = img;
    const char *suffix = ch;
    if (dot) {
        src = NULL;
        for (int i = 0; i < nlayers && !src; i++)
            if (strlen(layers[i].name) == (size_t)(dot - ch) && !strncmp(layers[i].name, ch, (size_t)(dot - ch)))
                src = layers[i].img;
        suffix = dot + 1;
    }
    if (!src)
        return NULL;
    int off = suffix[0] == 'G' ? 1 : suffix[0] == 'B' ? 2 : 0; /* R and Y */
    return src->rgb + off;
}

/* OpenEXR up to 3.4.7 stores a chunk whose zlib output is exactly as long as
 * its packed pixels as if it were uncompressed, and readers then take the
 * zlib bytes for pixels (openexr issue 2306; hit by real renders here). The
 * default routine runs, and a chunk of that size is stored raw, as the
 * format says a chunk that does not shrink is. */
typedef exr_result_t (*compress_fn)(exr_encode_pipeline_t *);
_Static_assert(sizeof(compress_fn) == sizeof(void *), "the default routine travels in encoding_user_data");

static exr_result_t compress_guarded(exr_encode_pipeline_t *enc)
{
    compress_fn fn;
    memcpy(&fn, &enc->encoding_user_data, sizeof fn);
    exr_result_t rv = fn(enc);
    if (rv == EXR_ERR_SUCCESS && enc->compressed_bytes == enc->packed_bytes &&
        enc->compressed_buffer != enc->packed_buffer)
        memcpy(enc->compressed_buffer, enc->packed_buffer, enc->packed_bytes);
    return rv;
}

int cdl_exr_write(const char *file, const char *name, const cdl_image *img,
                  const cdl_layer *layers, int nlayers, const cdl_kv *meta, int nmeta,
                  cdl_error *err)
{
    exr_msg m = {{0}};
    exr_context_initializer_t ci = exr_init(&m);
    exr_context_t ctx = NULL;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int part = 0, have_enc = 0, status = 0;
    int32_t lines = 1;
    const char *what = "cannot create file";
    const int w = img->width, h = img->height;

    exr_result_t rv = exr_start_write(&ctx, file, EXR_WRITE_FILE_DIRECTLY, &ci);
    if (rv == EXR_ERR_SUCCESS) {
        what = "cannot set up OpenEXR header";
        rv = exr_add_part(ctx, "rgb", EXR_STORAGE_SCANLINE, &part);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr_simple(ctx, part, w, h,
                                                 EXR_COMPRESSION_ZIP);
    /* Channels are stored sorted by name, so B, G, R is file order. */
    const char *names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3 && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    for (int l = 0; l < nlayers && rv == EXR_ERR_SUCCESS; l++) {
        static const char *sfx[4] = {"R", "G", "B", "Y"};
        for (int c = layers[l].grey ? 3 : 0; c < (layers[l].grey ? 4 : 3) && rv == EXR_ERR_SUCCESS; c++) {
            char ch[96];
            snprintf(ch, sizeof ch, "%s.%s", layers[l].name, sfx[c]);
            rv = exr_add_channel(ctx, part, ch, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
        }
    }
    for (int i = 0; i < nmeta && rv == EXR_ERR_SUCCESS; i++) {
        what = "cannot add metadata attribute";
        rv = exr_attr_set_string(ctx, part, meta[i].key, meta[i].value);
    }
    if (rv == EXR_ERR_SUCCESS) {
        what = "cannot write OpenEXR header";
        rv = exr_write_header(ctx);
    }
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);

    for (int y = 0; y < h && rv == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t cinfo;
        what = "cannot write OpenEXR pixels";
        rv = exr_write_scanline_chunk_info(ctx, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = have_enc ? exr_encoding_update(ctx, part, &cinfo, &enc)
                      : exr_encoding_initialize(ctx, part, &cinfo, &enc);
        if (rv != EXR_ERR_SUCCESS)
            break;
        have_enc = 1;
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            const float *src = channel_source(ch->channel_name, img, layers, nlayers);
            if (!src) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            ch->encode_from_ptr = (const uint8_t *)(src + 3 * (size_t)y * w);
            ch->user_pixel_stride = 3 * sizeof(float);
            ch->user_line_stride = 3 * sizeof(float) * w;
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = sizeof(float);
        }
        rv = exr_encoding_choose_default_routines(ctx, part, &enc);
        if (rv == EXR_ERR_SUCCESS && enc.compress_fn && enc.compress_fn != compress_guarded) {
            memcpy(&enc.encoding_user_data, &enc.compress_fn, sizeof(void *));
            enc.compress_fn = compress_guarded;
        }
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, part, &enc);
    }
    if (rv != EXR_ERR_SUCCESS)
        status = exr_fail(err, CDL_ERR_SYSTEM, name, what, rv, &m);
    if (have_enc)
        exr_encoding_destroy(ctx, &enc);
    /* exr_finish writes the chunk offset table, so it can fail too. */
    if (ctx && (rv = exr_finish(&ctx)) != EXR_ERR_SUCCESS && !status)
        status = exr_fail(err, CDL_ERR_SYSTEM, name,
                          "cannot finish OpenEXR file", rv, &m);
    return status;
}

/* ---- reading ---------------------------------------------------------- */

/* Where a file channel goes in our RGB pixel, or -1 to skip it. Only plain
 * R, G, B (or Y when the file is grey) are used; layered names like
 * "diffuse.R" are other images. */
static int channel_slot(const char *name, int grey)
{
    if (grey)
        return strcmp(name, "Y") == 0 ? 0 : -1;
    if (strcmp(name, "R") == 0)
        return 0;
    if (strcmp(name, "G") == 0)
        return 1;
    if (strcmp(name, "B") == 0)
        return 2;
    return -1;
}

/* Decodes one chunk whose top-left pixel is (x0, y0) in img. */
static exr_result_t decode_chunk(exr_context_t ctx, const exr_chunk_info_t *ci,
                                 exr_decode_pipeline_t *dec, int *have_dec,
                                 cdl_image *img, int x0, int y0, int grey)
{
    /* The library computes chunk sizes from the header; still refuse a chunk
     * that would not fit so a bad file can never write out of bounds. */
    if (x0 < 0 || y0 < 0 || ci->width < 0 || ci->height < 0 ||
        x0 + ci->width > img->width || y0 + ci->height > img->height)
        return EXR_ERR_CORRUPT_CHUNK;
    exr_result_t rv = *have_dec ? exr_decoding_update(ctx, 0, ci, dec)
                                : exr_decoding_initialize(ctx, 0, ci, dec);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    *have_dec = 1;
    for (int c = 0; c < dec->channel_count; c++) {
        exr_coding_channel_info_t *ch = &dec->channels[c];
        int slot = channel_slot(ch->channel_name, grey);
        ch->decode_to_ptr = NULL; /* NULL = skip this channel */
        if (slot < 0)
            continue;
        ch->decode_to_ptr =
            (uint8_t *)(img->rgb +
                        3 * ((size_t)y0 * img->width + (size_t)x0) + slot);
        ch->user_pixel_stride = 3 * sizeof(float);
        ch->user_line_stride = 3 * sizeof(float) * img->width;
        ch->user_data_type = EXR_PIXEL_FLOAT; /* half/uint converted */
        ch->user_bytes_per_element = sizeof(float);
    }
    rv = exr_decoding_choose_default_routines(ctx, 0, dec);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_decoding_run(ctx, 0, dec);
    return rv;
}

static int read_pixels(exr_context_t ctx, const char *path, cdl_image *img,
                       const exr_msg *m, cdl_error *err)
{
    exr_storage_t storage;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *chl = NULL;
    exr_result_t rv;

    /* Multi-part files: the first part is the image. */
    if ((rv = exr_get_storage(ctx, 0, &storage)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_data_window(ctx, 0, &dw)) != EXR_ERR_SUCCESS ||
        (rv = exr_get_channels(ctx, 0, &chl)) != EXR_ERR_SUCCESS)
        return exr_fail(err, CDL_ERR_INPUT, path, "bad OpenEXR header", rv, m);
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "deep OpenEXR images are not supported");

    /* Pick R,G,B, else Y; subsampled channels would need resampling. */
    int found[4] = {0, 0, 0, 0}; /* R, G, B, Y */
    for (int i = 0; i < chl->num_channels; i++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[i];
        int slot = strcmp(e->name.str, "Y") == 0 ? 3
                                                 : channel_slot(e->name.str, 0);
        if (slot < 0)
            continue;
        if (e->x_sampling != 1 || e->y_sampling != 1)
            return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                                 "subsampled channel '%s' is not supported",
                                 e->name.str);
        found[slot] = 1;
    }
    int grey = !(found[0] && found[1] && found[2]);
    if (grey && !found[3])
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "no R, G, B or Y channels in OpenEXR file");

    /* The image is the data window; widths are computed in 64 bits since a
     * hostile header may hold any int32 values. */
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1;
    int64_t h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > INT32_MAX / 4 || h > INT32_MAX / 4)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "bad OpenEXR data window %d,%d .. %d,%d",
                             dw.min.x, dw.min.y, dw.max.x, dw.max.y);
    if ((uint64_t)w * (uint64_t)h > CDL_MAX_PIXELS)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                             "OpenEXR data window %lldx%lld is larger than candela reads (2^28 pixels)",
                             (long long)w, (long long)h);
    if (cdl_image_alloc(img, (int)w, (int)h, err))
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0,
                             "out of memory for a %dx%d image", (int)w,
                             (int)h);

    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    exr_chunk_info_t ci;
    int have_dec = 0;
    if (storage == EXR_STORAGE_SCANLINE) {
        int32_t lines = 1;
        rv = exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (int64_t y = dw.min.y; y <= dw.max.y && rv == EXR_ERR_SUCCESS;
             y += lines) {
            rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &ci);
            if (rv == EXR_ERR_SUCCESS)
                rv = decode_chunk(ctx, &ci, &dec, &have_dec, img, 0,
                                  ci.start_y - dw.min.y, grey);
        }
    } else {
        /* Tiled: read only the full-resolution level (0, 0). */
        int32_t tw = 0, th = 0;
        rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tw, &th);
        if (rv == EXR_ERR_SUCCESS && (tw <= 0 || th <= 0))
            rv = EXR_ERR_INVALID_ATTR;
        int64_t nx = rv ? 0 : (w + tw - 1) / tw, ny = rv ? 0 : (h + th - 1) / th;
        for (int64_t ty = 0; ty < ny && rv == EXR_ERR_SUCCESS; ty++)
            for (int64_t tx = 0; tx < nx && rv == EXR_ERR_SUCCESS; tx++) {
                rv = exr_read_tile_chunk_info(ctx, 0, (int)tx, (int)ty, 0, 0,
                                              &ci);
                if (rv == EXR_ERR_SUCCESS)
                    rv = decode_chunk(ctx, &ci, &dec, &have_dec, img,
                                      (int)(tx * tw), (int)(ty * th), grey);
            }
    }
    if (have_dec)
        exr_decoding_destroy(ctx, &dec);
    if (rv != EXR_ERR_SUCCESS) {
        cdl_image_free(img);
        return exr_fail(err, CDL_ERR_INPUT, path,
                        "cannot read OpenEXR pixels (damaged or truncated?)",
                        rv, m);
    }
    if (grey) /* Y was decoded into R; grey means R = G = B */
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            img->rgb[3 * i + 1] = img->rgb[3 * i + 2] = img->rgb[3 * i];
    return 0;
}

int cdl_exr_read(const char *path, cdl_image *img, cdl_error *err)
{
    exr_msg m = {{0}};
    exr_context_t ctx;
    int status = exr_open(path, &ctx, &m, err);
    if (status)
        return status;
    status = read_pixels(ctx, path, img, &m, err);
    exr_finish(&ctx);
    return status;
}

int cdl_image_exr_attr(const char *path, const char *key, char *buf, size_t n,
                       cdl_error *err)
{
    exr_msg m = {{0}};
    exr_context_t ctx;
    int32_t len = 0;
    const char *s = NULL;
    if (n > 0)
        buf[0] = '\0';
    int status = exr_open(path, &ctx, &m, err);
    if (status)
        return status;
    /* Silence the callback: an absent attribute is a normal answer here. */
    m.text[0] = 'x';
    exr_result_t rv = exr_attr_get_string(ctx, 0, key, &len, &s);
    if (rv == EXR_ERR_NO_ATTR_BY_NAME)
        status = cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                               "no attribute '%s' in OpenEXR header", key);
    else if (rv != EXR_ERR_SUCCESS || !s)
        status = cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                               "attribute '%s' is not a string", key);
    else if (n > 0)
        snprintf(buf, n, "%.*s", (int)len, s);
    exr_finish(&ctx);
    return status;
}
