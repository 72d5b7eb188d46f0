/* Mitsuba's binary grid volume files (".vol", version 3), as its gridvolume
 * texture and sdfgrid shape read them: the bytes "VOL", a version byte 3,
 * int32 encoding (1 = float32, the only one Mitsuba 3 reads), int32 x, y
 * and z resolutions, int32 channel count, six floats of bounding box (min,
 * max), then the samples with the channel fastest, then x, y and z:
 * data[((z * yres + y) * xres + x) * channels + c]. Little-endian. */
#ifndef CDL_VOL_H
#define CDL_VOL_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

typedef struct cdl_vol {
    int32_t res[3]; /* x, y, z */
    int32_t channels;
    float bbox[6];
    float *data; /* res[0] * res[1] * res[2] * channels floats */
} cdl_vol;

/* Reads path into v (zeroed on failure). Refuses a file that is not
 * version 3 float32, has another channel count than `channels` (when > 0),
 * a resolution below min_res or more than max_samples samples, a length
 * other than the header's, or a non-finite sample. Errors name the file
 * (line 0) and the problem. */
int cdl_vol_read(const char *path, int channels, int min_res, size_t max_samples, cdl_vol *v, cdl_error *err);

void cdl_vol_free(cdl_vol *v);

#endif
