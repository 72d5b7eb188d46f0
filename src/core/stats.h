/* What a method reports after rendering: named numbers (for scripts) and
 * the same facts as text lines (for people). */
#ifndef CDL_STATS_H
#define CDL_STATS_H

#include <stddef.h>

#define CDL_MAX_STATS 64

typedef struct cdl_stats {
    int n;
    struct {
        char name[32];
        double value;
    } v[CDL_MAX_STATS];
    char text[8192];
    size_t len;
} cdl_stats;

/* Adds (or replaces) the number called name; beyond CDL_MAX_STATS it is dropped. */
void cdl_stats_add(cdl_stats *s, const char *name, double value);
/* Appends text (truncated when the buffer is full). */
void cdl_stats_printf(cdl_stats *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
