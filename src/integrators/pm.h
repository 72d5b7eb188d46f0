/* The photon setup of pm's passes, shared with `candela photons` so that
 * its pictures show exactly the maps pm renders with. */
#ifndef CDL_PM_H
#define CDL_PM_H

#include "integrators/integrator.h"
#include "transport/photons.h"

/* The radiance estimate's maximum radius: max_radius, or 5 % of the
 * scene's diagonal; an error for a scene without extent. */
int cdl_pm_max_radius(const cdl_scene *s, const cdl_pm_options *o, float *r, cdl_error *err);

/* Deposition parameters from the options; with importance, traces the
 * importons into imp (free with cdl_importance_free) and points pp at it. */
int cdl_pm_photon_setup(const cdl_scene *s, const cdl_options *opt, const cdl_walk *walk, float max_radius,
                        cdl_photon_params *pp, cdl_importance *imp, cdl_error *err);

#endif
