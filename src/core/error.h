/* Error records: every fallible library function returns an int status
 * (0 = ok) and fills a cdl_error naming the file, the line and the problem.
 * The library never exits; only the CLI decides what an error does. */
#ifndef CDL_ERROR_H
#define CDL_ERROR_H

#include <stdarg.h>
#include <stddef.h>

#include "candela/candela.h"

/* The status codes and struct cdl_error are public (candela.h). */

/* Fills err (which may be NULL) and returns code, so callers can write
 * `return cdl_error_set(err, CDL_ERR_INPUT, path, line, "...")`. */
int cdl_error_set(cdl_error *err, int code, const char *file, int line,
                  const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
int cdl_error_vset(cdl_error *err, int code, const char *file, int line, const char *fmt, va_list ap)
    __attribute__((format(printf, 5, 0)));
/* A reader's call into the scene failed (rc): its message names the scene
 * file `from` without a line; the element at file:line is more useful.
 * Other errors (an image's, a mesh file's) keep their place. Returns rc. */
int cdl_error_place(cdl_error *err, int rc, const char *from, const char *file, int line);


#endif
