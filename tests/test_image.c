/* Image file and metrics tests: round trips through EXR, PFM and PNG,
 * foreign EXR layouts, damaged files, and metrics on hand-computed inputs.
 * Usage: test_image [references-dir]; returns non-zero on any failure. */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */

#include <dirent.h>
#include <math.h>
#include <openexr.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "film/image.h"
#include "film/metrics.h"

static int failures;

#define CHECK(cond, ...)                                                      \
    do {                                                                      \
        if (!(cond)) {                                                        \
            failures++;                                                       \
            printf("FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);            \
            printf(__VA_ARGS__);                                              \
            printf("\n");                                                     \
        }                                                                     \
    } while (0)

static char dir[] = "/tmp/candela-test-image-XXXXXX";

static const char *tmp_path(const char *name)
{
    static char buf[8][512];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 512, "%s/%s", dir, name);
    return p;
}

static void set_px(cdl_image *img, int x, int y, float r, float g, float b)
{
    float *p = img->rgb + 3 * ((size_t)y * img->width + x);
    p[0] = r;
    p[1] = g;
    p[2] = b;
}

static const float *px(const cdl_image *img, int x, int y)
{
    return img->rgb + 3 * ((size_t)y * img->width + x);
}

/* A gradient in [0,1] with a few values a PNG must clamp. 37x23 so EXR has
 * a partial last chunk and a top/bottom flip would show. */
static void make_gradient(cdl_image *g)
{
    cdl_image_alloc(g, 37, 23, NULL);
    for (int y = 0; y < g->height; y++)
        for (int x = 0; x < g->width; x++)
            set_px(g, x, y, x / 36.0f, y / 22.0f, (x * y) / (36.0f * 22.0f));
    set_px(g, 1, 0, -0.5f, 1.5f, 1000.0f);
    set_px(g, 2, 0, NAN, INFINITY, 1e-30f);
}

static int write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    size_t w = fwrite(data, 1, n, f);
    return fclose(f) == 0 && w == n ? 0 : -1;
}

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    *n = (size_t)ftell(f);
    rewind(f);
    unsigned char *d = malloc(*n + 1);
    if (d && fread(d, 1, *n, f) != *n) {
        free(d);
        d = NULL;
    }
    fclose(f);
    return d;
}

static int contains(const unsigned char *d, size_t n, const char *s, size_t m)
{
    for (size_t i = 0; i + m <= n; i++)
        if (memcmp(d + i, s, m) == 0)
            return 1;
    return 0;
}

/* Reading a bad file must fail cleanly with an error naming it. */
static void expect_read_error(const char *path, const char *what)
{
    cdl_image img = {0, 0, NULL};
    cdl_error err = {0};
    char msg[2048];
    int rc = cdl_image_read(path, &img, &err);
    cdl_error_format(&err, msg, sizeof msg);
    CHECK(rc != 0, "%s: read succeeded (%dx%d)", what, img.width, img.height);
    CHECK(img.rgb == NULL, "%s: image not left empty", what);
    CHECK(strcmp(err.file, path) == 0, "%s: error names '%s'", what, err.file);
    printf("  %-16s -> %s\n", what, msg);
    cdl_image_free(&img);
}

/* Writes img through the OpenEXR C API in layouts our writer never makes,
 * so the reader's handling of them is really exercised. grey writes the red
 * channel as Y. */
static int write_variant(const char *path, const cdl_image *img, int tiled,
                         exr_pixel_type_t type, int grey,
                         exr_compression_t comp, int ox, int oy)
{
    exr_context_initializer_t ci = EXR_DEFAULT_CONTEXT_INITIALIZER;
    exr_context_t ctx;
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    int part = 0, w = img->width, h = img->height, first = 1, tile = 16;
    exr_attr_box2i_t dw;
    exr_attr_v2f_t swc;
    dw.min.x = ox;
    dw.min.y = oy;
    dw.max.x = ox + w - 1;
    dw.max.y = oy + h - 1;
    swc.x = swc.y = 0.0f;
    float *ones = malloc(sizeof(float) * 3 * w * h);
    for (int i = 0; i < 3 * w * h; i++)
        ones[i] = 1.0f;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &ci);
    if (rv)
        return free(ones), rv;
    rv = exr_add_part(ctx, "variant",
                      tiled ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part);
    if (!rv)
        rv = exr_initialize_required_attr(ctx, part, &dw, &dw, 1.0f, &swc,
                                          1.0f, EXR_LINEORDER_INCREASING_Y,
                                          comp);
    if (!rv && tiled)
        rv = exr_set_tile_descriptor(ctx, part, tile, tile, EXR_TILE_ONE_LEVEL,
                                     EXR_TILE_ROUND_DOWN);
    const char *names[4] = {"A", "B", "G", "R"};
    for (int c = grey ? 3 : 0; c < 4 && !rv; c++)
        rv = exr_add_channel(ctx, part, grey ? "Y" : names[c], type,
                             EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv)
        rv = exr_attr_set_string(ctx, part, "note", "variant");
    if (!rv)
        rv = exr_write_header(ctx);
    int32_t lines = 1;
    if (!rv && !tiled)
        rv = exr_get_scanlines_per_chunk(ctx, part, &lines);
    int step_y = tiled ? tile : lines, step_x = tiled ? tile : w;
    for (int y = 0; y < h && !rv; y += step_y)
        for (int x = 0; x < w && !rv; x += step_x) {
            exr_chunk_info_t cinfo;
            rv = tiled ? exr_write_tile_chunk_info(ctx, part, x / tile,
                                                   y / tile, 0, 0, &cinfo)
                       : exr_write_scanline_chunk_info(ctx, part, oy + y,
                                                       &cinfo);
            if (!rv)
                rv = first ? exr_encoding_initialize(ctx, part, &cinfo, &enc)
                           : exr_encoding_update(ctx, part, &cinfo, &enc);
            first = 0;
            for (int c = 0; c < enc.channel_count && !rv; c++) {
                exr_coding_channel_info_t *ch = &enc.channels[c];
                char n = ch->channel_name[0];
                int slot = n == 'G' ? 1 : n == 'B' ? 2 : 0;
                const float *base = n == 'A' ? ones : img->rgb;
                ch->encode_from_ptr =
                    (const uint8_t *)(base + 3 * ((size_t)y * w + x) + slot);
                ch->user_pixel_stride = 12;
                ch->user_line_stride = 12 * w;
                ch->user_data_type = EXR_PIXEL_FLOAT;
                ch->user_bytes_per_element = 4;
            }
            if (!rv)
                rv = exr_encoding_choose_default_routines(ctx, part, &enc);
            if (!rv)
                rv = exr_encoding_run(ctx, part, &enc);
        }
    if (!first)
        exr_encoding_destroy(ctx, &enc);
    exr_result_t frv = exr_finish(&ctx);
    free(ones);
    return rv ? rv : frv;
}

static void test_roundtrip(void)
{
    cdl_image g, back;
    cdl_error err = {0};
    const cdl_kv meta[] = {{"candela.spp", "64"},
                           {"candela.scene", "cornell box"}};
    make_gradient(&g);
    const char *exts[] = {"grad.exr", "grad.pfm", "grad.png", "UPPER.EXR"};
    for (int i = 0; i < 4; i++) {
        int rc = cdl_image_write(tmp_path(exts[i]), &g, meta, 2, 0.0f, &err);
        CHECK(rc == 0, "write %s: %s", exts[i], err.msg);
    }
    /* EXR and PFM keep floats bit for bit, NaN and Inf included. */
    for (int i = 0; i < 4; i += (i == 1 ? 2 : 1)) {
        int rc = cdl_image_read(tmp_path(exts[i]), &back, &err);
        CHECK(rc == 0, "read %s: %s", exts[i], err.msg);
        if (rc)
            continue;
        CHECK(back.width == 37 && back.height == 23, "%s size %dx%d", exts[i],
              back.width, back.height);
        int same = back.width == 37 && back.height == 23 &&
                   memcmp(back.rgb, g.rgb, sizeof(float) * 3 * 37 * 23) == 0;
        CHECK(same, "%s pixels differ, e.g. (3,5) %g vs %g", exts[i],
              px(&back, 3, 5)[0], px(&g, 3, 5)[0]);
        cdl_image_free(&back);
    }
    /* PNG: compare in sRGB space against the clamped input. */
    if (cdl_image_read(tmp_path("grad.png"), &back, &err) == 0) {
        double worst = 0;
        for (size_t i = 0; i < 3 * 37 * 23; i++) {
            float v = g.rgb[i], e = v > 0 ? (v < 1 ? v : 1) : 0;
            double d = fabs(cdl_srgb_encode(e) - cdl_srgb_encode(back.rgb[i]));
            worst = d > worst ? d : worst;
        }
        CHECK(worst <= 0.5 / 255 + 1e-4, "PNG max sRGB error %g > 0.5/255",
              worst);
        printf("  PNG round trip max sRGB error %.5f (limit %.5f)\n", worst,
               1.0 / 255);
        cdl_image_free(&back);
    } else
        CHECK(0, "read grad.png: %s", err.msg);

    /* Exposure +1 doubles: 0.25 at (9,0) must come back as 0.5. */
    CHECK(cdl_image_write(tmp_path("exp.png"), &g, NULL, 0, 1.0f, &err) == 0,
          "%s", err.msg);
    if (cdl_image_read(tmp_path("exp.png"), &back, &err) == 0) {
        float v = px(&back, 9, 0)[0];
        CHECK(fabsf(cdl_srgb_encode(v) - cdl_srgb_encode(0.5f)) < 0.5f / 255,
              "exposure: got %g, want 0.5", v);
        cdl_image_free(&back);
    }

    /* Metadata: EXR attributes and PNG tEXt chunks. */
    char buf[64];
    CHECK(cdl_image_exr_attr(tmp_path("grad.exr"), "candela.spp", buf,
                             sizeof buf, &err) == 0 && strcmp(buf, "64") == 0,
          "spp attr '%s' (%s)", buf, err.msg);
    CHECK(cdl_image_exr_attr(tmp_path("grad.exr"), "candela.scene", buf,
                             sizeof buf, &err) == 0 &&
              strcmp(buf, "cornell box") == 0,
          "scene attr '%s' (%s)", buf, err.msg);
    CHECK(cdl_image_exr_attr(tmp_path("grad.exr"), "missing", buf, sizeof buf,
                             &err) == CDL_ERR_INPUT,
          "absent attribute not reported");
    size_t n = 0;
    unsigned char *d = slurp(tmp_path("grad.png"), &n);
    CHECK(d && contains(d, n, "tEXtcandela.scene\0cornell box", 29),
          "PNG has no tEXt chunk for candela.scene");
    free(d);

    /* Write failures: unknown extension, missing directory. */
    CHECK(cdl_image_write(tmp_path("x.tga"), &g, NULL, 0, 0, &err) ==
              CDL_ERR_USAGE,
          "unknown extension accepted");
    CHECK(cdl_image_write("/nonexistent-candela-dir/x.exr", &g, NULL, 0, 0,
                          &err) != 0 &&
              strcmp(err.file, "/nonexistent-candela-dir/x.exr") == 0,
          "write into missing dir: rc/file '%s'", err.file);
    cdl_image_free(&g);
}

static void test_exr_layouts(void)
{
    /* Values k/64 are exact in half, so every layout must read back exactly. */
    cdl_image q, back;
    cdl_error err = {0};
    cdl_image_alloc(&q, 37, 23, NULL);
    for (int y = 0; y < 23; y++)
        for (int x = 0; x < 37; x++)
            set_px(&q, x, y, (x % 16) / 16.0f, (y % 8) / 8.0f + 2,
                   ((x + y) % 32) / 4.0f + 0.5f);
    struct {
        const char *name;
        int tiled;
        exr_pixel_type_t type;
        int grey;
        exr_compression_t comp;
        int ox, oy;
    } v[] = {
        {"tiled-half-piz.exr", 1, EXR_PIXEL_HALF, 0, EXR_COMPRESSION_PIZ, 10, 20},
        {"scan-float-y-rle.exr", 0, EXR_PIXEL_FLOAT, 1, EXR_COMPRESSION_RLE, -5, -7},
        {"scan-half-zips.exr", 0, EXR_PIXEL_HALF, 0, EXR_COMPRESSION_ZIPS, 0, 3},
        {"tiled-float-none.exr", 1, EXR_PIXEL_FLOAT, 0, EXR_COMPRESSION_NONE, 0, 0},
    };
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++) {
        exr_result_t rv = write_variant(tmp_path(v[i].name), &q, v[i].tiled,
                                        v[i].type, v[i].grey, v[i].comp,
                                        v[i].ox, v[i].oy);
        CHECK(rv == 0, "writing %s: %s", v[i].name,
              exr_get_default_error_message(rv));
        if (rv)
            continue;
        int rc = cdl_image_read(tmp_path(v[i].name), &back, &err);
        CHECK(rc == 0, "read %s: %s", v[i].name, err.msg);
        if (rc)
            continue;
        int bad = -1;
        for (int k = 0; k < 3 * 37 * 23 && bad < 0; k++) {
            float want = q.rgb[v[i].grey ? k - k % 3 : k];
            if (back.rgb[k] != want)
                bad = k;
        }
        CHECK(back.width == 37 && back.height == 23 && bad < 0,
              "%s: %dx%d, first bad value #%d = %g", v[i].name, back.width,
              back.height, bad, bad >= 0 ? back.rgb[bad] : 0);
        printf("  read %-22s ok\n", v[i].name);
        cdl_image_free(&back);
    }
    cdl_image_free(&q);
}

static void test_bad_files(void)
{
    size_t n = 0;
    unsigned char *d;
    cdl_image big;
    /* Big enough for many chunks, so a cut lands in pixel data. */
    cdl_image_alloc(&big, 64, 256, NULL);
    for (size_t i = 0; i < 3 * 64 * 256; i++)
        big.rgb[i] = (float)(i % 97) * 0.37f;
    cdl_image_write(tmp_path("big.exr"), &big, NULL, 0, 0, NULL);
    cdl_image_write(tmp_path("big.pfm"), &big, NULL, 0, 0, NULL);
    cdl_image_write(tmp_path("big.png"), &big, NULL, 0, 0, NULL);
    cdl_image_free(&big);

    const char *src[] = {"big.exr", "big.pfm", "big.png"};
    const char *cut[] = {"cut.exr", "cut.pfm", "cut.png"};
    for (int i = 0; i < 3; i++) {
        d = slurp(tmp_path(src[i]), &n);
        CHECK(d != NULL, "cannot read back %s", src[i]);
        if (d)
            write_file(tmp_path(cut[i]), d, n * 6 / 10);
        free(d);
        expect_read_error(tmp_path(cut[i]), cut[i]);
    }
    d = slurp(tmp_path("big.exr"), &n);
    if (d)
        write_file(tmp_path("header-cut.exr"), d, 40);
    free(d);
    expect_read_error(tmp_path("header-cut.exr"), "header-cut.exr");
    const char text[] = "this is not an image\n";
    write_file(tmp_path("text.exr"), text, sizeof text - 1);
    expect_read_error(tmp_path("text.exr"), "text file");
    write_file(tmp_path("empty.png"), "", 0);
    expect_read_error(tmp_path("empty.png"), "empty file");
    const char pfm[] = "PF\n-3 5\n-1.0\n";
    write_file(tmp_path("neg.pfm"), pfm, sizeof pfm - 1);
    expect_read_error(tmp_path("neg.pfm"), "bad PFM header");
    expect_read_error(tmp_path("does-not-exist.exr"), "missing file");
}

static void test_pfm_variants(void)
{
    /* Big-endian greyscale "Pf" (positive scale), 2x2, bottom row first. */
    unsigned char f[] = "Pf\n2 2\n1.0\n"
                        "\x3f\x80\x00\x00\x40\x00\x00\x00"  /* 1, 2 bottom */
                        "\x40\x40\x00\x00\x40\x80\x00\x00"; /* 3, 4 top */
    write_file(tmp_path("grey.pfm"), f, sizeof f - 1);
    cdl_image img;
    cdl_error err = {0};
    int rc = cdl_image_read(tmp_path("grey.pfm"), &img, &err);
    CHECK(rc == 0, "Pf read: %s", err.msg);
    if (rc == 0) {
        CHECK(px(&img, 0, 0)[0] == 3 && px(&img, 1, 0)[2] == 4 &&
                  px(&img, 0, 1)[1] == 1 && px(&img, 1, 1)[0] == 2,
              "Pf pixels %g %g %g %g", px(&img, 0, 0)[0], px(&img, 1, 0)[2],
              px(&img, 0, 1)[1], px(&img, 1, 1)[0]);
        cdl_image_free(&img);
    }
}

static int near(double a, double b, double tol)
{
    return fabs(a - b) <= tol * (fabs(b) > 1 ? fabs(b) : 1);
}

static void test_metrics(void)
{
    cdl_image t, r, heat;
    cdl_metrics m;
    cdl_error err = {0};

    /* Constant 0.5 vs 0.55: d = 0.05, relmse = 0.0025/0.26. */
    cdl_image_alloc(&t, 4, 3, NULL);
    cdl_image_alloc(&r, 4, 3, NULL);
    for (int i = 0; i < 36; i++) {
        r.rgb[i] = 0.5f;
        t.rgb[i] = 0.55f;
    }
    CHECK(cdl_image_compare(&t, &r, &m, &err) == 0, "%s", err.msg);
    CHECK(near(m.rmse, 0.05, 1e-6), "rmse %.9g", m.rmse);
    CHECK(near(m.mae, 0.05, 1e-6), "mae %.9g", m.mae);
    CHECK(near(m.relmse, 0.0025 / 0.26, 1e-5), "relmse %.9g want %.9g",
          m.relmse, 0.0025 / 0.26);
    CHECK(near(m.mean_ratio, 1.1, 1e-6), "mean_ratio %.9g", m.mean_ratio);
    CHECK(near(m.mean_test, 0.55, 1e-6) && near(m.mean_ref, 0.5, 1e-6),
          "means %g %g", m.mean_test, m.mean_ref);

    /* Half the pixels 1, half 0; test = 1.1 ref: relmse = 0.5*0.01/1.01. */
    for (int i = 0; i < 36; i++) {
        r.rgb[i] = i < 18 ? 1.0f : 0.0f;
        t.rgb[i] = r.rgb[i] * 1.1f;
    }
    CHECK(cdl_image_compare(&t, &r, &m, &err) == 0, "%s", err.msg);
    CHECK(near(m.relmse, 0.5 * 0.01 / 1.01, 1e-5), "relmse %.9g want %.9g",
          m.relmse, 0.5 * 0.01 / 1.01);
    CHECK(near(m.mean_ratio, 1.1, 1e-6), "mean_ratio %.9g", m.mean_ratio);
    CHECK(near(m.rmse, sqrt(0.5 * 0.01), 1e-5), "rmse %.9g", m.rmse);

    /* Errors: size mismatch names both sizes; NaN in test is refused. */
    cdl_image other;
    cdl_image_alloc(&other, 5, 3, NULL);
    CHECK(cdl_image_compare(&other, &r, &m, &err) == CDL_ERR_INPUT &&
              strstr(err.msg, "5x3") && strstr(err.msg, "4x3"),
          "size mismatch: '%s'", err.msg);
    cdl_image_free(&other);
    t.rgb[7] = NAN;
    CHECK(cdl_image_compare(&t, &r, &m, &err) == CDL_ERR_INPUT,
          "NaN not refused");
    printf("  NaN test pixel  -> %s\n", err.msg);
    cdl_image_free(&t);
    cdl_image_free(&r);

    /* 1000 pixels, one firefly: relmse = 999.5^2/0.26/1000, trimmed 0;
     * block median still sees the 1.1 bias. */
    cdl_image_alloc(&t, 40, 25, NULL);
    cdl_image_alloc(&r, 40, 25, NULL);
    for (int i = 0; i < 3000; i++) {
        r.rgb[i] = 0.5f;
        t.rgb[i] = 0.5f;
    }
    set_px(&t, 13, 7, 1000, 1000, 1000);
    CHECK(cdl_image_compare(&t, &r, &m, &err) == 0, "%s", err.msg);
    CHECK(near(m.relmse, 999.5 * 999.5 / 0.26 / 1000, 1e-6), "relmse %.9g",
          m.relmse);
    CHECK(m.relmse_trimmed == 0, "trimmed %.9g", m.relmse_trimmed);

    CHECK(cdl_image_heatmap(&t, &r, &heat, &err) == 0, "%s", err.msg);
    CHECK(cdl_image_write(tmp_path("heat.png"), &heat, NULL, 0, 0, &err) == 0,
          "%s", err.msg);
    cdl_image_free(&heat);
    cdl_image back;
    if (cdl_image_read(tmp_path("heat.png"), &back, &err) == 0) {
        /* Shown colours are the ramp ends in sRGB: red and blue. */
        const float *hot = px(&back, 13, 7), *cold = px(&back, 0, 0);
        float e_hot[3] = {0.85f, 0.10f, 0.10f}, e_cold[3] = {0.16f, 0.20f, 0.65f};
        for (int c = 0; c < 3; c++) {
            CHECK(fabsf(cdl_srgb_encode(hot[c]) - e_hot[c]) < 1.0f / 255,
                  "hot[%d] %g", c, cdl_srgb_encode(hot[c]));
            CHECK(fabsf(cdl_srgb_encode(cold[c]) - e_cold[c]) < 1.0f / 255,
                  "cold[%d] %g", c, cdl_srgb_encode(cold[c]));
        }
        cdl_image_free(&back);
    }

    for (int i = 0; i < 3000; i++)
        t.rgb[i] = 0.55f;
    set_px(&t, 13, 7, 1000, 1000, 1000);
    double med = cdl_image_block_median_ratio(&t, &r, 8);
    CHECK(near(med, 1.1, 1e-6), "block median %.9g", med);
    CHECK(isnan(cdl_image_block_median_ratio(&t, &r, 0)), "bs 0 not NaN");
    cdl_image_free(&t);
    cdl_image_free(&r);
}

static void test_reference(const char *refdir)
{
    char path[4096];
    cdl_image ref;
    cdl_error err = {0};
    cdl_metrics m;
    snprintf(path, sizeof path, "%s/mcguire-cornell-original_path_256.exr",
             refdir);
    int rc = cdl_image_read(path, &ref, &err);
    CHECK(rc == 0, "read %s: %s", path, err.msg);
    if (rc)
        return;
    CHECK(ref.width == 256 && ref.height == 256, "size %dx%d", ref.width,
          ref.height);
    rc = cdl_image_compare(&ref, &ref, &m, &err);
    CHECK(rc == 0, "compare: %s", err.msg);
    CHECK(rc == 0 && isfinite(m.mean_ref) && m.mean_ref > 0, "mean %g",
          m.mean_ref);
    CHECK(rc == 0 && m.relmse == 0 && m.mean_ratio == 1,
          "self relmse %g ratio %g", m.relmse, m.mean_ratio);
    printf("  reference %dx%d mean %.6f\n", ref.width, ref.height,
           m.mean_ref);
    cdl_image_free(&ref);
}

/* Eight rows of a real render whose ZIP chunk compresses to exactly its
 * packed size: OpenEXR <= 3.4.7 wrote zlib bytes that read back as raw
 * pixels (NaN at one pixel). Must round-trip bit for bit. */
static void test_exr_zip_stored(const char *data)
{
    char in[1024];
    snprintf(in, sizeof in, "%s/exr_zip_stored.pfm", data);
    cdl_image img, back;
    cdl_error err = {0};
    if (cdl_image_read(in, &img, &err)) {
        CHECK(0, "read %s: %s", in, err.msg);
        return;
    }
    CHECK(cdl_image_write(tmp_path("stored.exr"), &img, NULL, 0, 0.0f, &err) == 0, "%s", err.msg);
    if (cdl_image_read(tmp_path("stored.exr"), &back, &err) == 0) {
        size_t n = 3 * (size_t)img.width * (size_t)img.height, bad = 0, first = n;
        for (size_t i = 0; i < n; i++)
            if (memcmp(&img.rgb[i], &back.rgb[i], sizeof(float))) {
                bad++;
                first = first < i ? first : i;
            }
        CHECK(bad == 0, "ZIP chunk of incompressible size: %zu of %zu values differ (first at pixel %zu: %g)",
              bad, n, first / 3, bad ? back.rgb[first] : 0.0);
        printf("  ZIP chunk of incompressible size: %zu values, %zu differ\n", n, bad);
        cdl_image_free(&back);
    } else
        CHECK(0, "read stored.exr: %s", err.msg);
    cdl_image_free(&img);
}

/* The temp dir must hold no PATH.tmp-<pid> leftovers; then remove it. */
static void clean_dir(void)
{
    DIR *dp = opendir(dir);
    struct dirent *e;
    while (dp && (e = readdir(dp))) {
        if (e->d_name[0] == '.')
            continue;
        CHECK(!strstr(e->d_name, ".tmp-"), "temp file left: %s", e->d_name);
        remove(tmp_path(e->d_name));
    }
    if (dp)
        closedir(dp);
    rmdir(dir);
}

int main(int argc, char **argv)
{
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 1;
    }
    printf("round trips\n");
    test_roundtrip();
    printf("EXR layouts\n");
    test_exr_layouts();
    test_exr_zip_stored(CDL_TEST_DATA);
    test_pfm_variants();
    printf("bad files\n");
    test_bad_files();
    printf("metrics\n");
    test_metrics();
    if (argc > 1) {
        printf("reference\n");
        test_reference(argv[1]);
    } else
        printf("reference: skipped (no directory given)\n");
    clean_dir();
    printf(failures ? "%d FAILED\n" : "all passed\n", failures);
    return failures != 0;
}
