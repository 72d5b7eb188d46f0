/* Materials as stored in the scene (one per MTL `newmtl`), before any
 * texture lookup; cdl_bsdf (bsdf.h) is a material evaluated at a hit. */
#ifndef CDL_MATERIAL_H
#define CDL_MATERIAL_H

#include "core/vec.h"

typedef enum cdl_mat_type {
    CDL_MAT_DIFFUSE,   /* Lambert: Kd */
    CDL_MAT_PHONG,     /* Lambert Kd + normalized Phong lobe Ks, exponent Ns */
    CDL_MAT_MIRROR,    /* ideal specular reflection, reflectance Ks */
    CDL_MAT_DIELECTRIC /* smooth glass, index eta */
} cdl_mat_type;

typedef struct cdl_material {
    cdl_mat_type type;
    cdl_vec3 kd;  /* diffuse reflectance, multiplied by the texture */
    int kd_tex;   /* texture index or -1 */
    cdl_vec3 ks;  /* specular reflectance (Phong, mirror) */
    float ns;     /* Phong exponent */
    float eta;    /* index of refraction (dielectric) */
    cdl_vec3 ke;  /* emitted radiance from the front face; 0 = not a light */
    char name[64];
} cdl_material;

#endif
