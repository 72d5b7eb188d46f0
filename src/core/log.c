#define _POSIX_C_SOURCE 200809L
#include "core/log.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

int cdl_log_quiet = 0;

void cdl_warn(const char *file, int line, const char *fmt, ...)
{
    if (cdl_log_quiet)
        return;
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
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

void cdl_progress_begin(cdl_progress *p)
{
    p->start = cdl_time_now();
    p->last = 0.0;
    p->active = !cdl_log_quiet && isatty(STDERR_FILENO);
    p->drawn = 0;
}

void cdl_progress_update(cdl_progress *p, double frac, const char *label)
{
    if (!p->active)
        return;
    double now = cdl_time_now();
    if (now - p->last < 0.1 && frac < 1.0)
        return;
    p->last = now;
    if (frac < 0.0)
        frac = 0.0;
    if (frac > 1.0)
        frac = 1.0;
    enum { W = 40 };
    char bar[W + 1];
    int fill = (int)(frac * W + 0.5);
    for (int i = 0; i < W; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[W] = 0;
    double el = now - p->start;
    double eta = frac > 0.0 ? el / frac - el : 0.0;
    fprintf(stderr, "\r[%s] %5.1f%%  %s  %.1fs elapsed, %.1fs left  ", bar, 100.0 * frac,
            label ? label : "", el, eta);
    fflush(stderr);
    p->drawn = 1;
}

void cdl_progress_end(cdl_progress *p)
{
    if (p->active && p->drawn)
        fprintf(stderr, "\r%*s\r", 100, "");
    p->drawn = 0;
}
