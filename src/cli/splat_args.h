/* Command-line options of the splat integrator (--photons and --direct
 * are shared with pm and parsed there). */
#ifndef CDL_SPLAT_ARGS_H
#define CDL_SPLAT_ARGS_H

#include "integrators/integrator.h"

/* 1 if o is a splat option (all take a value), else 0. */
int cdl_splat_arg_kind(const char *o);
/* Parses option o with value v into sp. */
int cdl_splat_arg(const char *o, const char *v, cdl_splat_options *sp, cdl_error *err);
/* The splat part of --help. */
void cdl_splat_args_help(void);

#endif
