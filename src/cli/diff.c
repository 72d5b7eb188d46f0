/* candela diff TEST REF [--heatmap OUT.png] [--flip-map OUT.png] [--ppd N]
 * [--region X0,Y0,X1,Y1]: error metrics of one image against a reference
 * (DESIGN.md, Verification), FLIP among them. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

static int usage_error(cdl_error *err, const char *opt, const char *msg)
{
    *err = (cdl_error){CDL_ERR_USAGE, 0, "", ""};
    snprintf(err->file, sizeof err->file, "%s", opt);
    snprintf(err->msg, sizeof err->msg, "%.500s", msg);
    return CDL_ERR_USAGE;
}

static int parse_region(const char *s, int *rg, cdl_error *err)
{
    const char *p = s;
    char msg[500];
    snprintf(msg, sizeof msg, "expected pixel numbers X0,Y0,X1,Y1 (whole, >= 0), got '%.400s'", s);
    for (int i = 0; i < 4; i++) {
        char *end;
        errno = 0;
        long v = strtol(p, &end, 10);
        if (end == p || errno || v < 0 || v > 65536 || (i < 3 ? *end != ',' : *end != 0))
            return usage_error(err, "--region", msg);
        rg[i] = (int)v;
        p = end + 1;
    }
    if (rg[2] <= rg[0] || rg[3] <= rg[1]) {
        snprintf(msg, sizeof msg, "empty: X1 must exceed X0 and Y1 Y0, got '%.400s'", s);
        return usage_error(err, "--region", msg);
    }
    return 0;
}

/* Replaces *img by its region, naming path when it reaches outside. */
static int crop(cdl_image **img, const char *path, const int *rg, cdl_error *err)
{
    cdl_image *c = NULL;
    if (rg[2] > cdl_image_width(*img) || rg[3] > cdl_image_height(*img)) {
        char msg[500];
        snprintf(msg, sizeof msg, "%d,%d,%d,%d reaches outside %.400s (%dx%d)", rg[0], rg[1], rg[2], rg[3], path,
                 cdl_image_width(*img), cdl_image_height(*img));
        return usage_error(err, "--region", msg);
    }
    int rc = cdl_image_crop(*img, rg[0], rg[1], rg[2], rg[3], &c, err);
    if (!rc) {
        cdl_image_release(*img);
        *img = c;
    }
    return rc;
}

int cli_diff(int argc, char **argv)
{
    const char *files[2] = {NULL, NULL}, *heat = NULL, *flipmap = NULL;
    int nfiles = 0, region[4] = {0, 0, 0, 0}, has_region = 0;
    double ppd = 0.0;
    cdl_error err;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf("usage: candela diff TEST REF [--heatmap OUT.png] [--flip-map OUT.png] [--ppd N]\n"
                   "                    [--region X0,Y0,X1,Y1]\n"
                   "Prints RMSE, relative MSE (mean of (t-r)^2/(r^2+0.01)), mean absolute\n"
                   "error and the ratio of image means; for images with rare fireflies also\n"
                   "the relative MSE without the largest 0.1%% of per-pixel terms and the\n"
                   "median over 16x16 blocks of the ratio of block means; block_dev32 is the\n"
                   "RMS over 32x32 blocks of (block mean ratio - 1), a measure of bias.\n"
                   "--heatmap writes a\n"
                   "false-colour map of the per-pixel relative error (log scale, 1e-4 blue\n"
                   "to 1 red). --region compares only the pixels x in [X0, X1), y in [Y0, Y1)\n"
                   "(y = 0 the top row), e.g. one room of an interior.\n"
                   "flip_ldr / flip_hdr is the mean FLIP error in [0, 1] (Andersson et al.\n"
                   "2020, 0 = identical): LDR-FLIP when both files are PNG (the sRGB\n"
                   "values as displayed), otherwise HDR-FLIP (Andersson et al. 2021: the\n"
                   "largest LDR-FLIP over ACES-tone-mapped exposures from the reference's\n"
                   "median to its largest luminance). --ppd sets the viewing condition in\n"
                   "pixels per degree, 1 to 1000 (default 67.02: 0.7 m from a 0.7 m wide\n"
                   "3840-pixel monitor). --flip-map writes the per-pixel FLIP error with\n"
                   "the magma colour map (black 0 to pale yellow 1).\n");
            return 0;
        }
        if (!strcmp(argv[i], "--heatmap")) {
            if (i + 1 >= argc)
                return usage_error(&err, "--heatmap", "expects a file name"), cli_report(&err);
            heat = argv[++i];
            if (!cli_has_ext(heat, ".png"))
                return usage_error(&err, "--heatmap", "the heat map is written as PNG: name it *.png"),
                       cli_report(&err);
        } else if (!strcmp(argv[i], "--flip-map")) {
            if (i + 1 >= argc)
                return usage_error(&err, "--flip-map", "expects a file name"), cli_report(&err);
            flipmap = argv[++i];
            if (!cli_has_ext(flipmap, ".png"))
                return usage_error(&err, "--flip-map", "the FLIP map is written as PNG: name it *.png"),
                       cli_report(&err);
        } else if (!strcmp(argv[i], "--ppd")) {
            char *end;
            if (i + 1 >= argc)
                return usage_error(&err, "--ppd", "expects pixels per degree, 1 to 1000"), cli_report(&err);
            errno = 0;
            ppd = strtod(argv[++i], &end);
            if (end == argv[i] || *end || errno || !(ppd >= 1.0 && ppd <= 1000.0)) {
                char msg[500];
                snprintf(msg, sizeof msg, "expected pixels per degree from 1 to 1000, got '%.400s'", argv[i]);
                return usage_error(&err, "--ppd", msg), cli_report(&err);
            }
        } else if (!strcmp(argv[i], "--region")) {
            if (i + 1 >= argc)
                return usage_error(&err, "--region", "expects X0,Y0,X1,Y1"), cli_report(&err);
            if (parse_region(argv[++i], region, &err))
                return cli_report(&err);
            has_region = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            return usage_error(&err, argv[i], "unknown option for diff"), cli_report(&err);
        } else if (nfiles < 2) {
            files[nfiles++] = argv[i];
        } else {
            return usage_error(&err, argv[i], "diff takes two images"), cli_report(&err);
        }
    }
    if (nfiles != 2)
        return usage_error(&err, "diff", "expects TEST and REF images"), cli_report(&err);
    cdl_image *t = NULL, *r = NULL, *h = NULL, *fm = NULL;
    cdl_diff m;
    double flip = 0.0;
    int ldr = cli_has_ext(files[0], ".png") && cli_has_ext(files[1], ".png");
    int rc = cdl_image_load(files[0], &t, &err);
    if (!rc)
        rc = cdl_image_load(files[1], &r, &err);
    if (!rc && has_region) {
        rc = crop(&t, files[0], region, &err);
        if (!rc)
            rc = crop(&r, files[1], region, &err);
    }
    if (!rc)
        rc = cdl_image_diff(t, r, &m, &err);
    if (!rc && heat) {
        rc = cdl_image_diff_heatmap(t, r, &h, &err);
        if (!rc)
            rc = cdl_image_save(h, heat, 0.0f, &err);
    }
    if (!rc)
        rc = cdl_image_flip(t, r, !ldr, ppd, &flip, flipmap ? &fm : NULL, &err);
    if (!rc && flipmap)
        rc = cdl_image_save(fm, flipmap, 0.0f, &err);
    cdl_image_release(t);
    cdl_image_release(r);
    cdl_image_release(h);
    cdl_image_release(fm);
    if (rc) {
        if (err.code == CDL_ERR_INPUT && strcmp(err.file, files[0]) && strcmp(err.file, files[1]) &&
            !(heat && !strcmp(err.file, heat)) && !(flipmap && !strcmp(err.file, flipmap)))
            snprintf(err.file, sizeof err.file, "%s", files[0]); /* size mismatch names TEST */
        return cli_report(&err);
    }
    printf("rmse %.6g  relmse %.6g  mae %.6g  mean_ratio %.6f  relmse_trimmed %.6g  "
           "block_median_ratio %.6f  block_dev32 %.6f  (mean test %.6g, ref %.6g)  %s %.6f\n",
           m.rmse, m.relmse, m.mae, m.mean_ratio, m.relmse_trimmed, m.block_median_ratio, m.block_dev32,
           m.mean_test, m.mean_ref, ldr ? "flip_ldr" : "flip_hdr", flip);
    return 0;
}
