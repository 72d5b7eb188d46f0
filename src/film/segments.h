/* Discontinuity-preserving filtering in image space (Herzog et al. 2007,
 * §6.2): a discontinuity buffer (per pixel the distance along the camera
 * ray and the normal of the surface seen) is cut into segments, the
 * continuous surfaces, by region growing; a box filter then averages each
 * pixel over the pixels of its own segment within a per-pixel support,
 * through summed-area tables built per segment, so no filter mixes two
 * surfaces. Used by splat for its radiance images and radiance cache. */
#ifndef CDL_SEGMENTS_H
#define CDL_SEGMENTS_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_seg_rect {
    int x0, y0, x1, y1; /* bounding rectangle [x0, x1) x [y0, y1) */
} cdl_seg_rect;

typedef struct cdl_segments {
    int w, h;
    int32_t *id; /* per pixel: its segment, -1 where the buffer has no surface */
    uint32_t n;
    cdl_seg_rect *rect;
} cdl_segments;

/* depth: per pixel the distance along the camera's view axis (on a plane
 * 1 / depth is affine in the image), <= 0 or non-finite where no surface
 * is seen. Neighbouring pixels (4-neighbourhood) join one segment when
 * their normals differ by less than acos(cos_max) and the second
 * difference of 1 / depth across them (the change of slope; the first
 * difference, 4x looser, where no third pixel is at hand) is below
 * depth_tol times 1 / depth. */
int cdl_segment(cdl_segments *sg, int w, int h, const float *depth, const cdl_vec3 *normal, float cos_max,
                float depth_tol, cdl_error *err);
void cdl_segments_free(cdl_segments *sg);

/* Per pixel the half-width r (0..rmax) of the smallest box whose pixels
 * of the pixel's segment hold a total count >= target (rmax if none). */
int cdl_segment_support(const cdl_segments *sg, const float *count, double target, int rmax, uint8_t *radius,
                        cdl_error *err);

/* Filters nc channels in place (img[p * nc + c]): pixel p (with use[p],
 * NULL: every pixel of a segment) becomes the mean of the pixels q of its
 * segment with use[q] in the box of half-width radius[p] around it. */
int cdl_segment_filter(const cdl_segments *sg, float *img, int nc, const uint8_t *use, const uint8_t *radius,
                       cdl_error *err);

#endif
