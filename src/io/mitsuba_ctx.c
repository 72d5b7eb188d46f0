/* The Mitsuba reader's context: errors and warnings at file:line,
 * attributes and properties, $variables and <default>, ids, paths; what
 * the loader, the values, shapes and materials all use. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/file.h"
#include "core/log.h"
#include "io/mitsuba_internal.h"

int cdl_mts_error(cdl_mts_ctx *c, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_error_vset(c->err, CDL_ERR_INPUT, c->file, line, fmt, ap);
    va_end(ap);
    return CDL_ERR_INPUT;
}

void cdl_mts_warn(cdl_mts_ctx *c, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_vwarn(c->file, line, fmt, ap);
    va_end(ap);
}

int cdl_mts_scene_rc(cdl_mts_ctx *c, int line, int rc)
{
    return cdl_error_place(c->err, rc, c->s->path, c->file, line);
}

/* ---- names, variables and attributes ---- */

/* snake_case of a camelCase name: an upper-case letter after a lower-case
 * one or a digit starts a word ("intIOR" -> "int_ior"). */
static void fold(const char *s, char *out, size_t cap)
{
    size_t o = 0;
    for (size_t i = 0; s[i] && o + 2 < cap; i++) {
        unsigned char ch = (unsigned char)s[i];
        if (isupper(ch) && i > 0 && (islower((unsigned char)s[i - 1]) || isdigit((unsigned char)s[i - 1])))
            out[o++] = '_';
        out[o++] = (char)tolower(ch);
    }
    out[o] = 0;
}

int cdl_mts_same_name(const char *a, const char *b)
{
    char fa[128], fb[128];
    fold(a, fa, sizeof fa);
    fold(b, fb, sizeof fb);
    return !strcmp(fa, fb);
}

static cdl_mts_var *var_get(const cdl_mts_ctx *c, const char *name, size_t len)
{
    for (int i = 0; i < c->nvars; i++)
        if (strlen(c->vars[i].name) == len && !strncmp(c->vars[i].name, name, len))
            return &c->vars[i];
    return NULL;
}

static int oom(cdl_mts_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, 0, "out of memory");
}

int cdl_mts_define(cdl_mts_ctx *c, const char *name, size_t len, const char *value, int given)
{
    if (var_get(c, name, len))
        return 0; /* the first definition holds: -D before the file's <default> */
    if (c->nvars == c->capvars) {
        int cap = c->capvars ? 2 * c->capvars : 8;
        cdl_mts_var *v = realloc(c->vars, sizeof *v * (size_t)cap);
        if (!v)
            return oom(c);
        c->vars = v;
        c->capvars = cap;
    }
    cdl_mts_var *v = &c->vars[c->nvars];
    *v = (cdl_mts_var){.name = strndup(name, len), .value = strdup(value), .given = given};
    if (!v->name || !v->value) {
        free(v->name);
        free(v->value);
        return oom(c);
    }
    c->nvars++;
    return 0;
}

/* <default name value>: defines name unless it is defined already. */
int cdl_mts_default(cdl_mts_ctx *c, const cdl_xml_node *n)
{
    const char *name = cdl_xml_attr_get(n, "name"), *value = cdl_xml_attr_get(n, "value");
    if (!name || !value)
        return cdl_mts_error(c, n->line, "<default> needs \"name\" and \"value\"");
    if (!*name)
        return cdl_mts_error(c, n->line, "<default>: empty name");
    for (const char *p = name; *p; p++)
        if (!isalnum((unsigned char)*p) && *p != '_')
            return cdl_mts_error(c, n->line, "<default>: \"%s\" is not a parameter name (letters, digits, _)", name);
    cdl_mts_var *v = var_get(c, name, strlen(name));
    if (v) {
        v->used = 1; /* declared: a -D of it is not unknown */
        return 0;
    }
    return cdl_mts_define(c, name, strlen(name), value, 0);
}

const char *cdl_mts_attr(cdl_mts_ctx *c, const cdl_xml_node *n, const char *attr, int *rc)
{
    const char *v = cdl_xml_attr_get(n, attr);
    if (!v)
        return NULL;
    size_t o = 0, cap = sizeof c->buf;
    for (const char *p = v; *p;) {
        const char *add = p;
        size_t len = 1;
        if (*p == '$' && (isalnum((unsigned char)p[1]) || p[1] == '_')) {
            const char *q = p + 1;
            while (isalnum((unsigned char)*q) || *q == '_')
                q++;
            cdl_mts_var *var = var_get(c, p + 1, (size_t)(q - p - 1));
            add = var ? var->value : NULL;
            if (var)
                var->used = 1;
            if (!add) {
                *rc = cdl_mts_error(c, n->line, "%s=\"%s\": parameter $%.*s is not defined (no <default>)", attr, v,
                                    (int)(q - p - 1), p + 1);
                return NULL;
            }
            len = strlen(add);
            p = q;
        } else {
            p++;
        }
        if (o + len >= cap) {
            *rc = cdl_mts_error(c, n->line, "%s: value longer than %zu characters", attr, cap - 1);
            return NULL;
        }
        memcpy(c->buf + o, add, len);
        o += len;
    }
    c->buf[o] = 0;
    return c->buf;
}

int cdl_mts_type(cdl_mts_ctx *c, const cdl_xml_node *n, char *out, size_t cap)
{
    int rc = 0;
    const char *t = cdl_mts_attr(c, n, "type", &rc);
    if (rc)
        return rc;
    if (!t || !*t)
        return cdl_mts_error(c, n->line, "<%s> needs a \"type\"", n->name);
    snprintf(out, cap, "%s", t);
    return 0;
}

cdl_xml_node *cdl_mts_prop(cdl_mts_ctx *c, cdl_xml_node *n, const char *name)
{
    (void)c;
    for (int i = 0; i < n->nkids; i++) {
        const char *pn = cdl_xml_attr_get(&n->kids[i], "name");
        if (pn && cdl_mts_same_name(pn, name)) {
            n->kids[i].used = 1;
            return &n->kids[i];
        }
    }
    return NULL;
}

void cdl_mts_warn_unused(cdl_mts_ctx *c, cdl_xml_node *n, const char *what)
{
    for (int i = 0; i < n->nkids; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (k->used)
            continue;
        const char *pn = cdl_xml_attr_get(k, "name");
        if (pn)
            cdl_mts_warn(c, k->line, "%s: <%s name=\"%s\"> is not supported (ignored)", what, k->name, pn);
        else
            cdl_mts_warn(c, k->line, "%s: <%s> is not supported (ignored)", what, k->name);
        k->used = 1;
    }
}

int cdl_mts_add_path(cdl_mts_ctx *c, const cdl_xml_node *n)
{
    int rc = 0;
    const char *v = cdl_mts_attr(c, n, "value", &rc);
    if (rc)
        return rc;
    if (!v || !*v)
        return cdl_mts_error(c, n->line, "<path> needs a \"value\"");
    if (c->npaths == CDL_MTS_MAX_PATHS)
        return cdl_mts_error(c, n->line, "more than %d <path> elements", CDL_MTS_MAX_PATHS);
    char *dir = c->paths[c->npaths];
    cdl_path_join_dir(c->file, v, dir, sizeof c->paths[0]);
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        cdl_mts_warn(c, n->line, "<path> \"%s\" is not a folder (searched anyway)", dir);
    c->npaths++;
    return 0;
}

int cdl_mts_path(cdl_mts_ctx *c, int line, const char *name, char *out, size_t n)
{
    struct stat st;
    for (int i = c->npaths - 1; i >= 0 && name[0] != '/'; i--) {
        snprintf(out, n, "%s/%s", c->paths[i], name);
        if (stat(out, &st) == 0 && S_ISREG(st.st_mode))
            return 0;
    }
    cdl_path_join_dir(c->main_path, name, out, n);
    if (stat(out, &st) != 0)
        return cdl_mts_error(c, line, "\"%s\" cannot be opened: %s", out, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return cdl_mts_error(c, line, "\"%s\" is not a regular file", out);
    return 0;
}

/* ---- ids ---- */

const cdl_mts_id *cdl_mts_find_id(cdl_mts_ctx *c, const char *id)
{
    for (int i = 0; i < c->nids; i++)
        if (!strcmp(c->ids[i].id, id))
            return &c->ids[i];
    return NULL;
}

cdl_xml_node *cdl_mts_find_decl(cdl_mts_ctx *c, const char *id)
{
    for (int d = c->depth - 1; d >= 0; d--) {
        cdl_xml_node *r = c->roots[d];
        for (int i = 0; r && i < r->nkids; i++) {
            const char *k = cdl_xml_attr_get(&r->kids[i], "id");
            if (k && !strcmp(k, id))
                return &r->kids[i];
        }
    }
    return NULL;
}

int cdl_mts_add_id(cdl_mts_ctx *c, const cdl_xml_node *n, const cdl_mts_id *v)
{
    if (cdl_mts_find_id(c, v->id))
        return cdl_mts_error(c, n->line, "id \"%s\" is declared twice", v->id);
    if (c->nids == c->capids) {
        int cap = c->capids ? 2 * c->capids : 16;
        cdl_mts_id *p = realloc(c->ids, sizeof *p * (size_t)cap);
        if (!p)
            return oom(c);
        c->ids = p;
        c->capids = cap;
    }
    c->ids[c->nids] = *v;
    if (!(c->ids[c->nids].id = strdup(v->id)))
        return oom(c);
    c->nids++;
    return 0;
}
