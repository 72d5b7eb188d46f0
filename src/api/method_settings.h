/* The options of pm, gkde and splat, by their command-line names ("--photons").
 * Each kind function says whether o is one of the method's options: 1 with
 * a value, 2 a flag without one (pm only), 0 not. */
#ifndef CDL_METHOD_SETTINGS_H
#define CDL_METHOD_SETTINGS_H

#include "integrators/integrator.h"

int cdl_pm_arg_kind(const char *o);
/* Parses option o (value v, NULL for flags) into pm. */
int cdl_pm_arg(const char *o, const char *v, cdl_pm_options *pm, cdl_error *err);
/* Checks that combine several options. */
int cdl_pm_args_check(const cdl_pm_options *pm, cdl_error *err);

int cdl_gkde_arg_kind(const char *o);
int cdl_gkde_arg(const char *o, const char *v, cdl_gkde_options *g, cdl_error *err);

int cdl_splat_arg_kind(const char *o);
int cdl_splat_arg(const char *o, const char *v, cdl_splat_options *sp, cdl_error *err);

#endif
