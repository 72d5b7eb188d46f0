/* The first non-specular point a camera ray sees: the ray follows ideal
 * specular reflection and refraction (a Fresnel choice at dielectrics,
 * drawn from the sampler) and collects the emission it meets on the way.
 * Shared by the methods that estimate at that point (pm's direct
 * visualization and final gathering, splat's eye samples). */
#ifndef CDL_VISIBLE_H
#define CDL_VISIBLE_H

#include "core/sampler.h"
#include "scene/bsdf.h"
#include "scene/scene.h"

typedef struct cdl_visible {
    cdl_vec3 L;    /* emission met on the way, weighted (the point's own included) */
    cdl_vec3 beta; /* weight of the specular chain up to the point */
    cdl_surface sf;
    cdl_bsdf b;
    cdl_vec3 wo;   /* unit direction back along the ray */
    int depth;     /* specular bounces before the point (or before the ray left the scene) */
    float dist;    /* length of the chain from the ray's origin to the point */
} cdl_visible;

/* 1 if the ray from o along d reaches a non-specular point with fewer
 * than maxdepth bounces before it (v describes it); 0 if it escapes, is
 * absorbed or runs out of bounces (v->L holds what it collected). */
int cdl_find_visible(const cdl_scene *s, cdl_vec3 o, cdl_vec3 d, int maxdepth, cdl_sampler *smp, uint64_t *rays,
                     cdl_visible *v);

#endif
