#include "api/parse.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

int cdl_arg_int(const char *opt, const char *s, long lo, long hi, long *out, cdl_error *err)
{
    char *end;
    errno = 0;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || end == s || *end || errno || v < lo || v > hi)
        return cdl_error_set(err, CDL_ERR_USAGE, opt, 0, "expected an integer in [%ld, %ld], got '%s'",
                             lo, hi, s ? s : "");
    *out = v;
    return 0;
}

int cdl_arg_float(const char *opt, const char *s, double lo, double hi, double *out, cdl_error *err)
{
    char *end;
    errno = 0;
    double v = s ? strtod(s, &end) : 0.0;
    if (!s || end == s || *end || errno || !isfinite(v) || v < lo || v > hi)
        return cdl_error_set(err, CDL_ERR_USAGE, opt, 0, "expected a number in [%g, %g], got '%s'", lo,
                             hi, s ? s : "");
    *out = v;
    return 0;
}

int cdl_arg_floats(const char *opt, const char *s, int n, float *out, cdl_error *err)
{
    const char *p = s;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        double v = strtod(p, &end);
        if (end == p || errno || !isfinite(v) || fabs(v) > 1e20 ||
            (i < n - 1 ? *end != ',' : *end != 0))
            return cdl_error_set(err, CDL_ERR_USAGE, opt, 0,
                                 "expected %d comma-separated finite numbers, got '%s'", n, s);
        out[i] = (float)v;
        p = end + 1;
    }
    return 0;
}

int cdl_arg_res(const char *opt, const char *s, int max, int *w, int *h, cdl_error *err)
{
    char *end;
    errno = 0;
    long a = strtol(s, &end, 10);
    if (end != s && (*end == 'x' || *end == 'X') && !errno) {
        const char *q = end + 1;
        long b = strtol(q, &end, 10);
        if (end != q && !*end && !errno && a >= 1 && a <= max && b >= 1 && b <= max) {
            *w = (int)a;
            *h = (int)b;
            return 0;
        }
    }
    return cdl_error_set(err, CDL_ERR_USAGE, opt, 0, "expected WIDTHxHEIGHT with each in [1, %d], got '%s'",
                         max, s);
}
