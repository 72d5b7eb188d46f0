/* Mitsuba property values: numbers, booleans, strings, colors (rgb, srgb,
 * spectrum), points and vectors, and <transform> operations, each checked
 * and reported with the element's line. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/spectrum.h"
#include "io/mitsuba_internal.h"
/* Up to max numbers separated by commas and/or white space; *count gets
 * how many there were (more than max is an error). */
static int numbers(cdl_mts_ctx *c, const cdl_xml_node *n, const char *attr, const char *s, double *v, int max,
                   int *count)
{
    int k = 0;
    const char *p = s;
    for (;;) {
        while (isspace((unsigned char)*p) || *p == ',')
            p++;
        if (!*p)
            break;
        if (k == max)
            return cdl_mts_error(c, n->line, "<%s> %s=\"%s\": more than %d numbers", n->name, attr, s, max);
        char *end;
        errno = 0;
        double x = strtod(p, &end);
        if (end == p || (*end && !isspace((unsigned char)*end) && *end != ','))
            return cdl_mts_error(c, n->line, "<%s> %s=\"%s\" is not a number list", n->name, attr, s);
        if (!isfinite(x) || fabs(x) > 1e30)
            return cdl_mts_error(c, n->line, "<%s> %s=\"%s\": %g is not a finite number", n->name, attr, s, x);
        v[k++] = x;
        p = end;
    }
    *count = k;
    return 0;
}

/* The value attribute of a property element, substituted. */
static int value_of(cdl_mts_ctx *c, const cdl_xml_node *p, const char **v)
{
    int rc = 0;
    *v = cdl_mts_attr(c, p, "value", &rc);
    if (rc)
        return rc;
    if (!*v)
        return cdl_mts_error(c, p->line, "<%s name=\"%s\"> needs a \"value\"", p->name, cdl_xml_attr_get(p, "name"));
    return 0;
}

static int one_number(cdl_mts_ctx *c, const cdl_xml_node *p, double *out)
{
    const char *v;
    int rc = value_of(c, p, &v), k;
    if (!rc)
        rc = numbers(c, p, "value", v, out, 1, &k);
    if (!rc && k != 1)
        rc = cdl_mts_error(c, p->line, "<%s name=\"%s\"> needs one number", p->name, cdl_xml_attr_get(p, "name"));
    return rc;
}

static int want_tag(cdl_mts_ctx *c, const cdl_xml_node *p, const char *tag, const char *tag2)
{
    if (strcmp(p->name, tag) && (!tag2 || strcmp(p->name, tag2)))
        return cdl_mts_error(c, p->line, "property \"%s\" must be <%s>, not <%s>", cdl_xml_attr_get(p, "name"), tag,
                             p->name);
    return 0;
}

int cdl_mts_float(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double *out)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (!p)
        return 0;
    int rc = want_tag(c, p, "float", "integer");
    return rc ? rc : one_number(c, p, out);
}

int cdl_mts_int(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, long def, long *out)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (!p)
        return 0;
    double v;
    int rc = want_tag(c, p, "integer", NULL);
    if (!rc)
        rc = one_number(c, p, &v);
    if (!rc && (v != floor(v) || fabs(v) > 2e9))
        rc = cdl_mts_error(c, p->line, "<integer name=\"%s\">: %g is not an integer", name, v);
    if (!rc)
        *out = (long)v;
    return rc;
}

int cdl_mts_bool(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, int def, int *out)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (!p)
        return 0;
    const char *v;
    int rc = want_tag(c, p, "boolean", NULL);
    if (!rc)
        rc = value_of(c, p, &v);
    if (rc)
        return rc;
    if (!strcmp(v, "true"))
        *out = 1;
    else if (!strcmp(v, "false"))
        *out = 0;
    else
        return cdl_mts_error(c, p->line, "<boolean name=\"%s\">: \"%s\" is not true or false", name, v);
    return 0;
}

int cdl_mts_string(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, const char *def, char *out, size_t cap)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    snprintf(out, cap, "%s", def ? def : "");
    if (!p)
        return 0;
    const char *v;
    int rc = want_tag(c, p, "string", NULL);
    if (!rc)
        rc = value_of(c, p, &v);
    if (rc)
        return rc;
    if (strlen(v) >= cap)
        return cdl_mts_error(c, p->line, "<string name=\"%s\">: longer than %zu characters", name, cap - 1);
    snprintf(out, cap, "%s", v);
    return 0;
}

static float srgb_to_linear(double v)
{
    return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
}

int cdl_mts_color_node(cdl_mts_ctx *c, cdl_xml_node *p, cdl_vec3 *out)
{
    const char *v;
    double x[64];
    int k, rc = value_of(c, p, &v);
    if (rc)
        return rc;
    int is_srgb = !strcmp(p->name, "srgb");
    if (!strcmp(p->name, "rgb") || is_srgb) {
        if (v[0] == '#') { /* Mitsuba 0.6's #rrggbb */
            unsigned r, g, b;
            char tail;
            if (strlen(v) != 7 || sscanf(v, "#%2x%2x%2x%c", &r, &g, &b, &tail) != 3)
                return cdl_mts_error(c, p->line, "<%s> \"%s\" is not #rrggbb", p->name, v);
            *out = cdl_v3(srgb_to_linear(r / 255.0), srgb_to_linear(g / 255.0), srgb_to_linear(b / 255.0));
            return 0;
        }
        if ((rc = numbers(c, p, "value", v, x, 3, &k)))
            return rc;
        if (k != 1 && k != 3)
            return cdl_mts_error(c, p->line, "<%s> \"%s\": give 3 numbers (or 1)", p->name, v);
        if (k == 1)
            x[1] = x[2] = x[0];
        *out = is_srgb ? cdl_v3(srgb_to_linear(x[0]), srgb_to_linear(x[1]), srgb_to_linear(x[2]))
                       : cdl_v3((float)x[0], (float)x[1], (float)x[2]);
    } else if (!strcmp(p->name, "spectrum")) {
        if (strchr(v, ':')) { /* wavelength:value pairs through the CIE observer */
            /* Mitsuba sets no limit; tabulated data at 1 nm steps over
             * 360-830 nm has 471 entries */
            enum { MAX_LAMBDA = 1024 };
            double lam[MAX_LAMBDA], val[MAX_LAMBDA];
            int m = 0;
            for (const char *q = v; *q;) {
                char *end;
                double l = strtod(q, &end);
                if (end == q || *end != ':' || !isfinite(l) || (m > 0 && !(l > lam[m - 1])))
                    return cdl_mts_error(c, p->line,
                                         "<spectrum> \"%s\" is not a list of increasing wavelength:value", v);
                q = end + 1;
                double y = strtod(q, &end);
                if (end == q || !isfinite(y))
                    return cdl_mts_error(c, p->line, "<spectrum> \"%s\" is not a list of wavelength:value", v);
                if (m == MAX_LAMBDA)
                    return cdl_mts_error(c, p->line, "<spectrum> \"%.40s...\": more than %d wavelengths", v,
                                         (int)MAX_LAMBDA);
                lam[m] = l;
                val[m++] = y;
                q = end;
                while (isspace((unsigned char)*q) || *q == ',')
                    q++;
            }
            if (m == 0)
                return cdl_mts_error(c, p->line, "<spectrum> \"%s\" is empty", v);
            /* emitted quantities integrate against the observer alone,
             * reflectances under D65 (Mitsuba 3's unbounded and bounded) */
            const char *name = cdl_xml_attr_get(p, "name");
            int emitted = name && (!strcmp(name, "radiance") || !strcmp(name, "intensity") ||
                                   !strcmp(name, "irradiance") || !strcmp(name, "power"));
            *out = cdl_spectrum_to_srgb(lam, val, m, !emitted);
            return 0;
        }
        if ((rc = numbers(c, p, "value", v, x, 3, &k)))
            return rc;
        if (k != 1 && k != 3)
            return cdl_mts_error(c, p->line, "<spectrum> \"%s\": give one number, three (RGB, as Mitsuba 0.6's RGB "
                                 "build reads them) or wavelength:value pairs", v);
        *out = k == 3 ? cdl_v3((float)x[0], (float)x[1], (float)x[2]) : cdl_v3((float)x[0], (float)x[0], (float)x[0]);
    } else if (!strcmp(p->name, "float")) {
        double f;
        if ((rc = one_number(c, p, &f)))
            return rc;
        *out = cdl_v3((float)f, (float)f, (float)f);
    } else {
        return cdl_mts_error(c, p->line, "property \"%s\": <%s> is not a color (rgb, srgb, spectrum, float)",
                             cdl_xml_attr_get(p, "name"), p->name);
    }
    return 0;
}

/* x, y, z attributes (missing ones are def) or value="x y z". */
static int xyz(cdl_mts_ctx *c, const cdl_xml_node *p, double def, double v[3])
{
    int rc = 0, k;
    const char *val = cdl_mts_attr(c, p, "value", &rc);
    if (rc)
        return rc;
    if (val) {
        if ((rc = numbers(c, p, "value", val, v, 3, &k)))
            return rc;
        if (k == 1)
            v[1] = v[2] = v[0];
        else if (k != 3)
            return cdl_mts_error(c, p->line, "<%s> value=\"%s\": give 3 numbers", p->name, val);
        return 0;
    }
    static const char *const ax[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; i++) {
        const char *s = cdl_mts_attr(c, p, ax[i], &rc);
        if (rc)
            return rc;
        v[i] = def;
        if (s) {
            if ((rc = numbers(c, p, ax[i], s, &v[i], 1, &k)))
                return rc;
            if (k != 1)
                return cdl_mts_error(c, p->line, "<%s> %s=\"%s\": give one number", p->name, ax[i], s);
        }
    }
    return 0;
}

int cdl_mts_vec(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_vec3 def, cdl_vec3 *out, int *found)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (found)
        *found = p != NULL;
    if (!p)
        return 0;
    double v[3];
    int rc = want_tag(c, p, "point", "vector");
    if (!rc)
        rc = xyz(c, p, 0.0, v);
    if (!rc)
        *out = cdl_v3((float)v[0], (float)v[1], (float)v[2]);
    return rc;
}

/* "x, y, z" of a lookat attribute. */
static int triple(cdl_mts_ctx *c, const cdl_xml_node *p, const char *attr, int required, const double def[3],
                  double v[3])
{
    int rc = 0, k;
    const char *s = cdl_mts_attr(c, p, attr, &rc);
    if (rc)
        return rc;
    if (!s) {
        if (required)
            return cdl_mts_error(c, p->line, "<lookat> needs \"%s\"", attr);
        memcpy(v, def, 3 * sizeof *v);
        return 0;
    }
    if ((rc = numbers(c, p, attr, s, v, 3, &k)))
        return rc;
    return k == 3 ? 0 : cdl_mts_error(c, p->line, "<lookat> %s=\"%s\": give 3 numbers", attr, s);
}

/* One operation of a <transform>, as a matrix applied after the ones before. */
static int transform_op(cdl_mts_ctx *c, cdl_xml_node *op, cdl_mat4 *m)
{
    double v[16];
    int rc = 0, k;
    op->used = 1;
    if (!strcmp(op->name, "translate")) {
        if ((rc = xyz(c, op, 0.0, v)))
            return rc;
        *m = cdl_mat4_translate(v[0], v[1], v[2]);
    } else if (!strcmp(op->name, "scale")) {
        if ((rc = xyz(c, op, 1.0, v)))
            return rc;
        if (v[0] == 0.0 || v[1] == 0.0 || v[2] == 0.0)
            return cdl_mts_error(c, op->line, "<scale> by zero");
        *m = cdl_mat4_scale(v[0], v[1], v[2]);
    } else if (!strcmp(op->name, "rotate")) {
        double angle;
        const char *a = cdl_mts_attr(c, op, "angle", &rc);
        if (rc)
            return rc;
        if (!a)
            return cdl_mts_error(c, op->line, "<rotate> needs an \"angle\" (degrees)");
        if ((rc = numbers(c, op, "angle", a, &angle, 1, &k)))
            return rc;
        if (k != 1)
            return cdl_mts_error(c, op->line, "<rotate> angle=\"%s\": give one number", a);
        if ((rc = xyz(c, op, 0.0, v)))
            return rc;
        if (cdl_mat4_rotate(angle, v[0], v[1], v[2], m))
            return cdl_mts_error(c, op->line, "<rotate>: the axis (%g, %g, %g) is zero", v[0], v[1], v[2]);
    } else if (!strcmp(op->name, "matrix")) {
        const char *s = cdl_mts_attr(c, op, "value", &rc);
        if (rc)
            return rc;
        if (!s)
            return cdl_mts_error(c, op->line, "<matrix> needs a \"value\" (16 numbers, row by row)");
        if ((rc = numbers(c, op, "value", s, v, 16, &k)))
            return rc;
        *m = cdl_mat4_identity();
        if (k == 16) {
            for (int i = 0; i < 16; i++)
                m->m[i / 4][i % 4] = v[i];
        } else if (k == 9) { /* Mitsuba 3's 3x3 form */
            for (int i = 0; i < 9; i++)
                m->m[i / 3][i % 3] = v[i];
        } else {
            return cdl_mts_error(c, op->line, "<matrix> has %d numbers; give 16 (or 9), row by row", k);
        }
    } else if (!strcmp(op->name, "lookat") || !strcmp(op->name, "lookAt")) { /* lookAt: Mitsuba 0.3 and before */
        static const double yup[3] = {0, 1, 0};
        double o[3], t[3], up[3];
        if ((rc = triple(c, op, "origin", 1, NULL, o)) || (rc = triple(c, op, "target", 1, NULL, t)) ||
            (rc = triple(c, op, "up", 0, yup, up)))
            return rc;
        /* Mitsuba's look-at frame is pbrt's camera frame: (cross(up, dir),
         * up', dir) at origin; pbrt builds its inverse */
        cdl_mat4 w2c;
        if (cdl_mat4_lookat(o, t, up, &w2c) || cdl_mat4_inverse(&w2c, m))
            return cdl_mts_error(c, op->line, "<lookat>: origin equals target or up is parallel to the view");
    } else {
        return cdl_mts_error(c, op->line, "<%s> is not a transform operation (translate, rotate, scale, matrix, "
                                          "lookat)",
                             op->name);
    }
    if (!cdl_mat4_is_finite(m))
        return cdl_mts_error(c, op->line, "<%s> gives a matrix that is not finite", op->name);
    return 0;
}

int cdl_mts_transform(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_mat4 *out)
{
    *out = cdl_mat4_identity();
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    if (!p)
        return 0;
    if (strcmp(p->name, "transform"))
        return cdl_mts_error(c, p->line, "property \"%s\" must be a <transform>, not <%s>", name, p->name);
    for (int i = 0; i < p->nkids; i++) {
        cdl_mat4 op;
        int rc = transform_op(c, &p->kids[i], &op);
        if (rc)
            return rc;
        *out = cdl_mat4_mul(&op, out);
    }
    if (!cdl_mat4_is_finite(out))
        return cdl_mts_error(c, p->line, "<transform name=\"%s\"> is not finite", name);
    return 0;
}

