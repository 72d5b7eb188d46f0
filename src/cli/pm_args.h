/* Command-line options of the pm integrator (render and photons commands). */
#ifndef CDL_PM_ARGS_H
#define CDL_PM_ARGS_H

#include "integrators/integrator.h"

/* 1 if o is a pm option taking a value, 2 if a flag without one, else 0. */
int cdl_pm_arg_kind(const char *o);
/* Parses option o (value v, NULL for flags) into pm. */
int cdl_pm_arg(const char *o, const char *v, cdl_pm_options *pm, cdl_error *err);
/* Checks that combine several options. */
int cdl_pm_args_check(const cdl_pm_options *pm, cdl_error *err);
/* The pm part of --help. */
void cdl_pm_args_help(void);

#endif
