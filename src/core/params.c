#include "core/params.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int cdl_param_choice(const cdl_param *p, int i, const char **s)
{
    const char *c = p->choices;
    if (!c)
        return 0;
    for (; i > 0; i--) {
        c = strchr(c, '|');
        if (!c)
            return 0;
        c++;
    }
    *s = c;
    const char *e = strchr(c, '|');
    return e ? (int)(e - c) : (int)strlen(c);
}

static int choice_index(const cdl_param *p, const char *v)
{
    const char *s;
    int n;
    for (int i = 0; (n = cdl_param_choice(p, i, &s)) > 0; i++)
        if ((int)strlen(v) == n && !strncmp(s, v, (size_t)n))
            return i;
    return -1;
}

/* "on"/"1"/"true" -> 1, "off"/"0"/"false" -> 0, else -1 */
static int flag_value(const char *v)
{
    if (!strcmp(v, "on") || !strcmp(v, "1") || !strcmp(v, "true") || !strcmp(v, "True"))
        return 1;
    if (!strcmp(v, "off") || !strcmp(v, "0") || !strcmp(v, "false") || !strcmp(v, "False"))
        return 0;
    return -1;
}

static void store(void *base, size_t at, int kind, double v)
{
    char *p = (char *)base + at;
    switch (kind) {
    case CDL_STORE_INT: *(int *)p = (int)v; break;
    case CDL_STORE_LONG: *(long *)p = (long)v; break;
    case CDL_STORE_U32: *(uint32_t *)p = (uint32_t)v; break;
    case CDL_STORE_U64: *(uint64_t *)p = (uint64_t)v; break;
    case CDL_STORE_FLOAT: *(float *)p = (float)v; break;
    case CDL_STORE_DOUBLE: *(double *)p = v; break;
    default: break;
    }
}

static double load(const void *base, size_t at, int kind)
{
    const char *p = (const char *)base + at;
    switch (kind) {
    case CDL_STORE_INT: return *(const int *)p;
    case CDL_STORE_LONG: return (double)*(const long *)p;
    case CDL_STORE_U32: return *(const uint32_t *)p;
    case CDL_STORE_U64: return (double)*(const uint64_t *)p;
    case CDL_STORE_FLOAT: return *(const float *)p;
    case CDL_STORE_DOUBLE: return *(const double *)p;
    default: return 0.0;
    }
}

static size_t store_size(int kind)
{
    switch (kind) {
    case CDL_STORE_INT: return sizeof(int);
    case CDL_STORE_LONG: return sizeof(long);
    case CDL_STORE_U32: return sizeof(uint32_t);
    case CDL_STORE_U64: return sizeof(uint64_t);
    case CDL_STORE_FLOAT: return sizeof(float);
    case CDL_STORE_DOUBLE: return sizeof(double);
    default: return 0;
    }
}

static int in_range(const cdl_param *p, double v)
{
    if (v < p->min || v > p->max)
        return 0;
    if ((p->flags & CDL_PARAM_OPEN_MIN) && v == p->min)
        return 0;
    return !((p->flags & CDL_PARAM_OPEN_MAX) && v == p->max);
}

static int range_error(const cdl_param *p, const char *what, const char *v, cdl_error *err)
{
    char note[512] = "";
    if (p->note)
        snprintf(note, sizeof note, " (%s)", p->note);
    /* integers in full: [1, 1000000], not [1, 1e+06] */
    const char *f = p->type == CDL_PARAM_INT ? "expected %s in %c%.0f, %.0f%c%s, got '%s'"
                                              : "expected %s in %c%g, %g%c%s, got '%s'";
    return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, f, what, p->flags & CDL_PARAM_OPEN_MIN ? '(' : '[', p->min,
                         p->max, p->flags & CDL_PARAM_OPEN_MAX ? ')' : ']', note, v);
}

static int parse_number(const char *s, int integer, double *out)
{
    char *end;
    errno = 0;
    if (integer) {
        long long v = strtoll(s, &end, 10);
        *out = (double)v;
    } else {
        *out = strtod(s, &end);
        if (end != s && *end == '/') { /* a ratio: "2/3" */
            const char *q = end + 1;
            double d = strtod(q, &end);
            if (end == q || !(d != 0.0))
                return 0;
            *out /= d;
        }
    }
    return end != s && !*end && !errno && isfinite(*out);
}

/* "a|b|c" -> "a, b or c" */
static void choices_text(const cdl_param *p, char *buf, size_t n)
{
    const char *s;
    int len, count = 0;
    while (cdl_param_choice(p, count, &s) > 0)
        count++;
    buf[0] = 0;
    for (int i = 0; (len = cdl_param_choice(p, i, &s)) > 0; i++) {
        size_t used = strlen(buf);
        snprintf(buf + used, n - used, "%s%.*s", i == 0 ? "" : i == count - 1 ? " or " : ", ", len, s);
    }
}

static int set_floats(const cdl_param *p, const char *value, void *base, cdl_error *err)
{
    double v[16];
    const char *s = value;
    int n = p->count < 16 ? p->count : 16;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        v[i] = strtod(s, &end);
        if (end == s || errno || !isfinite(v[i]) || (i < n - 1 ? *end != ',' : *end != 0))
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected %d comma-separated numbers, got '%s'", n,
                                 value);
        if (!in_range(p, v[i])) {
            char what[64];
            snprintf(what, sizeof what, "%d numbers each", n);
            return range_error(p, what, value, err);
        }
        s = end + 1;
    }
    const char *why = p->check ? p->check(v, n) : NULL;
    if (why)
        return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "%s, got '%s'", why, value);
    if (!base)
        return 0;
    size_t at = p->at, sz = store_size(p->store);
    if (p->flags & CDL_PARAM_REPEAT) {
        int *cnt = (int *)((char *)base + p->count_at);
        if (*cnt >= p->repeat)
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "given more than %d times", p->repeat);
        at += (size_t)(*cnt)++ * (size_t)n * sz;
    }
    for (int i = 0; i < n; i++)
        store(base, at + (size_t)i * sz, p->store, v[i]);
    return 0;
}

int cdl_param_set(const cdl_param *p, const char *value, void *base, cdl_error *err)
{
    if (!value && p->type != CDL_PARAM_BOOL && !(p->flags & CDL_PARAM_FLAG))
        return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expects a value (%s)", p->meta);
    double v = 0.0;
    switch (p->type) {
    case CDL_PARAM_INT:
        if (p->choices && !strcmp(value, p->choices)) {
            v = p->values ? p->values[0] : -1.0;
            break;
        }
        if (!parse_number(value, 1, &v)) {
            if (p->choices)
                return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected an integer or '%s', got '%s'",
                                     p->choices, value);
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected an integer, got '%s'", value);
        }
        if (!in_range(p, v))
            return range_error(p, "an integer", value, err);
        break;
    case CDL_PARAM_FLOAT:
        if (!parse_number(value, 0, &v))
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected a number, got '%s'", value);
        if (!in_range(p, v))
            return range_error(p, "a number", value, err);
        break;
    case CDL_PARAM_BOOL: {
        int f = value && value[0] ? flag_value(value) : 1;
        if (f < 0)
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected on or off, got '%s'", value);
        v = f;
        break;
    }
    case CDL_PARAM_CHOICE: {
        int i = choice_index(p, value);
        if (i < 0) {
            char c[512];
            choices_text(p, c, sizeof c);
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected %s, got '%s'", c, value);
        }
        v = p->values ? p->values[i] : i;
        if ((p->flags & CDL_PARAM_BITS) && base)
            v = (double)((unsigned)v | (unsigned)load(base, p->at, p->store));
        break;
    }
    case CDL_PARAM_FLOATS:
        return set_floats(p, value, base, err);
    case CDL_PARAM_RES: {
        char *end;
        errno = 0;
        long a = strtol(value, &end, 10), b = -1;
        if (end != value && (*end == 'x' || *end == 'X') && !errno) {
            const char *q = end + 1;
            b = strtol(q, &end, 10);
            if (end == q || *end || errno)
                b = -1;
        }
        if (!(a >= 1 && a <= p->max && b >= 1 && b <= p->max))
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0,
                                 "expected WIDTHxHEIGHT with each in [1, %g], got '%s'", p->max, value);
        if (base) {
            store(base, p->at, p->store, (double)a);
            store(base, p->at + store_size(p->store), p->store, (double)b);
        }
        return 0;
    }
    case CDL_PARAM_NAME: {
        if (!value[0] || strlen(value) >= (size_t)p->count)
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "expected a name of 1 to %d characters, got '%s'",
                                 p->count - 1, value);
        const char *why = p->check_text ? p->check_text(value) : NULL;
        if (why)
            return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "%s, got '%s'", why, value);
        if (!base)
            return 0;
        size_t at = p->at;
        if (p->flags & CDL_PARAM_REPEAT) {
            int *cnt = (int *)((char *)base + p->count_at);
            if (*cnt >= p->repeat)
                return cdl_error_set(err, CDL_ERR_USAGE, p->name, 0, "given more than %d times", p->repeat);
            at += (size_t)(*cnt)++ * (size_t)p->count;
        }
        memcpy((char *)base + at, value, strlen(value) + 1);
        return 0;
    }
    }
    if (base)
        store(base, p->at, p->store, v);
    return 0;
}

void cdl_param_defaults(const cdl_param_table *t, void *base)
{
    for (int i = 0; i < t->count; i++) {
        const cdl_param *p = &t->rows[i];
        if (p->def && p->def[0] && !(p->flags & CDL_PARAM_REPEAT))
            cdl_param_set(p, p->def, base, NULL); /* tests check every default parses */
    }
}

const cdl_param *cdl_param_find(const cdl_param_table *t, const char *name)
{
    for (int i = 0; i < t->count; i++)
        if (!strcmp(t->rows[i].name, name))
            return &t->rows[i];
    return NULL;
}
