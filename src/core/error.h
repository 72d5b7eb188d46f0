/* Error records: every fallible library function returns an int status
 * (0 = ok) and fills a cdl_error naming the file, the line and the problem.
 * The library never exits; only the CLI decides what an error does. */
#ifndef CDL_ERROR_H
#define CDL_ERROR_H

#include <stddef.h>

enum {
    CDL_OK = 0,
    CDL_ERR_INPUT = 1, /* bad scene file, image or value read from a file */
    CDL_ERR_USAGE = 2, /* bad option value given by the user */
    CDL_ERR_SYSTEM = 3 /* out of memory, I/O failure, device failure */
};

typedef struct cdl_error {
    int code;        /* one of CDL_ERR_* */
    int line;        /* 1-based line in file, 0 when there is none */
    char file[1024]; /* file or option the problem is in, "" if none */
    char msg[512];
} cdl_error;

/* Fills err (which may be NULL) and returns code, so callers can write
 * `return cdl_error_set(err, CDL_ERR_INPUT, path, line, "...")`. */
int cdl_error_set(cdl_error *err, int code, const char *file, int line,
                  const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* "file:line: msg", "file: msg" or "msg". */
void cdl_error_format(const cdl_error *err, char *buf, size_t n);

#endif
