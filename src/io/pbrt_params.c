#include "io/pbrt_params.h"

#include "core/spectrum.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "scene/scene.h"

static const struct {
    const char *name;
    cdl_pbrt_ptype type;
} TYPES[] = {
    {"integer", CDL_PT_INT},      {"float", CDL_PT_FLOAT},       {"point2", CDL_PT_POINT2},
    {"vector2", CDL_PT_VECTOR2},  {"point3", CDL_PT_POINT3},     {"point", CDL_PT_POINT3},
    {"vector3", CDL_PT_VECTOR3},  {"vector", CDL_PT_VECTOR3},    {"normal3", CDL_PT_NORMAL},
    {"normal", CDL_PT_NORMAL},    {"rgb", CDL_PT_RGB},           {"color", CDL_PT_RGB},
    {"xyz", CDL_PT_XYZ},          {"spectrum", CDL_PT_SPECTRUM}, {"blackbody", CDL_PT_BLACKBODY},
    {"bool", CDL_PT_BOOL},        {"string", CDL_PT_STRING},     {"texture", CDL_PT_TEXTURE},
};

const char *cdl_pbrt_type_name(cdl_pbrt_ptype t)
{
    for (size_t i = 0; i < sizeof TYPES / sizeof TYPES[0]; i++)
        if (TYPES[i].type == t)
            return TYPES[i].name;
    return "?";
}

void cdl_pbrt_params_free(cdl_pbrt_params *ps)
{
    free(ps->p);
    free(ps->num);
    free(ps->str);
    memset(ps, 0, sizeof *ps);
}

static int grow(void **buf, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 16;
    while (c < need)
        c *= 2;
    void *p = realloc(*buf, c * elem);
    if (!p)
        return -1;
    *buf = p;
    *cap = c;
    return 0;
}

static int push_num(cdl_pbrt_params *ps, double v)
{
    if (grow((void **)&ps->num, &ps->capnum, ps->nnum + 1, sizeof(double)))
        return -1;
    ps->num[ps->nnum++] = v;
    return 0;
}

static int push_str(cdl_pbrt_params *ps, const char *s)
{
    if (grow((void **)&ps->str, &ps->capstr, ps->nstr + 1, sizeof(char *)))
        return -1;
    ps->str[ps->nstr++] = s;
    return 0;
}

/* Splits "type name" in place (the declaration lives in the file buffer). */
static int split_decl(char *d, char **type, char **name)
{
    char *w[3];
    int n = 0;
    char *p = d;
    while (*p && n < 3) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (!*p)
            break;
        w[n++] = p;
        while (*p && *p != ' ' && *p != '\t')
            p++;
        if (*p)
            *p++ = 0;
    }
    while (*p == ' ' || *p == '\t')
        p++;
    if (n != 2 || *p)
        return -1;
    *type = w[0];
    *name = w[1];
    return 0;
}

int cdl_pbrt_parse_params(cdl_pbrt_lexer *lx, cdl_pbrt_params *ps, cdl_error *err)
{
    ps->n = ps->nnum = ps->nstr = 0;
    ps->file = lx->path;
    for (;;) {
        cdl_pbrt_token t, v;
        int rc = cdl_pbrt_peek(lx, &t, err);
        if (rc)
            return rc;
        if (t.kind != CDL_PBRT_STRING)
            return 0;
        cdl_pbrt_next(lx, &t, err);
        char *tname, *name;
        if (split_decl((char *)t.s, &tname, &name))
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter declaration \"%s\" is not of the form \"type name\"", t.s);
        cdl_pbrt_param p;
        memset(&p, 0, sizeof p);
        size_t ti = 0, nt = sizeof TYPES / sizeof TYPES[0];
        while (ti < nt && strcmp(TYPES[ti].name, tname))
            ti++;
        if (ti == nt)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "unknown parameter type '%s' (in \"%s %s\")", tname, tname, name);
        p.type = TYPES[ti].type;
        p.tname = tname;
        p.name = name;
        p.line = t.line;
        size_t num0 = ps->nnum, str0 = ps->nstr, nbw = 0;
        if ((rc = cdl_pbrt_next(lx, &v, err)))
            return rc;
        int bracket = v.kind == CDL_PBRT_LBRACK, open_line = v.line;
        for (int first = 1;; first = 0) {
            if (bracket && (rc = cdl_pbrt_next(lx, &v, err)))
                return rc;
            if (!bracket && !first)
                break;
            if (bracket && v.kind == CDL_PBRT_RBRACK)
                break;
            char txt[96];
            cdl_pbrt_token_text(&v, txt, sizeof txt);
            double d;
            if (v.kind == CDL_PBRT_STRING) {
                if (push_str(ps, v.s))
                    return cdl_error_set(err, CDL_ERR_SYSTEM, lx->path, v.line, "out of memory");
            } else if (v.kind == CDL_PBRT_WORD && !cdl_pbrt_word_number(&v, &d)) {
                if (!isfinite(d) || fabs(d) > CDL_MAX_COORD)
                    return cdl_error_set(err, CDL_ERR_INPUT, lx->path, v.line,
                                         "value %s of \"%s %s\" is not a finite number within 1e20",
                                         txt, tname, name);
                if (push_num(ps, d))
                    return cdl_error_set(err, CDL_ERR_SYSTEM, lx->path, v.line, "out of memory");
            } else if (cdl_pbrt_is_word(&v, "true") || cdl_pbrt_is_word(&v, "false")) {
                /* pbrt-v4 writes bools bare */
                if (push_num(ps, cdl_pbrt_is_word(&v, "true") ? 1.0 : 0.0))
                    return cdl_error_set(err, CDL_ERR_SYSTEM, lx->path, v.line, "out of memory");
                nbw++;
            } else if (bracket && v.kind == CDL_PBRT_EOF) {
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, open_line,
                                     "'[' of \"%s %s\" is never closed", tname, name);
            } else if (bracket) {
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, open_line,
                                     "'[' of \"%s %s\" is not closed before %s on line %d", tname,
                                     name, txt, v.line);
            } else {
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                     "parameter \"%s %s\" has no value (got %s)", tname, name, txt);
            }
        }
        size_t nn = ps->nnum - num0, ns = ps->nstr - str0;
        if (nn && ns)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter \"%s %s\" mixes strings and numbers", tname, name);
        p.is_str = ns > 0;
        p.n = ns ? ns : nn;
        p.off = ns ? str0 : num0;
        int numeric = p.type != CDL_PT_BOOL && p.type != CDL_PT_STRING && p.type != CDL_PT_TEXTURE &&
                      p.type != CDL_PT_SPECTRUM;
        if (numeric && (ns || nbw))
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter \"%s %s\" expects numbers", tname, name);
        if ((p.type == CDL_PT_STRING || p.type == CDL_PT_TEXTURE) && nn)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter \"%s %s\" expects quoted strings", tname, name);
        if (p.type == CDL_PT_SPECTRUM && nbw)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter \"%s %s\" expects a name or wavelength/value pairs", tname, name);
        if (p.type == CDL_PT_BOOL) {
            if (nn != nbw)
                return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                     "parameter \"%s %s\" expects true or false", tname, name);
            for (size_t i = 0; i < ns; i++) { /* pbrt-v3 quotes them */
                const char *s = ps->str[str0 + i];
                if (strcmp(s, "true") && strcmp(s, "false"))
                    return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                         "parameter \"%s %s\" expects true or false, got \"%s\"", tname,
                                         name, s);
                if (push_num(ps, !strcmp(s, "true") ? 1.0 : 0.0))
                    return cdl_error_set(err, CDL_ERR_SYSTEM, lx->path, t.line, "out of memory");
            }
            ps->nstr = str0;
            p.is_str = 0;
            p.off = num0;
            p.n = ps->nnum - num0;
        }
        size_t mult = 1;
        if (p.type == CDL_PT_POINT2 || p.type == CDL_PT_VECTOR2 ||
            (p.type == CDL_PT_SPECTRUM && !p.is_str) || (p.type == CDL_PT_BLACKBODY && p.n != 1))
            mult = 2;
        else if (p.type == CDL_PT_POINT3 || p.type == CDL_PT_VECTOR3 || p.type == CDL_PT_NORMAL ||
                 p.type == CDL_PT_RGB || p.type == CDL_PT_XYZ)
            mult = 3;
        if (p.n % mult)
            return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                 "parameter \"%s %s\" needs a multiple of %zu values, got %zu", tname,
                                 name, mult, p.n);
        if (p.type == CDL_PT_INT)
            for (size_t i = 0; i < p.n; i++) {
                double d = ps->num[num0 + i];
                if (d != floor(d) || fabs(d) > (double)INT32_MAX)
                    return cdl_error_set(err, CDL_ERR_INPUT, lx->path, t.line,
                                         "parameter \"%s %s\" value %g is not a 32-bit integer", tname,
                                         name, d);
            }
        if (grow((void **)&ps->p, &ps->cap, ps->n + 1, sizeof p))
            return cdl_error_set(err, CDL_ERR_SYSTEM, lx->path, t.line, "out of memory");
        ps->p[ps->n++] = p;
    }
}

cdl_pbrt_param *cdl_pbrt_find(cdl_pbrt_params *ps, const char *name)
{
    cdl_pbrt_param *found = NULL;
    for (size_t i = ps->n; i-- > 0;)
        if (!strcmp(ps->p[i].name, name)) {
            ps->p[i].used = 1;
            if (!found)
                found = &ps->p[i]; /* the last one wins, as in pbrt-v3 */
        }
    return found;
}

static int type_error(const cdl_pbrt_params *ps, const cdl_pbrt_param *p, const char *want,
                      cdl_error *err)
{
    return cdl_error_set(err, CDL_ERR_INPUT, ps->file, p->line, "parameter \"%s %s\" should be %s",
                         p->tname, p->name, want);
}

static int count_error(const cdl_pbrt_params *ps, const cdl_pbrt_param *p, const char *want,
                       cdl_error *err)
{
    return cdl_error_set(err, CDL_ERR_INPUT, ps->file, p->line,
                         "parameter \"%s %s\" expects %s, got %zu values", p->tname, p->name, want, p->n);
}

int cdl_pbrt_get_float(cdl_pbrt_params *ps, const char *name, double def, double *out, cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type != CDL_PT_FLOAT && p->type != CDL_PT_INT)
        return type_error(ps, p, "a float", err);
    if (p->n != 1)
        return count_error(ps, p, "one value", err);
    *out = ps->num[p->off];
    return 0;
}

int cdl_pbrt_get_int(cdl_pbrt_params *ps, const char *name, int def, int *out, cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type != CDL_PT_INT)
        return type_error(ps, p, "an integer", err);
    if (p->n != 1)
        return count_error(ps, p, "one value", err);
    *out = (int)ps->num[p->off];
    return 0;
}

int cdl_pbrt_get_bool(cdl_pbrt_params *ps, const char *name, int def, int *out, cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type != CDL_PT_BOOL)
        return type_error(ps, p, "a bool", err);
    if (p->n != 1)
        return count_error(ps, p, "one value", err);
    *out = ps->num[p->off] != 0.0;
    return 0;
}

int cdl_pbrt_get_string(cdl_pbrt_params *ps, const char *name, const char *def, const char **out,
                        cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type != CDL_PT_STRING)
        return type_error(ps, p, "a string", err);
    if (p->n != 1)
        return count_error(ps, p, "one value", err);
    *out = ps->str[p->off];
    return 0;
}

int cdl_pbrt_get_point3(cdl_pbrt_params *ps, const char *name, const double def[3], double out[3],
                        cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    for (int i = 0; i < 3; i++)
        out[i] = def[i];
    if (!p)
        return 0;
    if (p->type != CDL_PT_POINT3 && p->type != CDL_PT_VECTOR3 && p->type != CDL_PT_NORMAL)
        return type_error(ps, p, "a point3", err);
    if (p->n != 3)
        return count_error(ps, p, "one triple (3 values)", err);
    for (int i = 0; i < 3; i++)
        out[i] = ps->num[p->off + i];
    return 0;
}

int cdl_pbrt_param_spectrum(cdl_pbrt_params *ps, cdl_pbrt_param *p, cdl_vec3 *out, cdl_error *err)
{
    const double *v = ps->num ? ps->num + p->off : NULL; /* NULL + 0 is undefined */
    switch (p->type) {
    case CDL_PT_RGB:
        if (p->n != 3)
            return count_error(ps, p, "one triple (3 values)", err);
        *out = cdl_v3((float)v[0], (float)v[1], (float)v[2]);
        return 0;
    case CDL_PT_XYZ:
        if (p->n != 3)
            return count_error(ps, p, "one triple (3 values)", err);
        *out = cdl_pbrt_xyz_to_rgb(v[0], v[1], v[2]);
        return 0;
    case CDL_PT_FLOAT:
        if (p->n != 1)
            return count_error(ps, p, "one value", err);
        *out = cdl_v3((float)v[0], (float)v[0], (float)v[0]);
        return 0;
    case CDL_PT_BLACKBODY: {
        /* v4: one temperature; v3: (temperature, scale) pairs */
        if (p->n == 0)
            return count_error(ps, p, "a temperature", err);
        double T = v[0], sc = p->n >= 2 ? v[1] : 1.0;
        if (!(T > 0.0))
            return cdl_error_set(err, CDL_ERR_INPUT, ps->file, p->line,
                                 "parameter \"%s %s\": temperature %g K is not positive", p->tname,
                                 p->name, T);
        *out = cdl_scale(cdl_pbrt_blackbody(T, p->n == 1), (float)sc);
        return 0;
    }
    case CDL_PT_SPECTRUM:
        if (p->is_str) {
            const char *nm = ps->str[p->off];
            if (p->n != 1)
                return count_error(ps, p, "one name", err);
            if (strchr(nm, '.') || strchr(nm, '/')) { /* pbrt-v3 .spd files */
                cdl_warn(ps->file, p->line, "spectrum file \"%s\" is not supported: \"%s\" keeps its default",
                         nm, p->name);
                return 0;
            }
            int known = cdl_pbrt_named_spectrum(nm, out);
            if (known == 1)
                cdl_warn(ps->file, p->line, "named spectrum \"%s\" approximated by (%g, %g, %g)", nm,
                         (double)out->x, (double)out->y, (double)out->z);
            if (known >= 0)
                return 0;
            return cdl_error_set(err, CDL_ERR_INPUT, ps->file, p->line,
                                 "parameter \"%s %s\": unknown named spectrum \"%s\" (spectrum files are not supported)",
                                 p->tname, p->name, nm);
        } else {
            if (p->n < 2 || p->n % 2)
                return count_error(ps, p, "wavelength/value pairs", err);
            int n = (int)(p->n / 2);
            double *lv = malloc(2 * (size_t)n * sizeof *lv);
            if (!lv)
                return cdl_error_set(err, CDL_ERR_SYSTEM, ps->file, p->line, "out of memory");
            for (int i = 0; i < n; i++) {
                lv[i] = v[2 * i];
                lv[n + i] = v[2 * i + 1];
                if (!(lv[i] > 0.0) || (i > 0 && !(lv[i] > lv[i - 1]))) {
                    free(lv);
                    return cdl_error_set(err, CDL_ERR_INPUT, ps->file, p->line,
                                         "parameter \"%s %s\": wavelengths must be positive and increasing (%g after "
                                         "%g)",
                                         p->tname, p->name, v[2 * i], i > 0 ? v[2 * i - 2] : 0.0);
                }
            }
            /* through the CIE 1931 observer: a light's L or I as emitted,
             * everything else (reflectances, eta, k) under D65 so that a
             * constant stays grey */
            int emitted = !strcmp(p->name, "L") || !strcmp(p->name, "I");
            cdl_vec3 rgb = cdl_spectrum_to_srgb(lv, lv + n, n, !emitted);
            free(lv);
            /* a saturated spectrum lies outside the sRGB gamut: its nearest
             * colour inside */
            *out = cdl_v3(fmaxf(rgb.x, 0.0f), fmaxf(rgb.y, 0.0f), fmaxf(rgb.z, 0.0f));
            return 0;
        }
    default:
        return type_error(ps, p, "a spectrum (rgb, spectrum, blackbody)", err);
    }
}

int cdl_pbrt_get_spectrum(cdl_pbrt_params *ps, const char *name, cdl_vec3 def, cdl_vec3 *out,
                          int *found, cdl_error *err)
{
    cdl_pbrt_param *p = cdl_pbrt_find(ps, name);
    *out = def;
    if (found)
        *found = p != NULL;
    if (!p)
        return 0;
    return cdl_pbrt_param_spectrum(ps, p, out, err);
}

int cdl_pbrt_get_scale(cdl_pbrt_params *ps, const char *name, cdl_vec3 *out, cdl_error *err)
{
    return cdl_pbrt_get_spectrum(ps, name, cdl_v3(1, 1, 1), out, NULL, err);
}

void cdl_pbrt_warn_unused(const cdl_pbrt_params *ps, const char *directive)
{
    for (size_t i = 0; i < ps->n; i++)
        if (!ps->p[i].used)
            cdl_warn(ps->file, ps->p[i].line, "%s: parameter \"%s %s\" is not supported (ignored)",
                     directive, ps->p[i].tname, ps->p[i].name);
}
