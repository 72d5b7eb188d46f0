/* Unit vectors in 2 x `bits` bits by the octahedral map (Meyer et al.
 * 2010): photon directions and normals, the eye-sample tree's culling
 * nodes. */
#ifndef CDL_OCTAHEDRAL_H
#define CDL_OCTAHEDRAL_H

#include <stdint.h>

#include "core/vec.h"

uint32_t cdl_oct_encode_bits(cdl_vec3 d, int bits);
cdl_vec3 cdl_oct_decode_bits(uint32_t e, int bits);
/* The decoded direction before normalization (its signs are exact). */
cdl_vec3 cdl_oct_decode_raw(uint32_t e, int bits);

#endif
