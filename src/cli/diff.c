/* candela diff TEST REF [--heatmap OUT.png] [--region X0,Y0,X1,Y1]: error
 * metrics of one image against a reference (DESIGN.md, Verification). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/args.h"
#include "cli/commands.h"
#include "film/image.h"
#include "film/metrics.h"

/* Replaces img by its pixels [x0, x1) x [y0, y1) (checked against its size). */
static int crop(cdl_image *img, const char *path, const int *rg, cdl_error *err)
{
    if (rg[2] > img->width || rg[3] > img->height)
        return cdl_error_set(err, CDL_ERR_USAGE, "--region", 0, "%d,%d,%d,%d reaches outside %s (%dx%d)", rg[0],
                             rg[1], rg[2], rg[3], path, img->width, img->height);
    cdl_image c = {0};
    if (cdl_image_alloc(&c, rg[2] - rg[0], rg[3] - rg[1], err))
        return err->code;
    for (int y = 0; y < c.height; y++)
        memcpy(c.rgb + (size_t)3 * c.width * y, img->rgb + 3 * ((size_t)img->width * (y + rg[1]) + rg[0]),
               sizeof(float) * 3 * c.width);
    cdl_image_free(img);
    *img = c;
    return 0;
}

static int parse_region(const char *s, int *rg, cdl_error *err)
{
    float v[4];
    if (cdl_arg_floats("--region", s, 4, v, err))
        return err->code;
    for (int i = 0; i < 4; i++)
        if (v[i] < 0.0f || v[i] > 65536.0f || v[i] != floorf(v[i]))
            return cdl_error_set(err, CDL_ERR_USAGE, "--region", 0,
                                 "expected pixel numbers X0,Y0,X1,Y1 (whole, >= 0), got '%s'", s);
    for (int i = 0; i < 4; i++)
        rg[i] = (int)v[i];
    if (rg[2] <= rg[0] || rg[3] <= rg[1])
        return cdl_error_set(err, CDL_ERR_USAGE, "--region", 0, "empty: X1 must exceed X0 and Y1 Y0, got '%s'", s);
    return 0;
}

int cdl_cmd_diff(int argc, char **argv)
{
    const char *files[2] = {NULL, NULL}, *heat = NULL;
    int nfiles = 0, region[4] = {0, 0, 0, 0}, has_region = 0;
    cdl_error err;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf("usage: candela diff TEST REF [--heatmap OUT.png] [--region X0,Y0,X1,Y1]\n"
                   "Prints RMSE, relative MSE (mean of (t-r)^2/(r^2+0.01)), mean absolute\n"
                   "error and the ratio of image means; for images with rare fireflies also\n"
                   "the relative MSE without the largest 0.1%% of per-pixel terms and the\n"
                   "median over 16x16 blocks of the ratio of block means; block_dev32 is the\n"
                   "RMS over 32x32 blocks of (block mean ratio - 1), a measure of bias.\n"
                   "--heatmap writes a\n"
                   "false-colour map of the per-pixel relative error (log scale, 1e-4 blue\n"
                   "to 1 red). --region compares only the pixels x in [X0, X1), y in [Y0, Y1)\n"
                   "(y = 0 the top row), e.g. one room of an interior.\n");
            return 0;
        }
        if (!strcmp(argv[i], "--heatmap")) {
            if (i + 1 >= argc)
                return cdl_report(&(cdl_error){CDL_ERR_USAGE, 0, "--heatmap", "expects a file name"});
            heat = argv[++i];
            if (!cdl_image_has_ext(heat, ".png"))
                return cdl_report(&(cdl_error){CDL_ERR_USAGE, 0, "--heatmap", "the heat map is written as PNG: name it *.png"});
        } else if (!strcmp(argv[i], "--region")) {
            if (i + 1 >= argc)
                return cdl_report(&(cdl_error){CDL_ERR_USAGE, 0, "--region", "expects X0,Y0,X1,Y1"});
            if (parse_region(argv[++i], region, &err))
                return cdl_report(&err);
            has_region = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            cdl_error_set(&err, CDL_ERR_USAGE, argv[i], 0, "unknown option for diff");
            return cdl_report(&err);
        } else if (nfiles < 2) {
            files[nfiles++] = argv[i];
        } else {
            cdl_error_set(&err, CDL_ERR_USAGE, argv[i], 0, "diff takes two images");
            return cdl_report(&err);
        }
    }
    if (nfiles != 2) {
        cdl_error_set(&err, CDL_ERR_USAGE, "diff", 0, "expects TEST and REF images");
        return cdl_report(&err);
    }
    cdl_image t = {0}, r = {0}, h = {0};
    cdl_metrics m;
    int rc = cdl_image_read(files[0], &t, &err);
    if (!rc)
        rc = cdl_image_read(files[1], &r, &err);
    if (!rc && has_region) {
        rc = crop(&t, files[0], region, &err);
        if (!rc)
            rc = crop(&r, files[1], region, &err);
    }
    if (!rc)
        rc = cdl_image_compare(&t, &r, &m, &err);
    if (!rc && heat) {
        rc = cdl_image_heatmap(&t, &r, &h, &err);
        if (!rc)
            rc = cdl_image_write(heat, &h, NULL, 0, 0.0f, &err);
    }
    if (rc) {
        cdl_image_free(&t);
        cdl_image_free(&r);
        cdl_image_free(&h);
        if (err.code == CDL_ERR_INPUT && strcmp(err.file, files[0]) && strcmp(err.file, files[1]) &&
            !(heat && !strcmp(err.file, heat)))
            snprintf(err.file, sizeof err.file, "%s", files[0]); /* size mismatch names TEST */
        return cdl_report(&err);
    }
    printf("rmse %.6g  relmse %.6g  mae %.6g  mean_ratio %.6f  relmse_trimmed %.6g  "
           "block_median_ratio %.6f  block_dev32 %.6f  (mean test %.6g, ref %.6g)\n",
           m.rmse, m.relmse, m.mae, m.mean_ratio, m.relmse_trimmed,
           cdl_image_block_median_ratio(&t, &r, 16), cdl_image_block_rms_dev(&t, &r, 32), m.mean_test,
           m.mean_ref);
    cdl_image_free(&t);
    cdl_image_free(&r);
    cdl_image_free(&h);
    return 0;
}
