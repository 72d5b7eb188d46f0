/* RGB image textures (map_Kd), stored linear; sRGB 8-bit files are decoded
 * through the sRGB curve. */
#ifndef CDL_TEXTURE_H
#define CDL_TEXTURE_H

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_texture {
    int w, h;
    float *rgb; /* 3*w*h, top row first */
} cdl_texture;

int cdl_texture_load(cdl_texture *t, const char *path, cdl_error *err);
void cdl_texture_free(cdl_texture *t);
/* Bilinear, repeating; (u,v) as in OBJ: v = 0 is the bottom row. */
cdl_vec3 cdl_texture_lookup(const cdl_texture *t, float u, float v);

#endif
