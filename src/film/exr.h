/* OpenEXR reading and writing, internal to src/film (use image.h). */
#ifndef CDL_EXR_H
#define CDL_EXR_H

#include "film/image.h"

/* Writes to file; errors name `name` (the final path, not the temp file). */
int cdl_exr_write(const char *file, const char *name, const cdl_image *img,
                  const cdl_layer *layers, int nlayers, const cdl_kv *meta, int nmeta,
                  cdl_error *err);
int cdl_exr_read(const char *path, cdl_image *img, cdl_error *err);

#endif
