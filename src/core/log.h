/* Messages on stderr: warnings about input that is used anyway, and a
 * progress bar when stderr is a terminal. */
#ifndef CDL_LOG_H
#define CDL_LOG_H

#include <stdint.h>

extern int cdl_log_quiet; /* suppresses warnings and the progress bar */

void cdl_warn(const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

typedef struct cdl_progress {
    double start; /* cdl_time_now() at start */
    double last;  /* time of the last redraw */
    int active;   /* 0 when stderr is not a terminal */
    int drawn;
} cdl_progress;

double cdl_time_now(void); /* monotonic seconds */
void cdl_progress_begin(cdl_progress *p);
/* frac in [0,1]; label is printed after the bar (e.g. "12 spp"). Redraws at
 * most 10 times per second. */
void cdl_progress_update(cdl_progress *p, double frac, const char *label);
void cdl_progress_end(cdl_progress *p);

#endif
