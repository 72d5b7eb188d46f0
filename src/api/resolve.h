/* Settings resolved against a scene into the options of a render. */
#ifndef CDL_RESOLVE_H
#define CDL_RESOLVE_H

#include "api/settings.h"

/* out: in with the scene file's integrator, resolution, max depth and spp
 * where in left them open; opt: the method's options, camera placed. */
int cdl_settings_resolve(const cdl_settings *in, const cdl_scene *scene, cdl_settings *out, cdl_options *opt,
                         cdl_error *err);

#endif
