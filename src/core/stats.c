#include "core/stats.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void cdl_stats_add(cdl_stats *s, const char *name, double value)
{
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->v[i].name, name)) {
            s->v[i].value = value;
            return;
        }
    if (s->n == CDL_MAX_STATS)
        return;
    snprintf(s->v[s->n].name, sizeof s->v[s->n].name, "%s", name);
    s->v[s->n++].value = value;
}

void cdl_stats_printf(cdl_stats *s, const char *fmt, ...)
{
    if (s->len + 1 >= sizeof s->text)
        return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(s->text + s->len, sizeof s->text - s->len, fmt, ap);
    va_end(ap);
    if (k > 0)
        s->len = s->len + (size_t)k < sizeof s->text ? s->len + (size_t)k : sizeof s->text - 1;
}
