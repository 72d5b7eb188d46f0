/* Parameter lists of pbrt directives ("type name" [values]), checked as
 * they are read: known type, value kinds, counts, finite numbers within
 * CDL_MAX_COORD, integral integers. Lookups are typed and mark the
 * parameter used, so the loader can warn about the ones it ignored. */
#ifndef CDL_PBRT_PARAMS_H
#define CDL_PBRT_PARAMS_H

#include <stddef.h>

#include "core/error.h"
#include "core/vec.h"
#include "io/pbrt_lexer.h"

typedef enum cdl_pbrt_ptype {
    CDL_PT_INT,
    CDL_PT_FLOAT,
    CDL_PT_POINT2,
    CDL_PT_VECTOR2,
    CDL_PT_POINT3,
    CDL_PT_VECTOR3,
    CDL_PT_NORMAL,
    CDL_PT_RGB,
    CDL_PT_XYZ,
    CDL_PT_SPECTRUM,
    CDL_PT_BLACKBODY,
    CDL_PT_BOOL,
    CDL_PT_STRING,
    CDL_PT_TEXTURE
} cdl_pbrt_ptype;

typedef struct cdl_pbrt_param {
    cdl_pbrt_ptype type;
    const char *tname; /* type as written in the file */
    const char *name;
    int line;
    size_t n;          /* number of values */
    size_t off;        /* first value in num[] (numbers, bools as 0/1) or str[] */
    int is_str;        /* values are strings (string, texture, named spectrum) */
    int used;
} cdl_pbrt_param;

typedef struct cdl_pbrt_params {
    const char *file; /* for messages */
    cdl_pbrt_param *p;
    size_t n, cap;
    double *num;
    size_t nnum, capnum;
    const char **str;
    size_t nstr, capstr;
} cdl_pbrt_params;

void cdl_pbrt_params_free(cdl_pbrt_params *ps);
/* Reads "type name" value pairs while the next token is a string. String
 * values point into the lexer's buffer: use them before the file closes. */
int cdl_pbrt_parse_params(cdl_pbrt_lexer *lx, cdl_pbrt_params *ps, cdl_error *err);

/* The last parameter called name (marked used), or NULL. */
cdl_pbrt_param *cdl_pbrt_find(cdl_pbrt_params *ps, const char *name);
static inline const double *cdl_pbrt_nums(const cdl_pbrt_params *ps, const cdl_pbrt_param *p)
{
    return ps->num + p->off;
}
static inline const char *cdl_pbrt_str(const cdl_pbrt_params *ps, const cdl_pbrt_param *p, size_t i)
{
    return ps->str[p->off + i];
}

/* Single values: absent gives def; wrong type or count is an error. */
int cdl_pbrt_get_float(cdl_pbrt_params *ps, const char *name, double def, double *out, cdl_error *err);
int cdl_pbrt_get_int(cdl_pbrt_params *ps, const char *name, int def, int *out, cdl_error *err);
int cdl_pbrt_get_bool(cdl_pbrt_params *ps, const char *name, int def, int *out, cdl_error *err);
/* *out stays def (may be NULL) when absent. */
int cdl_pbrt_get_string(cdl_pbrt_params *ps, const char *name, const char *def, const char **out,
                        cdl_error *err);
/* point3, vector3 or normal: one triple. */
int cdl_pbrt_get_point3(cdl_pbrt_params *ps, const char *name, const double def[3], double out[3],
                        cdl_error *err);
/* A colour from rgb/color, xyz, spectrum (named or sampled), blackbody,
 * or a float (grey). *found (may be NULL) tells whether it was given.
 * A spectrum file (v3 .spd) leaves *out as it was, with a warning. */
int cdl_pbrt_get_spectrum(cdl_pbrt_params *ps, const char *name, cdl_vec3 def, cdl_vec3 *out,
                          int *found, cdl_error *err);
int cdl_pbrt_param_spectrum(cdl_pbrt_params *ps, cdl_pbrt_param *p, cdl_vec3 *out, cdl_error *err);
/* A "float" or "spectrum"/"rgb" scale (pbrt-v4 uses a float, v3 a spectrum). */
int cdl_pbrt_get_scale(cdl_pbrt_params *ps, const char *name, cdl_vec3 *out, cdl_error *err);

/* Warns (file and line) about every parameter no lookup asked for. */
void cdl_pbrt_warn_unused(const cdl_pbrt_params *ps, const char *directive);
const char *cdl_pbrt_type_name(cdl_pbrt_ptype t);

/* ---- spectra (pbrt_spectrum.c) ---- */

/* Named pbrt-v4 spectra ("metal-Cu-eta", "glass-BK7", "stdillum-D65", ...)
 * as RGB constants: returns 0, 1 when only approximated (the caller
 * warns), -1 for unknown names. */
int cdl_pbrt_named_spectrum(const char *name, cdl_vec3 *rgb);
/* Blackbody emission of temperature T in kelvin as linear sRGB, from
 * Planck's law against the CIE 1931 matching functions (10 nm steps).
 * v3: pbrt-v3's BlackbodyNormalized (peak 1), projected as
 * RGBSpectrum::FromSampled does; v4: normalized to luminance Y = 1. */
cdl_vec3 cdl_pbrt_blackbody(double T, int v4);
cdl_vec3 cdl_pbrt_xyz_to_rgb(double x, double y, double z);

#endif
