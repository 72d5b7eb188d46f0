/* Which eye samples may hide others this pass: the visibility mask's
 * occluders (hiders.c; mask.c builds their tree and rasterizes them). */
#ifndef CDL_SPLAT_HIDERS_H
#define CDL_SPLAT_HIDERS_H

#include "integrators/splat/state.h"

/* Per sample q of t (tree order; pw its footprints) into side[q] the
 * sides of its tangent plane from which it may hide another sample: bit 0
 * when some ray origin lies in front of the plane by more than pw[q] and
 * some sample behind it by more than its own footprint, bit 1 the same
 * with the sides swapped. scale: the coordinates' largest magnitude (the
 * planes' rounding margin: more hiders, never fewer). Returns how many
 * samples have a side, or -1 out of memory. */
int64_t splat_hiders(const cdl_skd *t, const float *pw, const cdl_photon_ray *rays, uint32_t nrays, float scale,
                     uint8_t *side);

#endif
