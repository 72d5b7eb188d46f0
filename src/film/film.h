/* The film: per-pixel sums of radiance samples (weighted by the pixel
 * filter where it is wider than the one-pixel box, see filter.h). A pixel is written by one thread at a time (passes split the
 * image into tiles), so sums need no atomics and are deterministic. */
#ifndef CDL_FILM_H
#define CDL_FILM_H

#include <stdatomic.h>
#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"
#include "film/filter.h"
#include "film/image.h"

typedef struct cdl_film {
    int width, height;
    double *sum;        /* 3 per pixel */
    uint32_t *count;    /* samples per pixel */
    uint64_t nonfinite; /* samples dropped as NaN/Inf (counted as zero) */
    uint64_t rays;      /* rays traced into this film, all threads */
    /* Light tracing: contributions that land on any pixel, summed per pass
     * in a fixed order and divided by the passes at the end. */
    double *splat;      /* 3 per pixel, NULL until the first splat */
    uint32_t splat_passes;
    /* Arbitrary output variables: per-pixel sums averaged like the image
     * (an integrator that fills one adds to it once per pixel sample). */
    struct cdl_aov *aovs;
    int naovs;
    atomic_int *cancel; /* the render's cancel flag (NULL: none); see cdl_cancelled */
} cdl_film;

#define CDL_MAX_AOVS 16

typedef struct cdl_aov {
    char name[32];
    int channels; /* 1 or 3 */
    double *sum;  /* channels per pixel */
} cdl_aov;

/* Adds an AOV layer (before rendering); returns its index or -1. */
int cdl_film_add_aov(cdl_film *f, const char *name, int channels, cdl_error *err);
/* Index of the AOV called name, or -1. */
int cdl_film_find_aov(const cdl_film *f, const char *name);
/* Averages AOV a into img (allocated here; 1-channel AOVs fill R = G = B). */
int cdl_film_resolve_aov(const cdl_film *f, int a, cdl_image *img, cdl_error *err);

/* Splats gathered by one tile or one batch of light paths during a pass;
 * merged into the film in a fixed order so that passes stay deterministic. */
typedef struct cdl_splats {
    uint32_t n, cap;
    uint32_t *pixel;
    float *rgb;
} cdl_splats;

int cdl_splats_add(cdl_splats *sp, uint32_t pixel, cdl_vec3 L);
/* A contribution at raster point (x, y) of a w x h image spread over the
 * pixels around it by the pixel filter (cdl_filter_spread). */
int cdl_splats_add_filtered(cdl_splats *sp, const cdl_filter *f, int w, int h, float x, float y, cdl_vec3 L);
void cdl_splats_free(cdl_splats *sp);
/* Adds sp to the film's splat buffer (allocating it) and empties sp.
 * Returns the number of non-finite splats dropped. */
uint64_t cdl_film_merge_splats(cdl_film *f, cdl_splats *sp);

int cdl_film_init(cdl_film *f, int width, int height, cdl_error *err);
void cdl_film_free(cdl_film *f);

/* Adds one sample to pixel (x, y); returns 1 if it was non-finite and so
 * counted as black (the caller sums those up into f->nonfinite). */
static inline int cdl_film_add(cdl_film *f, int x, int y, cdl_vec3 L)
{
    size_t i = (size_t)y * (size_t)f->width + (size_t)x;
    f->count[i]++;
    if (!cdl_is_finite3(L))
        return 1;
    f->sum[3 * i] += L.x;
    f->sum[3 * i + 1] += L.y;
    f->sum[3 * i + 2] += L.z;
    return 0;
}

/* Average per pixel into img (allocated here). */
int cdl_film_resolve(const cdl_film *f, cdl_image *img, cdl_error *err);

/* The film's accumulators (sums, sample counts, light-tracing splats,
 * counters, AOV sums) as one vector of doubles: the vectors of renders of
 * disjoint passes add up to the vector of all those passes (distributed
 * rendering reduces them). _set checks the counts it is given. */
size_t cdl_film_accum_size(const cdl_film *f);
void cdl_film_accum_get(const cdl_film *f, double *out);
int cdl_film_accum_set(cdl_film *f, const double *in, cdl_error *err);

#endif
