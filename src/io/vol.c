#define _POSIX_C_SOURCE 200809L
#include "io/vol.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define VOL_HEADER 48 /* "VOL", version, then 5 int32 and 6 floats */

void cdl_vol_free(cdl_vol *v)
{
    if (v) {
        free(v->data);
        memset(v, 0, sizeof *v);
    }
}

static uint32_t le_u32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static int32_t le_i32(const unsigned char *b)
{
    uint32_t u = le_u32(b);
    int32_t i;
    memcpy(&i, &u, sizeof i);
    return i;
}

static float le_f32(const unsigned char *b)
{
    uint32_t u = le_u32(b);
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

__attribute__((format(printf, 5, 6))) static int fail(const char *path, FILE *f, cdl_vol *v, cdl_error *err,
                                                      const char *fmt, ...)
{
    char msg[448];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (f)
        fclose(f);
    cdl_vol_free(v);
    return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "%s", msg);
}

int cdl_vol_read(const char *path, int channels, int min_res, size_t max_samples, cdl_vol *v, cdl_error *err)
{
    memset(v, 0, sizeof *v);
    FILE *f = fopen(path, "rb");
    if (!f)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot open grid volume file");
    struct stat st;
    if (fstat(fileno(f), &st) || !S_ISREG(st.st_mode))
        return fail(path, f, v, err, "not a regular file");
    unsigned char h[VOL_HEADER];
    if (fread(h, 1, sizeof h, f) != sizeof h)
        return fail(path, f, v, err, "truncated header (%lld bytes, a .vol header has %d)", (long long)st.st_size,
                    VOL_HEADER);
    if (memcmp(h, "VOL", 3))
        return fail(path, f, v, err, "not a grid volume file (no \"VOL\" at its start)");
    if (h[3] != 3)
        return fail(path, f, v, err, "version %d, only version 3 is read (as in Mitsuba 3)", h[3]);
    int32_t enc = le_i32(h + 4);
    if (enc != 1)
        return fail(path, f, v, err, "encoding %d, only 1 (float32) is read (as in Mitsuba 3)", (int)enc);
    for (int k = 0; k < 3; k++)
        v->res[k] = le_i32(h + 8 + 4 * k);
    v->channels = le_i32(h + 20);
    for (int k = 0; k < 6; k++)
        v->bbox[k] = le_f32(h + 24 + 4 * k);
    if (v->channels < 1 || (channels > 0 && v->channels != channels))
        return fail(path, f, v, err, "%d channels, %d expected", (int)v->channels, channels > 0 ? channels : 1);
    size_t n = (size_t)v->channels;
    for (int k = 0; k < 3; k++) {
        if (v->res[k] < min_res || (size_t)v->res[k] > max_samples)
            return fail(path, f, v, err, "resolution %d x %d x %d: each must be >= %d", (int)v->res[0],
                        (int)v->res[1], (int)v->res[2], min_res);
        n *= (size_t)v->res[k];
        if (n > max_samples) /* checked per factor, so the product cannot wrap */
            return fail(path, f, v, err, "resolution %d x %d x %d x %d channels: more than %zu samples",
                        (int)v->res[0], (int)v->res[1], (int)v->res[2], (int)v->channels, max_samples);
    }
    if ((unsigned long long)st.st_size != VOL_HEADER + 4ull * n)
        return fail(path, f, v, err, "%lld bytes, its header (%d x %d x %d, %d channels) says %llu",
                    (long long)st.st_size, (int)v->res[0], (int)v->res[1], (int)v->res[2], (int)v->channels,
                    VOL_HEADER + 4ull * n);
    if (!(v->data = malloc(4 * n))) {
        fclose(f);
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory for %zu samples", n);
    }
    if (fread(v->data, 4, n, f) != n)
        return fail(path, f, v, err, "read error");
    fclose(f);
    for (size_t i = 0; i < n; i++) {
        v->data[i] = le_f32((const unsigned char *)(v->data + i));
        if (!isfinite(v->data[i])) {
            size_t c = i % (size_t)v->channels, s = i / (size_t)v->channels, rx = (size_t)v->res[0],
                   ry = (size_t)v->res[1];
            return fail(path, NULL, v, err, "sample (%zu, %zu, %zu) channel %zu is not finite", s % rx, s / rx % ry,
                        s / rx / ry, c);
        }
    }
    return 0;
}
