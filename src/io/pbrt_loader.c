/* pbrt-v3 / pbrt-v4 scene files: the directive loop, the graphics state
 * (transform, attribute and object blocks), Include, camera and render
 * settings. The context (messages, paths) is in pbrt_ctx.c, lights in
 * pbrt_lights.c, shapes in pbrt_shapes.c, materials and textures in
 * pbrt_materials.c. */
#define _POSIX_C_SOURCE 200809L
#include "io/pbrt_loader.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/log.h"
#include "io/obj_check.h"
#include "io/pbrt_internal.h"

/* ---- tokens of directive arguments ---- */

static cdl_pbrt_lexer *top(cdl_pbrt_ctx *c)
{
    return &c->files[c->nfiles - 1];
}

static int want_string(cdl_pbrt_ctx *c, const char *dir, const char **out)
{
    cdl_pbrt_token t;
    int rc = cdl_pbrt_next(top(c), &t, c->err);
    if (rc)
        return rc;
    if (t.kind != CDL_PBRT_STRING) {
        char txt[96];
        cdl_pbrt_token_text(&t, txt, sizeof txt);
        return cdl_pbrt_error(c, c->line, "%s expects a quoted string, got %s", dir, txt);
    }
    *out = t.s;
    return 0;
}

static int want_numbers(cdl_pbrt_ctx *c, const char *dir, double *v, int n)
{
    for (int i = 0; i < n; i++) {
        cdl_pbrt_token t;
        int rc = cdl_pbrt_next(top(c), &t, c->err);
        if (rc)
            return rc;
        char txt[96];
        cdl_pbrt_token_text(&t, txt, sizeof txt);
        if (cdl_pbrt_word_number(&t, &v[i]))
            return cdl_pbrt_error(c, t.kind == CDL_PBRT_EOF ? c->line : t.line,
                                  "%s expects %d numbers, got %s as number %d", dir, n, txt, i + 1);
        if (!isfinite(v[i]) || fabs(v[i]) > CDL_MAX_COORD)
            return cdl_pbrt_error(c, t.line, "%s: %s is not a finite number within 1e20", dir, txt);
    }
    return 0;
}

static int want_matrix(cdl_pbrt_ctx *c, const char *dir, cdl_mat4 *m)
{
    cdl_pbrt_token t;
    double v[16];
    int rc = cdl_pbrt_next(top(c), &t, c->err);
    if (rc)
        return rc;
    if (t.kind != CDL_PBRT_LBRACK)
        return cdl_pbrt_error(c, c->line, "%s expects [ and 16 numbers ]", dir);
    if ((rc = want_numbers(c, dir, v, 16)))
        return rc;
    if ((rc = cdl_pbrt_next(top(c), &t, c->err)))
        return rc;
    if (t.kind != CDL_PBRT_RBRACK)
        return cdl_pbrt_error(c, c->line, "%s: missing ']' after 16 numbers", dir);
    *m = cdl_mat4_from_pbrt(v);
    return 0;
}

static int read_params(cdl_pbrt_ctx *c)
{
    return cdl_pbrt_parse_params(top(c), &c->ps, c->err);
}

/* An unsupported directive: skip its arguments (everything up to the
 * next bare word that is not a number or a bool). */
static int skip_args(cdl_pbrt_ctx *c)
{
    for (;;) {
        cdl_pbrt_token t;
        double d;
        int rc = cdl_pbrt_peek(top(c), &t, c->err);
        if (rc)
            return rc;
        if (t.kind == CDL_PBRT_EOF ||
            (t.kind == CDL_PBRT_WORD && cdl_pbrt_word_number(&t, &d) && !cdl_pbrt_is_word(&t, "true") &&
             !cdl_pbrt_is_word(&t, "false")))
            return 0;
        cdl_pbrt_next(top(c), &t, c->err);
    }
}

/* ---- graphics state ---- */

static void concat(cdl_pbrt_ctx *c, const cdl_mat4 *m)
{
    if (!c->active_end) /* motion blur: only the start transform is kept */
        c->gs.ctm = cdl_mat4_mul(&c->gs.ctm, m);
}

static int push(cdl_pbrt_ctx *c, cdl_pbrt_block kind)
{
    if (c->nstack == c->capstack) {
        int cap = c->capstack ? 2 * c->capstack : 16;
        cdl_pbrt_gstate *p = realloc(c->stack, sizeof *p * (size_t)cap);
        if (!p)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        c->stack = p;
        c->capstack = cap;
    }
    cdl_pbrt_gstate *g = &c->stack[c->nstack++];
    *g = c->gs;
    g->kind = kind;
    g->line = c->line;
    snprintf(g->file, sizeof g->file, "%s", c->file);
    return 0;
}

static const char *block_name(cdl_pbrt_block k)
{
    return k == CDL_PBRT_ATTR ? "AttributeBegin" : k == CDL_PBRT_XFORM ? "TransformBegin" : "ObjectBegin";
}

static int pop(cdl_pbrt_ctx *c, cdl_pbrt_block kind, const char *dir)
{
    if (c->nstack == 0)
        return cdl_pbrt_error(c, c->line, "%s without a matching %s", dir, block_name(kind));
    cdl_pbrt_gstate *g = &c->stack[c->nstack - 1];
    if (g->kind != kind)
        return cdl_pbrt_error(c, c->line, "%s does not match the %s of %s:%d", dir, block_name(g->kind),
                              g->file, g->line);
    c->nstack--;
    if (kind == CDL_PBRT_XFORM)
        c->gs.ctm = g->ctm; /* TransformEnd restores the transform only (pbrt-v3) */
    else
        c->gs = *g;
    return 0;
}

static int need_world(cdl_pbrt_ctx *c, const char *dir)
{
    if (!c->in_world)
        return cdl_pbrt_error(c, c->line, "%s is only allowed after WorldBegin", dir);
    return 0;
}

static int need_options(cdl_pbrt_ctx *c, const char *dir)
{
    if (c->in_world)
        return cdl_pbrt_error(c, c->line, "%s must come before WorldBegin", dir);
    return 0;
}

static int set_coordsys(cdl_pbrt_ctx *c, const char *name, const cdl_mat4 *m)
{
    for (int i = 0; i < c->ncs; i++)
        if (!strcmp(c->cs[i].name, name)) {
            c->cs[i].m = *m;
            return 0;
        }
    if (c->ncs == c->capcs) {
        int cap = c->capcs ? 2 * c->capcs : 8;
        cdl_pbrt_coordsys *p = realloc(c->cs, sizeof *p * (size_t)cap);
        if (!p)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        c->cs = p;
        c->capcs = cap;
    }
    char *dup = strdup(name);
    if (!dup)
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
    c->cs[c->ncs].name = dup;
    c->cs[c->ncs++].m = *m;
    return 0;
}

/* ---- options block ---- */

static void set_camera(cdl_pbrt_ctx *c, const cdl_mat4 *c2w, double fov)
{
    cdl_scene_settings *set = c->set;
    set->has_camera = 1;
    set->eye = cdl_mat4_point3(c2w, cdl_v3(0, 0, 0));
    set->right = cdl_mat4_vector3(c2w, cdl_v3(1, 0, 0));
    set->up = cdl_mat4_vector3(c2w, cdl_v3(0, 1, 0));
    set->fwd = cdl_mat4_vector3(c2w, cdl_v3(0, 0, 1));
    set->fov = (float)fov;
}

static int camera(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_params *ps = &c->ps;
    cdl_error *err = c->err;
    double fov, half, lens;
    int rc;
    if (strcmp(type, "perspective"))
        cdl_pbrt_warn(c, c->line, "camera \"%s\" is not supported: rendered as a perspective camera", type);
    if ((rc = cdl_pbrt_get_float(ps, "fov", 90.0, &fov, err)) ||
        (rc = cdl_pbrt_get_float(ps, "halffov", -1.0, &half, err)) ||
        (rc = cdl_pbrt_get_float(ps, "lensradius", 0.0, &lens, err)))
        return rc;
    if (half > 0.0)
        fov = 2.0 * half;
    if (!(fov > 0.0 && fov < 180.0))
        return cdl_pbrt_error(c, c->line, "Camera fov %g must be in (0, 180) degrees", fov);
    if (lens > 0.0)
        cdl_pbrt_warn(c, c->line, "lensradius %g ignored: candela's camera is a pinhole", lens);
    cdl_pbrt_find(ps, "focaldistance");
    cdl_pbrt_find(ps, "shutteropen");
    cdl_pbrt_find(ps, "shutterclose");
    if (cdl_pbrt_find(ps, "screenwindow") || cdl_pbrt_find(ps, "frameaspectratio"))
        cdl_pbrt_warn(c, c->line, "screenwindow / frameaspectratio ignored: the image's aspect ratio is used");
    /* pbrt: the current transform is world-to-camera */
    cdl_mat4 c2w;
    if (cdl_mat4_inverse(&c->gs.ctm, &c2w))
        return cdl_pbrt_error(c, c->line, "the camera transform is singular");
    if ((rc = set_coordsys(c, "camera", &c2w)))
        return rc;
    set_camera(c, &c2w, fov);
    c->saw_camera = 1;
    return 0;
}

static int film(cdl_pbrt_ctx *c)
{
    cdl_pbrt_params *ps = &c->ps;
    int w, h, rc;
    const char *fn;
    if ((rc = cdl_pbrt_get_int(ps, "xresolution", 640, &w, c->err)) ||
        (rc = cdl_pbrt_get_int(ps, "yresolution", 480, &h, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "filename", NULL, &fn, c->err)))
        return rc;
    if (w < 1 || w > 16384 || h < 1 || h > 16384)
        return cdl_pbrt_error(c, c->line, "Film resolution %dx%d: each side must be in 1..16384", w, h);
    c->set->width = w;
    c->set->height = h;
    if (fn)
        snprintf(c->set->filename, sizeof c->set->filename, "%s", fn);
    if (cdl_pbrt_find(ps, "cropwindow") || cdl_pbrt_find(ps, "pixelbounds"))
        cdl_pbrt_warn(c, c->line, "Film cropwindow / pixelbounds ignored: the whole image is rendered");
    cdl_pbrt_find(ps, "diagonal"); /* only for realistic cameras */
    return 0;
}

static int sampler(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_params *ps = &c->ps;
    int n, xs, ys, rc;
    if ((rc = cdl_pbrt_get_int(ps, "pixelsamples", 16, &n, c->err)) ||
        (rc = cdl_pbrt_get_int(ps, "xsamples", 4, &xs, c->err)) ||
        (rc = cdl_pbrt_get_int(ps, "ysamples", 4, &ys, c->err)))
        return rc;
    if (!strcmp(type, "stratified")) /* pbrt-v3: xsamples * ysamples per pixel */
        n = (xs > 0 && ys > 0 && xs <= 1000 && ys <= 1000) ? xs * ys : -1;
    if (n < 1 || n > 1000000)
        return cdl_pbrt_error(c, c->line, "Sampler: samples per pixel must be in 1..1000000");
    c->set->spp = n;
    for (size_t i = 0; i < ps->n; i++) /* seeds, jitter, dimensions: noise only */
        ps->p[i].used = 1;
    return 0;
}

/* PixelFilter as pbrt-v3 (xwidth/ywidth: the radii; alpha; "sinc") or
 * pbrt-v4 (xradius/yradius; sigma; "lanczos") defines it; the two agree
 * on every default but the gaussian's radius (v3: 2, v4: 1.5), which
 * follows the parameters' names (v3 without a hint). pbrt spreads samples
 * past the image's edge: clip is off. */
static int filter(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_params *ps = &c->ps;
    int v4 = !strcmp(type, "lanczos") || cdl_pbrt_find(ps, "xradius") || cdl_pbrt_find(ps, "yradius") ||
             cdl_pbrt_find(ps, "sigma");
    int gauss = !strcmp(type, "gaussian"), sinc = !strcmp(type, "sinc") || !strcmp(type, "lanczos");
    double def = !strcmp(type, "box") ? 0.5 : sinc ? 4.0 : (gauss && v4) ? 1.5 : 2.0;
    double rx, ry, p0 = 0.0, p1 = 0.0;
    int rc;
    if ((rc = cdl_pbrt_get_float(ps, v4 ? "xradius" : "xwidth", def, &rx, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, v4 ? "yradius" : "ywidth", def, &ry, c->err)))
        return rc;
    cdl_filter_type t;
    if (!strcmp(type, "box")) {
        t = CDL_FILTER_BOX;
    } else if (!strcmp(type, "triangle")) {
        t = CDL_FILTER_TENT;
    } else if (gauss) {
        t = CDL_FILTER_GAUSSIAN;
        if (v4) {
            double sigma;
            if ((rc = cdl_pbrt_get_float(ps, "sigma", 0.5, &sigma, c->err)))
                return rc;
            if (!(sigma > 0.0 && sigma < 1e3))
                return cdl_pbrt_error(c, c->line, "PixelFilter gaussian: sigma %g must be positive", sigma);
            p0 = 1.0 / (2.0 * sigma * sigma);
        } else if ((rc = cdl_pbrt_get_float(ps, "alpha", 2.0, &p0, c->err))) {
            return rc;
        } else if (!(p0 > 0.0 && p0 < 1e6)) {
            return cdl_pbrt_error(c, c->line, "PixelFilter gaussian: alpha %g must be positive", p0);
        }
    } else if (!strcmp(type, "mitchell")) {
        t = CDL_FILTER_MITCHELL;
        if ((rc = cdl_pbrt_get_float(ps, "B", 1.0 / 3.0, &p0, c->err)) ||
            (rc = cdl_pbrt_get_float(ps, "C", 1.0 / 3.0, &p1, c->err)))
            return rc;
        if (!(fabs(p0) <= 10.0 && fabs(p1) <= 10.0))
            return cdl_pbrt_error(c, c->line, "PixelFilter mitchell: B and C must be in [-10, 10]");
    } else if (sinc) {
        t = CDL_FILTER_LANCZOS;
        if ((rc = cdl_pbrt_get_float(ps, "tau", 3.0, &p0, c->err)))
            return rc;
        if (!(p0 > 0.0 && p0 < 1e3))
            return cdl_pbrt_error(c, c->line, "PixelFilter %s: tau %g must be positive", type, p0);
    } else {
        cdl_pbrt_warn(c, c->line, "PixelFilter \"%s\" falls back to box (one pixel)", type);
        for (size_t i = 0; i < ps->n; i++)
            ps->p[i].used = 1;
        return 0;
    }
    if (!(rx > 0.0 && rx <= 16.0 && ry > 0.0 && ry <= 16.0))
        return cdl_pbrt_error(c, c->line, "PixelFilter %s: radii %g x %g must be in (0, 16] pixels", type, rx, ry);
    cdl_scene_settings *set = c->set;
    if (cdl_filter_init(&set->filter, t, (float)rx, (float)ry, (float)p0, (float)p1, 0))
        return cdl_pbrt_error(c, c->line, "PixelFilter %s: its weights do not integrate to a positive value", type);
    set->has_filter = 1;
    snprintf(set->filter_file, sizeof set->filter_file, "%s", c->ps.file);
    set->filter_line = c->line;
    return 0;
}

static int integrator(cdl_pbrt_ctx *c, const char *type)
{
    cdl_scene_settings *set = c->set;
    int depth, rc;
    if ((rc = cdl_pbrt_get_int(&c->ps, "maxdepth", 5, &depth, c->err)))
        return rc;
    if (depth < 0)
        return cdl_pbrt_error(c, c->line, "Integrator maxdepth %d must be >= 0", depth);
    set->maxdepth = depth;
    snprintf(set->integrator_file, sizeof set->integrator_file, "%s", c->ps.file);
    set->integrator_line = c->line;
    if (!strcmp(type, "path") || !strcmp(type, "volpath")) {
        snprintf(set->integrator, sizeof set->integrator, "path");
    } else if (!strcmp(type, "bdpt")) {
        snprintf(set->integrator, sizeof set->integrator, "bdpt");
    } else if (!strcmp(type, "directlighting")) {
        cdl_pbrt_warn(c, c->line, "Integrator \"directlighting\" rendered as path with maxdepth 1");
        snprintf(set->integrator, sizeof set->integrator, "path");
        set->maxdepth = 1;
    } else {
        /* candela's own methods by name (resolve.c warns about other names) */
        snprintf(set->integrator, sizeof set->integrator, "%s", type);
        if (!cdl_pbrt_find(&c->ps, "maxdepth"))
            set->maxdepth = -1;
    }
    /* the rest for the method's parameter table, as the command line writes them */
    for (size_t i = 0; i < c->ps.n; i++) {
        cdl_pbrt_param *p = &c->ps.p[i];
        if (p->used)
            continue;
        p->used = 1;
        /* pbrt's sppm names its photons per pass so */
        const char *name = !strcmp(p->name, "photonsperiteration") ? "photons" : p->name;
        char v[96] = "";
        for (size_t k = 0; k < p->n; k++) {
            size_t len = strlen(v);
            if (p->is_str)
                snprintf(v + len, sizeof v - len, "%s%s", k ? "," : "", cdl_pbrt_str(&c->ps, p, k));
            else if (p->type == CDL_PT_BOOL)
                snprintf(v + len, sizeof v - len, "%s%s", k ? "," : "", cdl_pbrt_nums(&c->ps, p)[k] ? "on" : "off");
            else
                snprintf(v + len, sizeof v - len, "%s%.17g", k ? "," : "", cdl_pbrt_nums(&c->ps, p)[k]);
        }
        cdl_scene_settings_param(set, name, v, c->ps.file, p->line);
    }
    return 0;
}

/* ---- Include ---- */

static int include(cdl_pbrt_ctx *c, const char *name)
{
    char path[1024];
    struct stat st;
    int rc;
    if (c->nfiles > CDL_PBRT_MAX_INCLUDE)
        return cdl_pbrt_error(c, c->line, "Include \"%s\": files nested deeper than %d", name,
                              CDL_PBRT_MAX_INCLUDE);
    cdl_pbrt_resolve(c, name, path, sizeof path);
    if ((rc = cdl_pbrt_check_file(c, "Include file", path)))
        return rc;
    if (stat(path, &st) == 0)
        for (int i = 0; i < c->nfiles; i++)
            if (c->files[i].dev == st.st_dev && c->files[i].ino == st.st_ino)
                return cdl_pbrt_error(c, c->line, "Include cycle: \"%s\" is already being read", path);
    cdl_error sub;
    if (cdl_pbrt_lexer_open(&c->files[c->nfiles], path, &sub)) {
        if (sub.line > 0) { /* binary data in the included file: name it */
            *c->err = sub;
            return sub.code;
        }
        return cdl_error_set(c->err, sub.code, c->file, c->line, "Include \"%s\": %s", path, sub.msg);
    }
    c->nfiles++;
    return 0;
}

/* ---- directives ---- */

typedef struct word {
    const char *s;
    size_t n;
} word;

static int is(word w, const char *name)
{
    return strlen(name) == w.n && !memcmp(w.s, name, w.n);
}

static int directive(cdl_pbrt_ctx *c, word w)
{
    char dir[64];
    snprintf(dir, sizeof dir, "%.*s", (int)(w.n < 60 ? w.n : 60), w.s);
    double v[9];
    const char *a = NULL, *b, *cls;
    cdl_mat4 m;
    int rc = 0;
    int xform = is(w, "Translate") || is(w, "Scale") || is(w, "Rotate") || is(w, "LookAt") ||
                is(w, "Transform") || is(w, "ConcatTransform") || is(w, "Identity") ||
                is(w, "CoordSysTransform");
    if (xform) {
        if (is(w, "Translate") && !(rc = want_numbers(c, dir, v, 3))) {
            m = cdl_mat4_translate(v[0], v[1], v[2]);
            concat(c, &m);
        } else if (is(w, "Scale") && !(rc = want_numbers(c, dir, v, 3))) {
            m = cdl_mat4_scale(v[0], v[1], v[2]);
            concat(c, &m);
        } else if (is(w, "Rotate") && !(rc = want_numbers(c, dir, v, 4))) {
            if (cdl_mat4_rotate(v[0], v[1], v[2], v[3], &m))
                return cdl_pbrt_error(c, c->line, "Rotate about a zero axis");
            concat(c, &m);
        } else if (is(w, "LookAt") && !(rc = want_numbers(c, dir, v, 9))) {
            if (cdl_mat4_lookat(v, v + 3, v + 6, &m))
                return cdl_pbrt_error(c, c->line,
                                      "LookAt: eye equals look, or up is parallel to the view direction");
            concat(c, &m);
        } else if (is(w, "Transform") && !(rc = want_matrix(c, dir, &m))) {
            if (!c->active_end)
                c->gs.ctm = m;
        } else if (is(w, "ConcatTransform") && !(rc = want_matrix(c, dir, &m))) {
            concat(c, &m);
        } else if (is(w, "Identity")) {
            if (!c->active_end)
                c->gs.ctm = cdl_mat4_identity();
        } else if (is(w, "CoordSysTransform") && !(rc = want_string(c, dir, &a))) {
            int i = c->ncs;
            while (i-- > 0 && strcmp(c->cs[i].name, a))
                ;
            if (i < 0)
                return cdl_pbrt_error(c, c->line, "CoordSysTransform: no coordinate system \"%s\"", a);
            c->gs.ctm = c->cs[i].m;
        }
        return rc;
    }
    if (is(w, "CoordinateSystem")) {
        if ((rc = want_string(c, dir, &a)))
            return rc;
        return set_coordsys(c, a, &c->gs.ctm);
    }
    if (is(w, "Include") || is(w, "Import")) {
        if ((rc = want_string(c, dir, &a)))
            return rc;
        return include(c, a);
    }
    if (is(w, "ActiveTransform")) {
        cdl_pbrt_token t;
        if ((rc = cdl_pbrt_next(top(c), &t, c->err)))
            return rc;
        if (cdl_pbrt_is_word(&t, "All") || cdl_pbrt_is_word(&t, "StartTime")) {
            c->active_end = 0;
        } else if (cdl_pbrt_is_word(&t, "EndTime")) {
            cdl_pbrt_warn(c, c->line, "ActiveTransform EndTime: motion blur is not supported, the "
                                      "start transform is used");
            c->active_end = 1;
        } else {
            return cdl_pbrt_error(c, c->line, "ActiveTransform expects All, StartTime or EndTime");
        }
        return 0;
    }
    /* directives with a name and a parameter list */
    int opt = is(w, "Camera") || is(w, "Film") || is(w, "Sampler") || is(w, "PixelFilter") ||
              is(w, "Integrator") || is(w, "Accelerator");
    int wld = is(w, "Shape") || is(w, "Material") || is(w, "MakeNamedMaterial") ||
              is(w, "LightSource") || is(w, "AreaLightSource") || is(w, "Texture");
    if (opt || wld) {
        if ((rc = opt ? need_options(c, dir) : need_world(c, dir)) || (rc = want_string(c, dir, &a)))
            return rc;
        b = cls = NULL;
        if (is(w, "Texture") && ((rc = want_string(c, dir, &b)) || (rc = want_string(c, dir, &cls))))
            return rc;
        if ((rc = read_params(c)))
            return rc;
        if (is(w, "Camera"))
            rc = camera(c, a);
        else if (is(w, "Film"))
            rc = film(c);
        else if (is(w, "Sampler"))
            rc = sampler(c, a);
        else if (is(w, "PixelFilter"))
            rc = filter(c, a);
        else if (is(w, "Integrator"))
            rc = integrator(c, a);
        else if (is(w, "Accelerator"))
            for (size_t i = 0; i < c->ps.n; i++)
                c->ps.p[i].used = 1;
        else if (is(w, "Shape"))
            rc = cdl_pbrt_shape_directive(c, a);
        else if (is(w, "LightSource"))
            rc = cdl_pbrt_light(c, a);
        else if (is(w, "AreaLightSource"))
            rc = cdl_pbrt_area_light(c, a);
        else if (is(w, "Texture"))
            rc = cdl_pbrt_texture(c, a, b, cls);
        else if (is(w, "Material")) {
            if (!*a || !strcmp(a, "none") || !strcmp(a, "interface"))
                c->gs.mat = CDL_PBRT_MAT_NONE;
            else
                rc = cdl_pbrt_material(c, a, NULL, &c->gs.mat);
        } else { /* MakeNamedMaterial */
            const char *type;
            int32_t id;
            if ((rc = cdl_pbrt_get_string(&c->ps, "type", NULL, &type, c->err)))
                return rc;
            if (!type)
                return cdl_pbrt_error(c, c->line, "MakeNamedMaterial \"%s\" has no \"string type\"", a);
            if (!*type || !strcmp(type, "none") || !strcmp(type, "interface"))
                id = CDL_PBRT_MAT_NONE;
            else if ((rc = cdl_pbrt_material(c, type, a, &id)))
                return rc;
            if (c->nnamed == c->capnamed) {
                int cap = c->capnamed ? 2 * c->capnamed : 16;
                cdl_pbrt_named *p = realloc(c->named, sizeof *p * (size_t)cap);
                if (!p)
                    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
                c->named = p;
                c->capnamed = cap;
            }
            if (!(c->named[c->nnamed].name = strdup(a)))
                return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
            c->named[c->nnamed++].mat = id;
        }
        if (!rc)
            cdl_pbrt_warn_unused(&c->ps, dir);
        return rc;
    }
    if (is(w, "WorldBegin")) {
        if (c->in_world)
            return cdl_pbrt_error(c, c->line, "WorldBegin appears twice");
        c->in_world = 1;
        c->gs.ctm = cdl_mat4_identity();
        return set_coordsys(c, "world", &c->gs.ctm);
    }
    if (is(w, "WorldEnd")) {
        if ((rc = need_world(c, dir)))
            return rc;
        /* pbrt-v3 closes open blocks at WorldEnd with a warning */
        for (; c->nstack > 0; c->nstack--) {
            cdl_pbrt_gstate *g = &c->stack[c->nstack - 1];
            cdl_pbrt_warn(c, c->line, "WorldEnd closes the %s of %s:%d", block_name(g->kind), g->file,
                          g->line);
        }
        if (c->cur_obj >= 0 && (rc = cdl_pbrt_object_end(c)))
            return rc;
        c->world_done = 1;
        return 0;
    }
    if (is(w, "AttributeBegin"))
        return (rc = need_world(c, dir)) ? rc : push(c, CDL_PBRT_ATTR);
    if (is(w, "AttributeEnd"))
        return (rc = need_world(c, dir)) ? rc : pop(c, CDL_PBRT_ATTR, dir);
    if (is(w, "TransformBegin"))
        return push(c, CDL_PBRT_XFORM);
    if (is(w, "TransformEnd"))
        return pop(c, CDL_PBRT_XFORM, dir);
    if (is(w, "ReverseOrientation")) {
        if ((rc = need_world(c, dir)))
            return rc;
        c->gs.reverse = !c->gs.reverse;
        return 0;
    }
    if (is(w, "NamedMaterial")) {
        if ((rc = need_world(c, dir)) || (rc = want_string(c, dir, &a)))
            return rc;
        int i = c->nnamed;
        while (i-- > 0 && strcmp(c->named[i].name, a))
            ;
        if (i < 0)
            return cdl_pbrt_error(c, c->line, "NamedMaterial \"%s\" is not defined", a);
        c->gs.mat = c->named[i].mat;
        return 0;
    }
    if (is(w, "ObjectBegin")) {
        if ((rc = need_world(c, dir)) || (rc = want_string(c, dir, &a)))
            return rc;
        if (c->cur_obj >= 0)
            return cdl_pbrt_error(c, c->line, "ObjectBegin \"%s\" inside the definition of \"%s\"", a,
                                  c->objs[c->cur_obj].name);
        if ((rc = cdl_pbrt_object_begin(c, a)))
            return rc;
        return push(c, CDL_PBRT_OBJECT); /* pbrt: ObjectBegin implies AttributeBegin */
    }
    if (is(w, "ObjectEnd")) {
        if ((rc = need_world(c, dir)))
            return rc;
        if (c->cur_obj < 0)
            return cdl_pbrt_error(c, c->line, "ObjectEnd without ObjectBegin");
        if ((rc = cdl_pbrt_object_end(c)))
            return rc;
        return pop(c, CDL_PBRT_OBJECT, dir);
    }
    if (is(w, "ObjectInstance")) {
        if ((rc = need_world(c, dir)) || (rc = want_string(c, dir, &a)))
            return rc;
        if (c->cur_obj >= 0)
            return cdl_pbrt_error(c, c->line, "ObjectInstance inside the definition of object \"%s\"",
                                  c->objs[c->cur_obj].name);
        return cdl_pbrt_object_instance(c, a);
    }
    cdl_pbrt_warn(c, c->line, "directive %s is not supported (skipped)", dir);
    return skip_args(c);
}

static void ctx_free(cdl_pbrt_ctx *c)
{
    for (int i = 0; i < c->nfiles; i++)
        cdl_pbrt_lexer_close(&c->files[i]);
    cdl_pbrt_params_free(&c->ps);
    free(c->stack);
    for (int i = 0; i < c->nnamed; i++)
        free(c->named[i].name);
    free(c->named);
    cdl_pbrt_textures_free(c);
    free(c->variants);
    for (int i = 0; i < c->ncs; i++)
        free(c->cs[i].name);
    free(c->cs);
    for (int i = 0; i < c->nobjs; i++)
        free(c->objs[i].name);
    free(c->objs);
}

static int parse(cdl_pbrt_ctx *c)
{
    int rc;
    for (;;) {
        cdl_pbrt_lexer *lx = top(c);
        cdl_pbrt_token t;
        if ((rc = cdl_pbrt_next(lx, &t, c->err)))
            return rc;
        if (t.kind == CDL_PBRT_EOF) {
            if (c->nfiles == 1)
                return 0;
            cdl_pbrt_lexer_close(lx);
            c->nfiles--;
            continue;
        }
        c->file = lx->path;
        c->line = t.line;
        double d;
        char txt[96];
        cdl_pbrt_token_text(&t, txt, sizeof txt);
        if (t.kind != CDL_PBRT_WORD || !cdl_pbrt_word_number(&t, &d) || cdl_pbrt_is_word(&t, "true") ||
            cdl_pbrt_is_word(&t, "false"))
            return cdl_pbrt_error(c, t.line, "expected a directive, got %s%s", txt,
                                  t.kind == CDL_PBRT_RBRACK ? " (unbalanced brackets)"
                                  : t.kind == CDL_PBRT_WORD ? " (too many values for the previous directive?)"
                                                            : "");
        if (c->world_done)
            return cdl_pbrt_error(c, t.line, "%s after WorldEnd", txt);
        if ((rc = directive(c, (word){t.s, t.len})))
            return rc;
    }
}

int cdl_load_pbrt(cdl_scene *s, const char *path, cdl_scene_settings *set, cdl_error *err)
{
    cdl_scene_settings dummy;
    if (!set) {
        cdl_scene_settings_init(&dummy);
        set = &dummy;
    }
    cdl_pbrt_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    c->s = s;
    c->set = set;
    c->err = err;
    c->main_path = path;
    c->file = path;
    c->gs.ctm = cdl_mat4_identity();
    c->gs.mat = CDL_PBRT_MAT_DEFAULT;
    c->cur_obj = -1;
    c->default_mat = -1;
    c->black_mat = -1;
    /* what pbrt renders when the file does not say: 640x480, 16 spp,
     * path tracing with maxdepth 5, a camera at the origin looking down +z */
    set->width = 640;
    set->height = 480;
    set->spp = 16;
    set->maxdepth = 5;
    snprintf(set->integrator, sizeof set->integrator, "path");
    int rc = cdl_pbrt_lexer_open(&c->files[0], path, err);
    if (!rc) {
        c->nfiles = 1;
        rc = parse(c);
    }
    if (!rc) {
        c->file = path;
        for (int i = c->nstack; i-- > 0;)
            cdl_warn(c->stack[i].file, c->stack[i].line, "%s is never closed",
                     block_name(c->stack[i].kind));
        if (c->cur_obj >= 0)
            rc = cdl_pbrt_object_end(c);
        if (!c->saw_camera) {
            cdl_mat4 id = cdl_mat4_identity();
            set_camera(c, &id, 90.0);
        }
        if (!rc && s->ntris == 0 && s->nspheres == 0 && s->ninsts == 0)
            rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                               c->nshapes ? "scene has no (non-degenerate) geometry"
                                          : "scene has no geometry (no Shape)");
    }
    ctx_free(c);
    free(c);
    return rc;
}
