/* Shading frames of the surface (Mitsuba's conventions): the tangent
 * along dp/du, bump and normal maps, and the textured parts of a BSDF
 * beyond kd. cdl_surface_shade is declared in scene.h. */
#ifndef CDL_SHADING_H
#define CDL_SHADING_H

#include "scene/scene.h"

/* After cdl_bsdf_init: textured roughness and the frame of sf (its
 * tangent, and the unperturbed normal the perturbed BSDF checks). */
void cdl_scene_bsdf_maps(const cdl_scene *s, const cdl_material *m, const cdl_surface *sf, cdl_bsdf *b);

/* The normal of a bump map in the local frame (s, t, n) of the unperturbed
 * shading frame: Mitsuba's bumpmap perturbation, unnormalized. grad is the
 * height's uv gradient times the map's scale; ng the geometric normal. */
cdl_vec3 cdl_bump_normal(cdl_vec3 dpdu, cdl_vec3 dpdv, const float grad[2], cdl_vec3 s, cdl_vec3 t, cdl_vec3 n,
                         cdl_vec3 ng);

#endif
