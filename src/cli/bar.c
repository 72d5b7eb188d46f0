#define _POSIX_C_SOURCE 200809L
#include <time.h>
#include <unistd.h>

#include "cli.h"

double cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_bar_begin(cli_bar *b, int quiet)
{
    b->start = cli_now();
    b->last = 0.0;
    b->active = !quiet && isatty(STDERR_FILENO);
    b->drawn = 0;
}

/* Redraws at most 10 times per second. */
void cli_bar_update(cli_bar *b, double frac, double el, const char *label)
{
    if (!b->active)
        return;
    double t = cli_now();
    if (t - b->last < 0.1 && frac < 1.0)
        return;
    b->last = t;
    frac = frac < 0.0 ? 0.0 : frac > 1.0 ? 1.0 : frac;
    enum { W = 40 };
    char bar[W + 1];
    int fill = (int)(frac * W + 0.5);
    for (int i = 0; i < W; i++)
        bar[i] = i < fill ? '#' : '.';
    bar[W] = 0;
    double eta = frac > 0.0 ? el / frac - el : 0.0;
    fprintf(stderr, "\r[%s] %5.1f%%  %s  %.1fs elapsed, %.1fs left  ", bar, 100.0 * frac, label ? label : "", el,
            eta);
    fflush(stderr);
    b->drawn = 1;
}

void cli_bar_end(cli_bar *b)
{
    if (b->active && b->drawn)
        fprintf(stderr, "\r%*s\r", 100, "");
    b->drawn = 0;
}
