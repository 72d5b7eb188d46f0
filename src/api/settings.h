/* The settings object of the public API: the common parameters parsed as
 * they are set, the method's kept as given until the method is known
 * (from the settings or the scene file) and read through its tables. */
#ifndef CDL_SETTINGS_H
#define CDL_SETTINGS_H

#include "core/common_params.h"
#include "core/log.h"
#include "integrators/integrator.h"

#define CDL_MAX_GIVEN 128

typedef struct cdl_given {
    char name[32];
    char value[224];
} cdl_given;

struct cdl_settings {
    cdl_common_params c;
    uint32_t given_common;           /* bit i: row i of cdl_common_table was set */
    cdl_given method[CDL_MAX_GIVEN]; /* the method's parameters, in the order set */
    int nmethod;
    cdl_log_sink sink; /* warnings of loads and renders with these settings */
};

/* Whether the common parameter called name was set explicitly. */
int cdl_settings_given(const cdl_settings *s, const char *name);

/* The row of method vt (NULL: any method) called name, or NULL. */
const cdl_param *cdl_method_param(const cdl_integrator_vtbl *vt, const char *name);

/* Reads s's method parameters into opt through vt's tables: one vt does not
 * read is a usage error naming both. */
int cdl_settings_apply(const cdl_settings *s, const cdl_integrator_vtbl *vt, cdl_options *opt, cdl_error *err);

#endif
