/* Pixel reconstruction filters, separable, as Mitsuba 3 (box, tent,
 * gaussian, mitchell, catmullrom, lanczos) and pbrt-v3/v4 (box, triangle,
 * gaussian, mitchell, sinc/lanczos) define them. A pixel's value is the
 * filter-weighted average of the radiance around its centre,
 * int f(x - c) L(x) dx / int f(x - c) dx, which is what their films'
 * sum w L / sum w converges to. candela reaches it by sampling each
 * camera ray's offset from |f| (tabulated) and weighting the sample by
 * f / pdf / int f, so the film's plain average per pixel needs no weights
 * and no pixel is written from another tile. Light-tracing contributions
 * land at a raster point and are spread over the pixels around it with
 * weights f normalized to sum to one (Mitsuba's ImageBlock, normalize on).
 * candela's own default is the one-pixel box, sampled exactly as before. */
#ifndef CDL_FILTER_H
#define CDL_FILTER_H

#include "core/vec.h"

typedef enum cdl_filter_type {
    CDL_FILTER_BOX, /* one pixel: candela's default */
    CDL_FILTER_TENT,
    CDL_FILTER_GAUSSIAN,
    CDL_FILTER_MITCHELL, /* Mitchell-Netravali cubic (B, C); Catmull-Rom is B = 0, C = 1/2 */
    CDL_FILTER_LANCZOS   /* sinc(x) sinc(x / tau) */
} cdl_filter_type;

#define CDL_FILTER_BINS 256

typedef struct cdl_filter {
    cdl_filter_type type;
    float radius[2]; /* support half-widths along x and y, pixels */
    float p0, p1;    /* gaussian: alpha of exp(-alpha x^2), 0; mitchell: B, C; lanczos: tau, 0 */
    int clip;        /* samples stay inside the image (Mitsuba) rather than spill past it (pbrt) */
    int wide;        /* not the one-pixel box: the tables below are in use */
    /* per axis, cumulative integrals of |f| and f over CDL_FILTER_BINS equal
     * bins spanning [-radius, radius] */
    float cabs[2][CDL_FILTER_BINS + 1];
    float csgn[2][CDL_FILTER_BINS + 1];
} cdl_filter;

/* The one-pixel box. */
void cdl_filter_box(cdl_filter *f);
/* Any filter: radii (> 0, <= 16 pixels) and parameters as above; builds the
 * tables. Returns 0, or -1 on a degenerate filter (f is then the box). */
int cdl_filter_init(cdl_filter *f, cdl_filter_type type, float rx, float ry, float p0, float p1, int clip);

/* The filter's 1D profile along axis (0: x, 1: y) at offset x pixels. */
float cdl_filter_eval(const cdl_filter *f, int axis, float x);

/* A camera sample for pixel (px, py) of a w x h image from two uniform
 * numbers: its raster position (*x, *y) and the weight its radiance takes
 * (1 for the box). */
static inline void cdl_filter_sample(const cdl_filter *f, int px, int py, int w, int h, float u1, float u2,
                                     float *x, float *y, float *weight);
void cdl_filter_sample_wide(const cdl_filter *f, int px, int py, int w, int h, float u1, float u2, float *x,
                            float *y, float *weight);

static inline void cdl_filter_sample(const cdl_filter *f, int px, int py, int w, int h, float u1, float u2,
                                     float *x, float *y, float *weight)
{
    if (!f || !f->wide) {
        *x = (float)px + u1;
        *y = (float)py + u2;
        *weight = 1.0f;
        return;
    }
    cdl_filter_sample_wide(f, px, py, w, h, u1, u2, x, y, weight);
}

/* The pixels a contribution at raster (x, y) spreads over: at most
 * CDL_FILTER_MAX_TAPS of them, with weights summing to one over the whole
 * footprint (pixels outside the w x h image are left out). Returns the
 * count written to pix[] (row-major index) and wt[]. */
#define CDL_FILTER_MAX_TAPS 1089 /* 33 x 33: radius 16 */
int cdl_filter_spread(const cdl_filter *f, float x, float y, int w, int h, int *pix, float *wt);

#endif
