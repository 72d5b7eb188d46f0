/* Mitsuba 0.6 and Mitsuba 3 scene files: the element walk, <default> and
 * $variables, <include>, ids, and the sensor, film, sampler and integrator
 * settings. Property values and transforms are in mitsuba_values.c, shapes
 * in mitsuba_shapes.c, bsdfs, textures and emitters in mitsuba_materials.c. */
#define _POSIX_C_SOURCE 200809L
#include "io/mitsuba_loader.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/file.h"
#include "core/log.h"
#include "io/mitsuba_internal.h"

#define PI 3.14159265358979323846

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

static const char *var_get(const cdl_mts_ctx *c, const char *name, size_t len)
{
    for (int i = 0; i < c->nvars; i++)
        if (strlen(c->vars[i].name) == len && !strncmp(c->vars[i].name, name, len))
            return c->vars[i].value;
    return NULL;
}

static int oom(cdl_mts_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, 0, "out of memory");
}

/* <default name value>: defines name unless it is defined already. */
static int var_default(cdl_mts_ctx *c, const cdl_xml_node *n)
{
    const char *name = cdl_xml_attr_get(n, "name"), *value = cdl_xml_attr_get(n, "value");
    if (!name || !value)
        return cdl_mts_error(c, n->line, "<default> needs \"name\" and \"value\"");
    if (!*name)
        return cdl_mts_error(c, n->line, "<default>: empty name");
    for (const char *p = name; *p; p++)
        if (!isalnum((unsigned char)*p) && *p != '_')
            return cdl_mts_error(c, n->line, "<default>: \"%s\" is not a parameter name (letters, digits, _)", name);
    if (var_get(c, name, strlen(name)))
        return 0;
    if (c->nvars == c->capvars) {
        int cap = c->capvars ? 2 * c->capvars : 8;
        cdl_mts_var *v = realloc(c->vars, sizeof *v * (size_t)cap);
        if (!v)
            return oom(c);
        c->vars = v;
        c->capvars = cap;
    }
    cdl_mts_var *v = &c->vars[c->nvars];
    v->name = strdup(name);
    v->value = strdup(value);
    if (!v->name || !v->value) {
        free(v->name);
        free(v->value);
        return oom(c);
    }
    c->nvars++;
    return 0;
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
            add = var_get(c, p + 1, (size_t)(q - p - 1));
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

int cdl_mts_path(cdl_mts_ctx *c, int line, const char *name, char *out, size_t n)
{
    cdl_path_join_dir(c->main_path, name, out, n);
    struct stat st;
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

/* ---- sensor, film, sampler, integrator ---- */

static int film(cdl_mts_ctx *c, cdl_xml_node *f, long *w, long *h)
{
    char type[64];
    int rc = cdl_mts_type(c, f, type, sizeof type);
    if (rc)
        return rc;
    f->used = 1;
    if (strcmp(type, "hdrfilm") && strcmp(type, "ldrfilm") && strcmp(type, "specfilm") && strcmp(type, "mfilm"))
        cdl_mts_warn(c, f->line, "film \"%s\": only its size is used", type);
    /* Mitsuba's default film is 768 x 576 */
    if ((rc = cdl_mts_int(c, f, "width", 768, w)) || (rc = cdl_mts_int(c, f, "height", 576, h)))
        return rc;
    if (*w < 1 || *h < 1 || *w > 65536 || *h > 65536)
        return cdl_mts_error(c, f->line, "film size %ld x %ld must be in 1..65536", *w, *h);
    for (int i = 0; i < f->nkids; i++) {
        cdl_xml_node *k = &f->kids[i];
        const char *pn = cdl_xml_attr_get(k, "name");
        if (!strcmp(k->name, "rfilter")) {
            k->used = 1; /* candela's pixel filter is a box */
        } else if (pn && (cdl_mts_same_name(pn, "crop_offset_x") || cdl_mts_same_name(pn, "crop_width") ||
                          cdl_mts_same_name(pn, "crop_offset_y") || cdl_mts_same_name(pn, "crop_height"))) {
            cdl_mts_warn(c, k->line, "film crop ignored: the whole image is rendered");
            k->used = 1;
        } else if (pn) {
            k->used = 1; /* file format, pixel format, banner, ...: output details */
        }
    }
    cdl_mts_warn_unused(c, f, "film");
    return 0;
}

/* The fov along fov_axis as candela's fov on the shorter image axis. */
static int shorter_axis_fov(cdl_mts_ctx *c, int line, double fov, const char *axis, long w, long h, double *out)
{
    double t = tan(fov * PI / 360.0), sw = (double)w, sh = (double)h, s = sw < sh ? sw : sh;
    double l = sw < sh ? sh : sw, along;
    if (!strcmp(axis, "x"))
        along = sw;
    else if (!strcmp(axis, "y"))
        along = sh;
    else if (!strcmp(axis, "diagonal"))
        along = sqrt(sw * sw + sh * sh);
    else if (!strcmp(axis, "smaller"))
        along = s;
    else if (!strcmp(axis, "larger"))
        along = l;
    else
        return cdl_mts_error(c, line, "fov_axis \"%s\" must be x, y, diagonal, smaller or larger", axis);
    *out = 2.0 * atan(t * s / along) * 180.0 / PI;
    return 0;
}

static int sensor(cdl_mts_ctx *c, cdl_xml_node *n)
{
    char type[64], axis[32];
    int rc = cdl_mts_type(c, n, type, sizeof type);
    if (rc)
        return rc;
    if (c->saw_sensor) {
        cdl_mts_warn(c, n->line, "a second <sensor>: only the first is used");
        return 0;
    }
    c->saw_sensor = 1;
    int thin = !strcmp(type, "thinlens");
    if (strcmp(type, "perspective") && !thin) {
        cdl_mts_warn(c, n->line, "sensor \"%s\" is not supported (candela's default camera is used)", type);
        return 0;
    }
    if (thin)
        cdl_mts_warn(c, n->line, "sensor \"thinlens\": rendered as a pinhole (no depth of field)");
    long w = 768, h = 576, spp;
    double fov;
    cdl_mat4 m;
    for (int i = 0; i < n->nkids && !rc; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (!strcmp(k->name, "film")) {
            rc = film(c, k, &w, &h);
        } else if (!strcmp(k->name, "sampler")) {
            k->used = 1;
            if (!(rc = cdl_mts_int(c, k, "sample_count", 4, &spp))) {
                if (spp < 1 || spp > (1L << 30))
                    rc = cdl_mts_error(c, k->line, "sample_count %ld must be in 1..2^30", spp);
                c->set->spp = (int)spp;
            }
            for (int j = 0; j < k->nkids; j++)
                k->kids[j].used = 1; /* seeds, dimensions: candela's own sampler */
        }
    }
    if (rc)
        return rc;
    if ((rc = cdl_mts_float(c, n, "fov", 0.0, &fov)) || (rc = cdl_mts_string(c, n, "fov_axis", "x", axis, sizeof axis)) ||
        (rc = cdl_mts_transform(c, n, "to_world", &m)))
        return rc;
    if (!cdl_mts_prop(c, n, "fov")) {
        double fl;
        char fs[32];
        if ((rc = cdl_mts_string(c, n, "focal_length", "50mm", fs, sizeof fs)))
            return rc;
        fl = strtod(fs, NULL);
        if (!(fl > 0.0 && fl < 1e6))
            return cdl_mts_error(c, n->line, "focal_length \"%s\" must be a positive length in mm", fs);
        fov = 2.0 * atan(36.0 / (2.0 * fl)) * 180.0 / PI; /* of a 36 mm film's width */
        snprintf(axis, sizeof axis, "x");
    }
    if (!(fov > 0.0 && fov < 180.0))
        return cdl_mts_error(c, n->line, "fov %g must be in (0, 180) degrees", fov);
    double f;
    if ((rc = shorter_axis_fov(c, n->line, fov, axis, w, h, &f)))
        return rc;
    for (int i = 0; i < n->nkids; i++) {
        const char *pn = cdl_xml_attr_get(&n->kids[i], "name");
        if (pn && (cdl_mts_same_name(pn, "near_clip") || cdl_mts_same_name(pn, "far_clip") ||
                   cdl_mts_same_name(pn, "focus_distance") || cdl_mts_same_name(pn, "aperture_radius") ||
                   cdl_mts_same_name(pn, "shutter_open") || cdl_mts_same_name(pn, "shutter_close")))
            n->kids[i].used = 1;
    }
    cdl_mts_warn_unused(c, n, "sensor");
    /* Mitsuba's camera looks down +z with +x to the image's left */
    cdl_scene_settings *set = c->set;
    set->has_camera = 1;
    set->eye = cdl_mat4_point3(&m, cdl_v3(0, 0, 0));
    set->right = cdl_scale(cdl_mat4_vector3(&m, cdl_v3(1, 0, 0)), -1.0f);
    set->up = cdl_mat4_vector3(&m, cdl_v3(0, 1, 0));
    set->fwd = cdl_mat4_vector3(&m, cdl_v3(0, 0, 1));
    set->fov = (float)f;
    set->width = (int)w;
    set->height = (int)h;
    if (!(cdl_length(set->fwd) > 0.0f) || !(cdl_length(set->up) > 0.0f) || !(cdl_length(set->right) > 0.0f))
        return cdl_mts_error(c, n->line, "sensor to_world is singular");
    return 0;
}

static int integrator(cdl_mts_ctx *c, cdl_xml_node *n)
{
    char type[64];
    int rc = cdl_mts_type(c, n, type, sizeof type);
    if (rc)
        return rc;
    static const char *const map[][2] = {{"path", "path"},         {"volpath", "path"}, {"volpath_simple", "path"},
                                         {"direct", "path"},       {"bdpt", "bdpt"},    {"photonmapper", "pm"},
                                         {"sppm", "pm"},           {"ppm", "pm"}};
    const char *ours = NULL;
    for (size_t i = 0; i < sizeof map / sizeof map[0]; i++)
        if (!strcmp(type, map[i][0]))
            ours = map[i][1];
    /* wrappers (irrcache, aov, moment, ...) hold the integrator that does the work */
    for (int i = 0; i < n->nkids; i++)
        if (!strcmp(n->kids[i].name, "integrator")) {
            n->kids[i].used = 1;
            if (!ours)
                return integrator(c, &n->kids[i]);
        }
    /* candela's own methods by name too (resolve.c warns about other names) */
    snprintf(c->set->integrator, sizeof c->set->integrator, "%.31s", ours ? ours : type);
    snprintf(c->set->integrator_file, sizeof c->set->integrator_file, "%s", c->file);
    c->set->integrator_line = n->line;
    long depth;
    if ((rc = cdl_mts_int(c, n, "max_depth", -1, &depth)))
        return rc;
    /* Mitsuba's max_depth counts path segments (1: emitters seen directly),
     * candela's (pbrt's) bounces; -1 is unlimited */
    if (!strcmp(type, "direct"))
        depth = 2;
    if (depth == 0)
        return cdl_mts_error(c, n->line, "integrator max_depth 0 renders nothing: give -1 or >= 1");
    if (depth < -1 || depth > 100000)
        return cdl_mts_error(c, n->line, "integrator max_depth %ld must be -1 or in 1..100000", depth);
    c->set->maxdepth = depth < 0 ? 1024 : (int)depth - 1;
    /* the rest for the method's parameter table (resolve.c warns about those
     * it does not read); Mitsuba's photon mapper names in candela's terms */
    static const char *const alias[][2] = {{"global_photons", "photons"}, {"globalPhotons", "photons"},
                                           {"photon_count", "photons"},   {"photonCount", "photons"},
                                           {"lookup_size", "knn"},        {"lookupSize", "knn"},
                                           {"global_lookup_radius", "max_radius"},
                                           {"globalLookupRadius", "max_radius"}};
    for (int i = 0; i < n->nkids; i++) {
        cdl_xml_node *k = &n->kids[i];
        const char *name = cdl_xml_attr_get(k, "name"), *value = cdl_xml_attr_get(k, "value");
        if (k->used || !name)
            continue;
        k->used = 1;
        for (size_t a = 0; a < sizeof alias / sizeof alias[0]; a++)
            if (!strcmp(name, alias[a][0]))
                name = alias[a][1];
        cdl_scene_settings_param(c->set, name, value ? value : "", c->file, k->line);
    }
    return 0;
}

/* ---- the element walk ---- */

static int read_file(cdl_mts_ctx *c, const char *path, int line);

static int element(cdl_mts_ctx *c, cdl_xml_node *n)
{
    int rc = 0;
    n->used = 1;
    if (!strcmp(n->name, "default"))
        return var_default(c, n);
    if (!strcmp(n->name, "include")) {
        const char *fn = cdl_mts_attr(c, n, "filename", &rc);
        char path[1024];
        if (rc)
            return rc;
        if (!fn)
            return cdl_mts_error(c, n->line, "<include> needs a \"filename\"");
        if ((rc = cdl_mts_path(c, n->line, fn, path, sizeof path)))
            return rc;
        return read_file(c, path, n->line);
    }
    if (!strcmp(n->name, "integrator"))
        return integrator(c, n);
    if (!strcmp(n->name, "sensor"))
        return sensor(c, n);
    if (!strcmp(n->name, "shape"))
        return cdl_mts_shape(c, n);
    if (!strcmp(n->name, "emitter"))
        return cdl_mts_emitter(c, n);
    if (!strcmp(n->name, "bsdf") || !strcmp(n->name, "texture")) {
        int rc2 = 0;
        const char *id = cdl_mts_attr(c, n, "id", &rc2);
        if (rc2)
            return rc2;
        cdl_mts_id v = {NULL, CDL_MTS_BSDF, -1, -1, cdl_v3(0, 0, 0)};
        char idbuf[256];
        if (!id || !*id) {
            cdl_mts_warn(c, n->line, "<%s> without an id cannot be referred to (ignored)", n->name);
            return 0;
        }
        snprintf(idbuf, sizeof idbuf, "%s", id);
        v.id = idbuf;
        if (n->name[0] == 'b') {
            rc = cdl_mts_bsdf(c, n, &v.mat);
        } else {
            v.kind = CDL_MTS_TEXTURE;
            rc = cdl_mts_texture(c, n, &v.tex, &v.value);
        }
        return rc ? rc : cdl_mts_add_id(c, n, &v);
    }
    cdl_mts_warn(c, n->line, "<%s> is not supported (ignored)", n->name);
    return 0;
}

static int read_file(cdl_mts_ctx *c, const char *path, int line)
{
    if (c->depth >= CDL_MTS_MAX_INCLUDE)
        return cdl_mts_error(c, line, "includes nested deeper than %d", CDL_MTS_MAX_INCLUDE);
    cdl_xml_doc doc;
    int rc = cdl_xml_load(path, &doc, c->err);
    if (rc)
        return rc;
    const char *outer = c->file;
    c->file = path;
    c->depth++;
    if (strcmp(doc.root.name, "scene")) {
        rc = cdl_mts_error(c, doc.root.line, "the document element is <%s>, not <scene>", doc.root.name);
    } else {
        const char *ver = cdl_xml_attr_get(&doc.root, "version");
        if (ver && !(ver[0] == '0' || !strncmp(ver, "2.", 2) || !strncmp(ver, "3.", 2)))
            cdl_mts_warn(c, doc.root.line, "scene version \"%s\": read as Mitsuba 3", ver);
        for (int i = 0; i < doc.root.nkids && !rc; i++)
            rc = element(c, &doc.root.kids[i]);
    }
    c->depth--;
    c->file = outer;
    cdl_xml_free(&doc);
    return rc;
}

int cdl_load_mitsuba(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err)
{
    cdl_scene_settings dummy;
    if (!set) {
        cdl_scene_settings_init(&dummy);
        set = &dummy;
    }
    cdl_mts_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    c->s = s;
    c->set = set;
    c->err = err;
    c->main_path = path;
    c->file = path;
    c->default_mat = -1;
    /* what Mitsuba renders when the file does not say: a 768 x 576 film,
     * 4 samples per pixel, path tracing without a depth limit */
    set->width = 768;
    set->height = 576;
    set->spp = 4;
    int rc = read_file(c, path, 0);
    if (!rc && !c->saw_sensor) {
        set->has_camera = 1; /* at the origin, looking down +z, 45 degrees along x */
        set->eye = cdl_v3(0, 0, 0);
        set->right = cdl_v3(-1, 0, 0);
        set->up = cdl_v3(0, 1, 0);
        set->fwd = cdl_v3(0, 0, 1);
        double f;
        shorter_axis_fov(c, 0, 45.0, "x", 768, 576, &f);
        set->fov = (float)f;
    }
    if (!rc && s->ntris == 0 && s->nspheres == 0)
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                           c->nshapes ? "scene has no (non-degenerate) geometry" : "scene has no geometry (no <shape>)");
    for (int i = 0; i < c->nvars; i++) {
        free(c->vars[i].name);
        free(c->vars[i].value);
    }
    free(c->vars);
    for (int i = 0; i < c->nids; i++)
        free(c->ids[i].id);
    free(c->ids);
    free(c);
    return rc;
}
