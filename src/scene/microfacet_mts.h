/* Mitsuba 3's microfacet distributions (its render/microfacet.h): Beckmann
 * or GGX, anisotropic, Smith's *separable* masking-shadowing G1(wi) G1(wo)
 * (not the height-correlated form of microfacet.h) with Beckmann's G1 as
 * Mitsuba's rational fit, and visible-normal sampling in slope space
 * (Heitz & d'Eon 2014; Jakob's numeric inversion for Beckmann, Heitz 2018
 * for GGX). Local frame, z = normal. Models read from Mitsuba files use it
 * so that they reflect what Mitsuba's do, sample for sample. */
#ifndef CDL_MICROFACET_MTS_H
#define CDL_MICROFACET_MTS_H

#include "core/vec.h"

/* CDL_MF_PBRT (0, the default of a zeroed material): pbrt's GGX with
 * height-correlated masking (microfacet.h); the others are Mitsuba's. */
typedef enum cdl_mf_type { CDL_MF_PBRT = 0, CDL_MF_GGX = 1, CDL_MF_BECKMANN = 2 } cdl_mf_type;

typedef struct cdl_mf {
    cdl_mf_type type;
    float ax, ay; /* clamped to >= 1e-4, as Mitsuba's */
} cdl_mf;

static inline cdl_mf cdl_mf_make(cdl_mf_type type, float ax, float ay)
{
    cdl_mf d = {type, cdl_maxf(ax, 1e-4f), cdl_maxf(ay, 1e-4f)};
    return d;
}

/* D(m); 0 where D cos(m) underflows below 1e-20 (Mitsuba's guard). */
float cdl_mf_D(const cdl_mf *d, cdl_vec3 m);
/* Smith's G1 of direction v for microfacet m; 0 when v sees m's back. */
float cdl_mf_G1(const cdl_mf *d, cdl_vec3 v, cdl_vec3 m);
/* A microfacet normal visible from wi (wi.z > 0), two uniform numbers. */
cdl_vec3 cdl_mf_sample_vndf(const cdl_mf *d, cdl_vec3 wi, float u1, float u2);
/* Its density: D(m) G1(wi, m) |wi.m| / wi.z. */
float cdl_mf_pdf_vndf(const cdl_mf *d, cdl_vec3 wi, cdl_vec3 m);

/* Single-precision inverse error function (Giles 2010). */
float cdl_erfinvf(float x);

/* Gauss-Legendre nodes and weights on [-1, 1], n <= 256. */
void cdl_gauss_legendre(int n, double *nodes, double *weights);

#endif
