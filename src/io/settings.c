#include "io/settings.h"

#include <stdio.h>
#include <string.h>

#include "core/log.h"

void cdl_scene_settings_init(cdl_scene_settings *set)
{
    memset(set, 0, sizeof *set);
    set->maxdepth = -1;
    cdl_filter_box(&set->filter);
}

void cdl_scene_settings_param(cdl_scene_settings *set, const char *name, const char *value, const char *file,
                              int line)
{
    if (set->nparams == CDL_MAX_SCENE_PARAMS) {
        cdl_warn(file, line, "more than %d integrator parameters: \"%s\" ignored", CDL_MAX_SCENE_PARAMS, name);
        return;
    }
    cdl_scene_param *p = &set->params[set->nparams++];
    snprintf(p->name, sizeof p->name, "%s", name);
    snprintf(p->value, sizeof p->value, "%s", value);
    snprintf(p->file, sizeof p->file, "%s", file);
    p->line = line;
}
