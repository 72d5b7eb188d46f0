/* Image comparison against a reference, for convergence and bias tests. */
#ifndef CDL_METRICS_H
#define CDL_METRICS_H

#include "film/image.h"

typedef struct cdl_metrics {
    double rmse, relmse, mae, mean_test, mean_ref, mean_ratio;
    double relmse_trimmed; /* dropping the largest 0.1% per-pixel terms */
} cdl_metrics;

/* Per channel over all pixels: rmse = sqrt(mean (t-r)^2);
 * relmse = mean (t-r)^2/(r^2+0.01); mae = mean |t-r|;
 * mean_ratio = mean(t)/mean(r) (NaN if mean(r) == 0).
 * relmse_trimmed averages the per-pixel terms (mean over the 3 channels of
 * the relmse term) after dropping the largest floor(0.1% of pixels).
 * Sizes must match; a non-finite value in either image is CDL_ERR_INPUT. */
int cdl_image_compare(const cdl_image *test, const cdl_image *ref,
                      cdl_metrics *out, cdl_error *err);

/* False-colour map of the per-pixel relative squared error (mean over
 * channels of (t-r)^2/(r^2+0.01)) on a log scale from 1e-4 (blue) through
 * green and yellow to 1 (red); non-finite errors are white. Colours are
 * stored linear, so cdl_image_write(.png, exposure 0) shows them as meant.
 * out is allocated here. */
int cdl_image_heatmap(const cdl_image *test, const cdl_image *ref,
                      cdl_image *out, cdl_error *err);

/* Median over bs x bs blocks (edge blocks may be smaller) of
 * mean(test block)/mean(ref block), skipping blocks whose ref mean < 1e-6 or
 * whose ratio is not finite: robust against fireflies when testing for bias.
 * NaN if sizes differ, bs < 1 or no block qualifies. */
double cdl_image_block_median_ratio(const cdl_image *test,
                                    const cdl_image *ref, int bs);

/* Root mean square over the same blocks of (ratio - 1): a bias measure
 * once the per-pixel noise averages out within a block. */
double cdl_image_block_rms_dev(const cdl_image *test, const cdl_image *ref, int bs);

#endif
