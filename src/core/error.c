#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int cdl_error_set(cdl_error *err, int code, const char *file, int line,
                  const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_error_vset(err, code, file, line, fmt, ap);
    va_end(ap);
    return code;
}

int cdl_error_place(cdl_error *err, int rc, const char *from, const char *file, int line)
{
    if (rc && err && err->code == CDL_ERR_INPUT && err->line == 0 && !strcmp(err->file, from)) {
        snprintf(err->file, sizeof err->file, "%s", file);
        err->line = line;
    }
    return rc;
}

int cdl_error_vset(cdl_error *err, int code, const char *file, int line, const char *fmt, va_list ap)
{
    if (!err)
        return code;
    err->code = code;
    err->line = line;
    snprintf(err->file, sizeof err->file, "%s", file ? file : "");
    vsnprintf(err->msg, sizeof err->msg, fmt, ap);
    /* One line per error: a newline in a message (e.g. from a library)
     * would break the contract that an error is a single line. */
    for (char *c = err->msg; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' ';
    return code;
}

void cdl_error_format(const cdl_error *err, char *buf, size_t n)
{
    if (err->file[0] && err->line > 0)
        snprintf(buf, n, "%s:%d: %s", err->file, err->line, err->msg);
    else if (err->file[0])
        snprintf(buf, n, "%s: %s", err->file, err->msg);
    else
        snprintf(buf, n, "%s", err->msg);
}
