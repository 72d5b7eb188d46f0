#ifndef CDL_SPLAT_FILTER_H
#define CDL_SPLAT_FILTER_H

#include "integrators/splat/state.h"

/* Filters the maps in image space within surface segments (§6.2, filter.c). */
int splat_filter(splat_state *s, cdl_error *err);

#endif
