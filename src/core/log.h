/* Warnings about input that is used anyway. They go to the sink the calling
 * thread has pushed (each API entry point pushes its settings' sink), so two
 * renders in one process keep their messages apart; with none pushed they
 * go to stderr. */
#ifndef CDL_LOG_H
#define CDL_LOG_H

#include <stdarg.h>

#include <stdint.h>

#include "candela/candela.h"

typedef struct cdl_log_sink {
    cdl_message_fn fn; /* NULL: stderr */
    void *user;
    int quiet;         /* drop warnings */
} cdl_log_sink;

/* Routes this thread's warnings to sink (which must outlive the matching
 * pop) and returns the previous sink, to be given to cdl_log_pop. */
const cdl_log_sink *cdl_log_push(const cdl_log_sink *sink);
void cdl_log_pop(const cdl_log_sink *prev);
int cdl_log_quiet(void); /* 1 if this thread's warnings are dropped */

void cdl_warn(const char *file, int line, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
void cdl_vwarn(const char *file, int line, const char *fmt, va_list ap) __attribute__((format(printf, 3, 0)));

double cdl_time_now(void); /* monotonic seconds */

#endif
