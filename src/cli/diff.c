/* candela diff TEST REF [--heatmap OUT.png]: error metrics of one image
 * against a reference (DESIGN.md, Verification). */
#include <stdio.h>
#include <string.h>

#include "cli/commands.h"
#include "film/image.h"
#include "film/metrics.h"

int cdl_cmd_diff(int argc, char **argv)
{
    const char *files[2] = {NULL, NULL}, *heat = NULL;
    int nfiles = 0;
    cdl_error err;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf("usage: candela diff TEST REF [--heatmap OUT.png]\n"
                   "Prints RMSE, relative MSE (mean of (t-r)^2/(r^2+0.01)), mean absolute\n"
                   "error and the ratio of image means; for images with rare fireflies also\n"
                   "the relative MSE without the largest 0.1%% of per-pixel terms and the\n"
                   "median over 16x16 blocks of the ratio of block means. --heatmap writes a\n"
                   "false-colour map of the per-pixel relative error (log scale, 1e-4 blue\n"
                   "to 1 red).\n");
            return 0;
        }
        if (!strcmp(argv[i], "--heatmap")) {
            if (i + 1 >= argc)
                return cdl_report(&(cdl_error){CDL_ERR_USAGE, 0, "--heatmap", "expects a file name"});
            heat = argv[++i];
            if (!cdl_image_has_ext(heat, ".png"))
                return cdl_report(&(cdl_error){CDL_ERR_USAGE, 0, "--heatmap", "the heat map is written as PNG: name it *.png"});
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
           "block_median_ratio %.6f  (mean test %.6g, ref %.6g)\n",
           m.rmse, m.relmse, m.mae, m.mean_ratio, m.relmse_trimmed,
           cdl_image_block_median_ratio(&t, &r, 16), m.mean_test, m.mean_ref);
    cdl_image_free(&t);
    cdl_image_free(&r);
    cdl_image_free(&h);
    return 0;
}
