/* The parameters a user can set, listed from the common table and every
 * method's (the command's help, the README's tables and the Python
 * package's discovery read this list), the integrators and the version. */
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "api/settings.h"

#define STR2(x) #x
#define STR(x) STR2(x)

const char *cdl_version(void)
{
    return STR(CDL_VERSION_MAJOR) "." STR(CDL_VERSION_MINOR) "." STR(CDL_VERSION_PATCH);
}

/* The list cdl_option_get hands out, built once from the tables. */
#define MAX_OPTIONS 256
static cdl_option_info options[MAX_OPTIONS];
static char methods[MAX_OPTIONS][64];
static int noptions;
static pthread_once_t once = PTHREAD_ONCE_INIT;

static const char *type_name(const cdl_param *p)
{
    static const char *names[] = {"int", "float", "switch", "choice", "floats", "res", "name"};
    return names[p->type];
}

static void add(const cdl_param *p, const char *section, const cdl_param_table *t)
{
    if (noptions == MAX_OPTIONS)
        return; /* a test checks the count against the tables */
    int k = noptions++;
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); t && *it; it++)
        for (const cdl_param_table *const *u = (*it)->params; u && *u; u++)
            if (*u == t) {
                size_t n = strlen(methods[k]);
                snprintf(methods[k] + n, sizeof methods[k] - n, "%s%s", n ? "," : "", (*it)->name);
            }
    options[k] = (cdl_option_info){p->name,
                                   p->meta,
                                   methods[k],
                                   p->def,
                                   p->help,
                                   section,
                                   type_name(p),
                                   p->min,
                                   p->max,
                                   !!(p->flags & CDL_PARAM_OPEN_MIN),
                                   !!(p->flags & CDL_PARAM_OPEN_MAX),
                                   p->choices ? p->choices : "",
                                   p->unit ? p->unit : "",
                                   !!(p->flags & (CDL_PARAM_REPEAT | CDL_PARAM_BITS))};
}

static void build(void)
{
    for (int i = 0; i < cdl_common_table.count; i++)
        add(&cdl_common_table.rows[i], cdl_common_table.title, NULL);
    const cdl_integrator_vtbl *const *all = cdl_integrator_list();
    for (int m = 0; all[m]; m++)
        for (const cdl_param_table *const *t = all[m]->params; t && *t; t++) {
            int seen = 0; /* a shared table: listed where it first appears */
            for (int e = 0; e < m && !seen; e++)
                for (const cdl_param_table *const *u = all[e]->params; u && *u; u++)
                    seen |= *u == *t;
            for (int i = 0; !seen && i < (*t)->count; i++)
                add(&(*t)->rows[i], (*t)->title, *t);
        }
}

int cdl_option_count(void)
{
    pthread_once(&once, build);
    return noptions;
}

const cdl_option_info *cdl_option_get(int i)
{
    return i >= 0 && i < cdl_option_count() ? &options[i] : NULL;
}

int cdl_integrator_count(void)
{
    int n = 0;
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); *it; it++)
        n++;
    return n;
}

const char *cdl_integrator_name(int i)
{
    return i >= 0 && i < cdl_integrator_count() ? cdl_integrator_list()[i]->name : NULL;
}

const char *cdl_integrator_summary(int i)
{
    return i >= 0 && i < cdl_integrator_count() ? cdl_integrator_list()[i]->summary : NULL;
}
