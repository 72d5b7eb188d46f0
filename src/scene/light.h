/* Lights: triangle area lights (emissive MTL materials, front face only)
 * and point lights. One interface for next-event estimation (sample a
 * point towards a receiver) and for light paths (sample an emitted ray). */
#ifndef CDL_LIGHT_H
#define CDL_LIGHT_H

#include <stdint.h>

#include "core/vec.h"

typedef enum cdl_light_type { CDL_LIGHT_TRIANGLE, CDL_LIGHT_POINT } cdl_light_type;

typedef struct cdl_light {
    cdl_light_type type;
    cdl_vec3 p;      /* triangle vertex 0, or the point light's position */
    cdl_vec3 e1, e2; /* triangle edges p1 - p0, p2 - p0 */
    cdl_vec3 n;      /* triangle front (CCW) unit normal */
    float area;
    cdl_vec3 L;      /* radiance (triangle) or intensity in W/sr (point) */
    uint32_t prim;   /* triangle index in the scene */
} cdl_light;

typedef struct cdl_light_sample {
    cdl_vec3 p;    /* point on the light */
    cdl_vec3 wi;   /* unit direction from the receiver to p */
    float dist;    /* distance receiver to p */
    cdl_vec3 Li;   /* radiance (area) or intensity / dist^2 (point) arriving */
    float pdf;     /* solid angle density at the receiver; 1 for delta lights */
    int delta;
} cdl_light_sample;

typedef struct cdl_light_emit {
    cdl_vec3 p, n, d; /* origin, normal there (0 for points), direction */
    cdl_vec3 Le;      /* radiance (area) or intensity (point) along d */
    float pdf_pos;    /* area density of p (1 for points) */
    float pdf_dir;    /* solid angle density of d */
} cdl_light_emit;

/* Returns 0 if the sample carries no light (back face, degenerate). */
int cdl_light_sample_li(const cdl_light *l, cdl_vec3 ref, float u1, float u2,
                        cdl_light_sample *s);
/* Solid-angle density of cdl_light_sample_li choosing point p (area lights). */
float cdl_light_pdf_li(const cdl_light *l, cdl_vec3 ref, cdl_vec3 p);
int cdl_light_sample_le(const cdl_light *l, float u1, float u2, float u3, float u4,
                        cdl_light_emit *e);
/* Emitted flux (RGB), for power-proportional light selection. */
cdl_vec3 cdl_light_power(const cdl_light *l);

#endif
