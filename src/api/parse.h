/* Checked parsing of option values: every number is validated and
 * an error names the option, the accepted range and what was given. */
#ifndef CDL_PARSE_H
#define CDL_PARSE_H

#include <stdint.h>

#include "core/error.h"

int cdl_arg_int(const char *opt, const char *s, long lo, long hi, long *out, cdl_error *err);
int cdl_arg_float(const char *opt, const char *s, double lo, double hi, double *out, cdl_error *err);
/* Exactly n comma-separated finite numbers. */
int cdl_arg_floats(const char *opt, const char *s, int n, float *out, cdl_error *err);
/* "WxH", each in [1, max]. */
int cdl_arg_res(const char *opt, const char *s, int max, int *w, int *h, cdl_error *err);

#endif
