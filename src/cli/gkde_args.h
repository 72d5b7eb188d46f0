/* Command-line options of the gkde integrator. */
#ifndef CDL_GKDE_ARGS_H
#define CDL_GKDE_ARGS_H

#include "integrators/integrator.h"

/* 1 if o is a gkde option (all take a value), else 0. */
int cdl_gkde_arg_kind(const char *o);
/* Parses option o with value v into g. */
int cdl_gkde_arg(const char *o, const char *v, cdl_gkde_options *g, cdl_error *err);
/* The gkde part of --help. */
void cdl_gkde_args_help(void);

#endif
