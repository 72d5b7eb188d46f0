/* splat's image-space filtering (Herzog et al. 2007, §6.2): the
 * discontinuity buffer (view depth and normal per pixel) cut into surface
 * segments; each radiance image (the irradiance of every pixel, and the
 * strata or SH coefficients of non-Lambertian pixels) averaged per pixel
 * over a box of its own segment, through summed-area tables, before the
 * BSDF is applied. The box is the smallest holding filter photon splats
 * (the pixels' splat counts summed over it): narrow where photons are
 * dense, wide where they are few, as k nearest neighbours would be. A
 * pixel's eye samples all take its filtered value. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/vec.h"
#include "film/segments.h"
#include "integrators/splat/filter.h"

/* Filters nc channels per pixel, gathered from the samples with
 * take(q) as the mean of each pixel's, and scattered back. */
static int filter_image(splat_state *s, const cdl_segments *sg, const uint8_t *rad, int nc, int glossy,
                        cdl_error *err)
{
    size_t npix = (size_t)sg->w * (size_t)sg->h;
    float *img = calloc(npix * (size_t)nc, sizeof(float)), *n = calloc(npix, sizeof(float));
    uint8_t *use = calloc(npix, 1);
    int rc = 0;
    if (!img || !n || !use) {
        rc = cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the filter");
        goto done;
    }
    for (uint32_t q = 0; q < s->neye; q++) {
        uint32_t g = s->gloss[q];
        if (glossy && g == SPLAT_LAMBERT)
            continue;
        size_t p = s->eye[q].pixel;
        float *dst = img + p * (size_t)nc;
        if (glossy) {
            for (int k = 0; k < (int)s->K; k++)
                for (int c = 0; c < 3; c++)
                    dst[3 * k + c] += splat_gmap_at(s, g, k)[c];
        } else {
            for (int c = 0; c < 3; c++)
                dst[c] += s->E[c][q];
        }
        n[p] += 1.0f;
    }
    for (size_t p = 0; p < npix; p++) {
        use[p] = n[p] > 0.0f;
        for (int c = 0; c < nc && n[p] > 1.0f; c++)
            img[p * (size_t)nc + c] /= n[p];
    }
    rc = cdl_segment_filter(sg, img, nc, use, rad, err);
    if (rc)
        goto done;
    for (uint32_t q = 0; q < s->neye; q++) {
        uint32_t g = s->gloss[q];
        if (glossy && g == SPLAT_LAMBERT)
            continue;
        const float *src = img + (size_t)s->eye[q].pixel * (size_t)nc;
        if (glossy) {
            for (int k = 0; k < (int)s->K; k++)
                for (int c = 0; c < 3; c++)
                    splat_gmap_at(s, g, k)[c] = src[3 * k + c];
        } else {
            for (int c = 0; c < 3; c++)
                s->E[c][q] = src[c];
        }
    }
done:
    free(img);
    free(n);
    free(use);
    return rc;
}

int splat_filter(splat_state *s, cdl_error *err)
{
    const cdl_splat_options *o = &s->opt.splat;
    if (!(o->filter > 0.0f))
        return 0;
    const cdl_camera *cam = &s->opt.camera;
    size_t npix = (size_t)cam->width * (size_t)cam->height;
    cdl_segments sg;
    int rc = cdl_segment(&sg, cam->width, cam->height, s->dz, s->dn, cosf(o->filter_normal * (float)(CDL_PI / 180.0)),
                         o->filter_depth, err);
    if (rc)
        return rc;
    float *count = calloc(npix, sizeof(float));
    uint8_t *rad = malloc(npix ? npix : 1);
    if (!count || !rad) {
        rc = cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the filter");
    } else {
        for (uint32_t q = 0; q < s->neye; q++)
            count[s->eye[q].pixel] += s->nsum[q];
        /* a box holding N splats grows as the kernels shrink with the
         * passes (splats per sample ~ h^2); N h^4 makes it shrink as the
         * kernels do instead, so the average converges */
        double b2 = s->pp.bw_scale * s->pp.bw_scale;
        float want = o->filter * (float)(b2 * b2);
        rc = cdl_segment_support(&sg, count, want, o->filter_max, rad, err);
        if (!rc)
            rc = filter_image(s, &sg, rad, 3, 0, err);
        if (!rc && s->nglossy)
            rc = filter_image(s, &sg, rad, 3 * (int)s->K, 1, err);
    }
    s->st.segments += sg.n;
    free(count);
    free(rad);
    cdl_segments_free(&sg);
    return rc;
}
