/* The public settings object: parameters by name, each checked when set
 * against the tables that define it (the command line's parser: `candela
 * render` passes its arguments here). */
#include "api/settings.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

cdl_settings *cdl_settings_create(void)
{
    cdl_settings *s = calloc(1, sizeof *s);
    if (s)
        cdl_common_default(&s->c);
    return s;
}

void cdl_settings_release(cdl_settings *s)
{
    free(s);
}

void cdl_settings_set_message_fn(cdl_settings *s, cdl_message_fn fn, void *user)
{
    s->sink.fn = fn;
    s->sink.user = user;
}

int cdl_settings_given(const cdl_settings *s, const char *name)
{
    const cdl_param *p = cdl_param_find(&cdl_common_table, name);
    return p && (s->given_common >> (p - cdl_common_table.rows) & 1u);
}

const cdl_param *cdl_method_param(const cdl_integrator_vtbl *vt, const char *name)
{
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); *it; it++) {
        if (vt && *it != vt)
            continue;
        for (const cdl_param_table *const *t = (*it)->params; t && *t; t++) {
            const cdl_param *p = cdl_param_find(*t, name);
            if (p)
                return p;
        }
    }
    return NULL;
}

/* The library's spelling of name: dashes before it dropped, the others
 * read as '_' ("max_radius" -> "max_radius"). */
static int canonical(const char *name, char *o, size_t n)
{
    while (*name == '-')
        name++;
    size_t len = strlen(name);
    if (!len || len >= n)
        return 0;
    for (size_t i = 0; i <= len; i++)
        o[i] = name[i] == '-' ? '_' : name[i];
    return 1;
}

/* Checks v against every method's row called name (the method may not be
 * known yet): the first that accepts it, else the first one's complaint. */
static int check_any(const char *name, const char *v, cdl_error *err)
{
    const cdl_param *first = NULL;
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); *it; it++)
        for (const cdl_param_table *const *t = (*it)->params; t && *t; t++) {
            const cdl_param *p = cdl_param_find(*t, name);
            if (p && !cdl_param_set(p, v, NULL, NULL))
                return 0;
            if (p && !first)
                first = p;
        }
    return cdl_param_set(first, v, NULL, err);
}

static int not_read(const char *name, const char *method, cdl_error *err)
{
    return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "%s does not read %s", method, name);
}

static int set(cdl_settings *s, const char *name, const char *v, cdl_error *err)
{
    const cdl_param *p = cdl_param_find(&cdl_common_table, name);
    if (p) {
        if (!strcmp(name, "integrator") && v && !cdl_integrator_find(v))
            return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "unknown integrator '%s' (path, bdpt, ir, rigi, pm, gkde, "
                                 "splat or vcm)", v);
        int rc = cdl_param_set(p, v, &s->c, err);
        if (!rc)
            s->given_common |= 1u << (p - cdl_common_table.rows);
        return rc;
    }
    const cdl_param *any = cdl_method_param(NULL, name);
    if (!any)
        return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "unknown parameter");
    if (cdl_settings_given(s, "integrator")) {
        const cdl_param *mine = cdl_method_param(cdl_integrator_find(s->c.integrator), name);
        if (!mine)
            return not_read(name, s->c.integrator, err);
        int rc = cdl_param_set(mine, v, NULL, err);
        if (rc)
            return rc;
    } else {
        int rc = check_any(name, v, err);
        if (rc)
            return rc;
    }
    if (v && strlen(v) >= sizeof s->method[0].value)
        return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "value too long");
    int slot = s->nmethod;
    if (!(any->flags & CDL_PARAM_BITS)) /* a later setting replaces an earlier one */
        for (int i = 0; i < s->nmethod; i++)
            if (!strcmp(s->method[i].name, name))
                slot = i;
    if (slot == CDL_MAX_GIVEN)
        return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "more than %d method parameters", CDL_MAX_GIVEN);
    snprintf(s->method[slot].name, sizeof s->method[slot].name, "%s", name);
    snprintf(s->method[slot].value, sizeof s->method[slot].value, "%s", v ? v : "on");
    if (slot == s->nmethod)
        s->nmethod++;
    return 0;
}

int cdl_settings_set(cdl_settings *s, const char *name, const char *value, cdl_error *err)
{
    char o[32];
    if (!s || !name)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_settings_set: no settings or no name");
    if (!canonical(name, o, sizeof o))
        return cdl_error_set(err, CDL_ERR_USAGE, name, 0, "unknown parameter");
    cdl_settings *t = malloc(sizeof *t); /* a failed set leaves s as it was */
    if (!t)
        return cdl_error_set(err, CDL_ERR_SYSTEM, name, 0, "out of memory");
    *t = *s;
    int rc = set(t, o, value, err);
    if (!rc)
        *s = *t;
    else if (err && !strcmp(err->file, o))
        snprintf(err->file, sizeof err->file, "%s", name); /* named as the caller spelled it */
    free(t);
    return rc;
}

int cdl_settings_apply(const cdl_settings *s, const cdl_integrator_vtbl *vt, cdl_options *opt, cdl_error *err)
{
    for (int i = 0; i < s->nmethod; i++) {
        const cdl_param *p = cdl_method_param(vt, s->method[i].name);
        if (!p)
            return not_read(s->method[i].name, vt->name, err);
        int rc = cdl_param_set(p, s->method[i].value, opt, err);
        if (rc)
            return rc;
    }
    return 0;
}

int cdl_settings_check(const cdl_settings *s, cdl_error *err)
{
    if (cdl_settings_given(s, "spp") && cdl_settings_given(s, "time"))
        return cdl_error_set(err, CDL_ERR_USAGE, "time", 0, "give either spp or time, not both");
    if (!cdl_settings_given(s, "integrator"))
        return 0;
    const cdl_integrator_vtbl *vt = cdl_integrator_find(s->c.integrator);
    for (int i = 0; i < s->nmethod; i++)
        if (!cdl_method_param(vt, s->method[i].name))
            return not_read(s->method[i].name, vt->name, err);
    return 0;
}
