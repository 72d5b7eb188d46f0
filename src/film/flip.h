/* FLIP, the image difference evaluator of Andersson et al. 2020 ("FLIP: A
 * Difference Evaluator for Alternating Images"), and HDR-FLIP of Andersson
 * et al. 2021 ("Visualizing Errors in Rendered High Dynamic Range Images"),
 * with the constants of NVlabs' reference implementation (v1.4 and later). */
#ifndef CDL_FLIP_H
#define CDL_FLIP_H

#include "film/image.h"

/* 0.7 m from a 0.7 m wide monitor of 3840 pixels: 3840 pi / 180. */
#define CDL_FLIP_PPD_DEFAULT (3840.0 * 3.14159265358979323846 / 180.0)
#define CDL_FLIP_PPD_MIN 1.0
#define CDL_FLIP_PPD_MAX 1000.0

/* HDR-FLIP's exposures: count values 2^e for e from start to stop. */
typedef struct cdl_flip_exposures {
    double start, stop;
    int count;
} cdl_flip_exposures;

/* Per-pixel FLIP of test against ref into map (width * height floats in
 * [0, 1]; may be NULL) and its mean into *mean (may be NULL).
 * hdr = 0: LDR-FLIP of the linear RGB pixels clamped to [0, 1];
 * hdr = 1: HDR-FLIP over the automatic exposures of ref (exp, if not NULL,
 * receives them). ppd <= 0 is the default; otherwise it must lie in
 * [CDL_FLIP_PPD_MIN, CDL_FLIP_PPD_MAX]. Sizes must match and pixels be
 * finite: CDL_ERR_INPUT otherwise. */
int cdl_flip(const cdl_image *test, const cdl_image *ref, int hdr, double ppd, float *map,
             double *mean, cdl_flip_exposures *exp, cdl_error *err);

/* The automatic exposure range of HDR-FLIP (section 2.1 of the HDR paper):
 * start = log2(x / Ymax), stop = log2(x / Ymedian), where x is the input
 * the ACES fit maps to 0.85 and Y the luminance of ref's pixels;
 * count = max(2, ceil(stop - start)). A black reference gives 0, 0, 2.
 * -1 when out of memory. */
int cdl_flip_exposure_range(const cdl_image *ref, cdl_flip_exposures *out);

/* Pieces exposed for the tests. */
double cdl_flip_aces(double x);           /* the ACES fit with 0.6 pre-exposure cancelled */
double cdl_flip_aces_inverse_085(void);   /* the x with cdl_flip_aces(x) = 0.85 */
double cdl_flip_cmax(void);               /* HyAB(green, blue)^0.7 after Hunt */
double cdl_flip_color_remap(double hyab); /* HyAB distance -> colour error in [0, 1] */
int cdl_flip_spatial_radius(double ppd);
int cdl_flip_feature_radius(double ppd);
/* Linear RGB of the colour-space pipeline: Hunt-adjusted L*a*b* of a linear RGB. */
void cdl_flip_lab_hunt(const double rgb[3], double lab[3]);

/* The magma colour of v in [0, 1] (the table's entry round(255 v)), as
 * linear RGB so that an sRGB PNG shows the map's colours. */
void cdl_flip_magma(float v, float rgb[3]);

#endif
