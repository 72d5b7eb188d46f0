#define _POSIX_C_SOURCE 200809L
#include "core/log.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>

static _Thread_local const cdl_log_sink *current;

const cdl_log_sink *cdl_log_push(const cdl_log_sink *sink)
{
    const cdl_log_sink *prev = current;
    current = sink;
    return prev;
}

void cdl_log_pop(const cdl_log_sink *prev)
{
    current = prev;
}

int cdl_log_quiet(void)
{
    return current && current->quiet;
}

void cdl_warn(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_vwarn(file, line, fmt, ap);
    va_end(ap);
}

void cdl_vwarn(const char *file, int line, const char *fmt, va_list ap)
{
    if (cdl_log_quiet())
        return;
    char msg[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (current && current->fn) {
        current->fn(current->user, file ? file : "", file && file[0] ? line : 0, msg);
        return;
    }
    if (file && file[0] && line > 0)
        fprintf(stderr, "candela: warning: %s:%d: %s\n", file, line, msg);
    else if (file && file[0])
        fprintf(stderr, "candela: warning: %s: %s\n", file, msg);
    else
        fprintf(stderr, "candela: warning: %s\n", msg);
}

double cdl_time_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
