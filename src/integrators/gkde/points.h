/* gkde's stages 3 to 5 on the eye points (points.c). */
#ifndef CDL_GKDE_POINTS_H
#define CDL_GKDE_POINTS_H

#include "integrators/gkde/state.h"

/* The kd-tree over the eye vertices that can be linked (points in tree
 * order), the per-point arrays and the parts threads own. */
int gkde_build_points(gkde_state *s, cdl_error *err);
/* Stages 3 to 5; returns the shadow rays traced, UINT64_MAX when out of
 * memory for the candidate records. */
uint64_t gkde_link_all(gkde_state *s, uint32_t pass);

#endif
