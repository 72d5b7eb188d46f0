/* Mitsuba 0.6 and Mitsuba 3 scene files: the element walk, <include>, and
 * the sensor, film, sampler and integrator settings. The context
 * (messages, attributes, <default> and $variables, ids) is in
 * mitsuba_ctx.c, property values and transforms in mitsuba_values.c, shapes
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

/* ---- sensor, film, sampler, integrator ---- */

/* A film's <rfilter>, or Mitsuba's default (a Gaussian of stddev 0.5)
 * when k is NULL. Mitsuba samples only inside the image: clip is on. */
static int rfilter(cdl_mts_ctx *c, cdl_xml_node *k, int line)
{
    char type[64] = "gaussian";
    int rc;
    cdl_filter *f = &c->set->filter;
    double p0 = 0.0, p1 = 0.0, r = 0.5;
    if (k) {
        k->used = 1;
        if ((rc = cdl_mts_type(c, k, type, sizeof type)))
            return rc;
        line = k->line;
    }
    cdl_filter_type t;
    if (!strcmp(type, "box")) {
        t = CDL_FILTER_BOX;
    } else if (!strcmp(type, "tent")) {
        t = CDL_FILTER_TENT;
        if (k && (rc = cdl_mts_float(c, k, "radius", 1.0, &r)))
            return rc;
        r = k ? r : 1.0;
    } else if (!strcmp(type, "gaussian")) {
        double sd = 0.5;
        if (k && (rc = cdl_mts_float(c, k, "stddev", 0.5, &sd)))
            return rc;
        if (!(sd > 0.0 && sd <= 4.0))
            return cdl_mts_error(c, line, "rfilter gaussian: stddev %g must be in (0, 4]", sd);
        t = CDL_FILTER_GAUSSIAN;
        r = 4.0 * sd; /* cut off after 4 standard deviations */
        p0 = 1.0 / (2.0 * sd * sd);
    } else if (!strcmp(type, "mitchell") || !strcmp(type, "catmullrom")) {
        t = CDL_FILTER_MITCHELL;
        r = 2.0;
        p0 = type[0] == 'c' ? 0.0 : 1.0 / 3.0;
        p1 = type[0] == 'c' ? 0.5 : 1.0 / 3.0;
        if (k && type[0] == 'm' && ((rc = cdl_mts_float(c, k, "B", p0, &p0)) || (rc = cdl_mts_float(c, k, "C", p1, &p1))))
            return rc;
        if (!(fabs(p0) <= 10.0 && fabs(p1) <= 10.0))
            return cdl_mts_error(c, line, "rfilter mitchell: B and C must be in [-10, 10]");
    } else if (!strcmp(type, "lanczos")) {
        long lobes = 3;
        if (k && (rc = cdl_mts_int(c, k, "lobes", 3, &lobes)))
            return rc;
        if (lobes < 1 || lobes > 16)
            return cdl_mts_error(c, line, "rfilter lanczos: lobes %ld must be in 1..16", lobes);
        t = CDL_FILTER_LANCZOS;
        r = p0 = (double)lobes;
    } else {
        cdl_mts_warn(c, line, "rfilter \"%s\" is not supported: the box is used", type);
        for (int i = 0; k && i < k->nkids; i++)
            k->kids[i].used = 1;
        return 0;
    }
    if (!(r > 0.0 && r <= 16.0))
        return cdl_mts_error(c, line, "rfilter %s: radius %g must be in (0, 16] pixels", type, r);
    if (k)
        cdl_mts_warn_unused(c, k, "rfilter");
    if (cdl_filter_init(f, t, (float)r, (float)r, (float)p0, (float)p1, 1))
        return cdl_mts_error(c, line, "rfilter %s: its weights do not integrate to a positive value", type);
    c->set->has_filter = 1;
    snprintf(c->set->filter_file, sizeof c->set->filter_file, "%s", c->file);
    c->set->filter_line = line;
    return 0;
}

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
    cdl_xml_node *rf = NULL;
    for (int i = 0; i < f->nkids; i++) {
        cdl_xml_node *k = &f->kids[i];
        const char *pn = cdl_xml_attr_get(k, "name");
        if (!strcmp(k->name, "rfilter")) {
            rf = k;
        } else if (pn && (cdl_mts_same_name(pn, "crop_offset_x") || cdl_mts_same_name(pn, "crop_width") ||
                          cdl_mts_same_name(pn, "crop_offset_y") || cdl_mts_same_name(pn, "crop_height"))) {
            cdl_mts_warn(c, k->line, "film crop ignored: the whole image is rendered");
            k->used = 1;
        } else if (pn) {
            k->used = 1; /* file format, pixel format, banner, ...: output details */
        }
    }
    if ((rc = rfilter(c, rf, f->line)))
        return rc;
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

/* Mitsuba's orthographic sensor: the to_world image of [-1, 1] x
 * [-1/aspect, 1/aspect] on the plane z = near_clip, looking down +z. */
static int ortho_sensor(cdl_mts_ctx *c, cdl_xml_node *n, long w, long h)
{
    double near, far;
    cdl_mat4 m;
    int rc;
    if ((rc = cdl_mts_float(c, n, "near_clip", 0.01, &near)) || (rc = cdl_mts_float(c, n, "far_clip", 1e4, &far)) ||
        (rc = cdl_mts_transform(c, n, "to_world", &m)))
        return rc;
    if (!(near >= 0.0 && near < far && far <= 1e30))
        return cdl_mts_error(c, n->line, "sensor near_clip %g and far_clip %g must satisfy 0 <= near < far", near, far);
    for (int i = 0; i < n->nkids; i++) {
        const char *pn = cdl_xml_attr_get(&n->kids[i], "name");
        if (pn && (cdl_mts_same_name(pn, "shutter_open") || cdl_mts_same_name(pn, "shutter_close") ||
                   cdl_mts_same_name(pn, "srf")))
            n->kids[i].used = 1;
    }
    cdl_mts_warn_unused(c, n, "sensor");
    cdl_scene_settings *set = c->set;
    set->has_camera = 1;
    set->ortho = 1;
    /* the frame keeps to_world's scale: it sizes the image plane */
    set->eye = cdl_mat4_point3(&m, cdl_v3(0, 0, 0));
    set->right = cdl_scale(cdl_mat4_vector3(&m, cdl_v3(1, 0, 0)), -1.0f);
    set->up = cdl_mat4_vector3(&m, cdl_v3(0, 1, 0));
    set->fwd = cdl_mat4_vector3(&m, cdl_v3(0, 0, 1));
    set->ortho_half_w = 1.0f;
    set->ortho_near = (float)near;
    set->fov = 90.0f;
    set->width = (int)w;
    set->height = (int)h;
    if (!(cdl_length(set->fwd) > 0.0f) || !(cdl_length(set->up) > 0.0f) || !(cdl_length(set->right) > 0.0f))
        return cdl_mts_error(c, n->line, "sensor to_world is singular");
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
    int thin = !strcmp(type, "thinlens"), ortho = !strcmp(type, "orthographic");
    if (strcmp(type, "perspective") && !thin && !ortho) {
        cdl_mts_warn(c, n->line, "sensor \"%s\" is not supported (candela's default camera is used)", type);
        return 0;
    }
    if (thin)
        cdl_mts_warn(c, n->line, "sensor \"thinlens\": rendered as a pinhole (no depth of field)");
    long w = 768, h = 576, spp;
    double fov;
    cdl_mat4 m;
    int saw_film = 0;
    for (int i = 0; i < n->nkids && !rc; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (!strcmp(k->name, "film")) {
            saw_film = 1;
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
    if (!rc && !saw_film) /* Mitsuba's default film, with its default filter */
        rc = rfilter(c, NULL, n->line);
    if (rc)
        return rc;
    if (ortho)
        return ortho_sensor(c, n, w, h);
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
        /* across the diagonal of a 36 x 24 mm film, as Mitsuba 0.6 and 3 */
        fov = 2.0 * atan(sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * fl)) * 180.0 / PI;
        snprintf(axis, sizeof axis, "diagonal");
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
                                         {"sppm", "sppm"},         {"ppm", "pm"},       {"ptracer", "path"}};
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
                                           {"globalLookupRadius", "max_radius"},
                                           {"initial_radius", "radius"},  {"initialRadius", "radius"}};
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
        return cdl_mts_default(c, n);
    if (!strcmp(n->name, "path"))
        return cdl_mts_add_path(c, n);
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

/* A top-level area emitter is read by the shapes that refer to it (Mitsuba
 * 3's spelling); one that no shape refers to lights nothing, and says so. */
static void unreferenced_area(cdl_mts_ctx *c, const cdl_xml_node *n)
{
    const char *id = cdl_xml_attr_get(n, "id"), *type = cdl_xml_attr_get(n, "type");
    if (!strcmp(n->name, "emitter") && id && type && !strcmp(type, "area") && !cdl_mts_find_id(c, id))
        cdl_mts_warn(c, n->line, "area emitter \"%s\": no shape refers to it, so it emits nowhere", id);
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
    c->roots[c->depth++] = &doc.root;
    if (strcmp(doc.root.name, "scene")) {
        rc = cdl_mts_error(c, doc.root.line, "the document element is <%s>, not <scene>", doc.root.name);
    } else {
        const char *ver = cdl_xml_attr_get(&doc.root, "version");
        if (c->depth == 1)
            c->legacy = ver && ver[0] == '0';
        if (ver && !(ver[0] == '0' || !strncmp(ver, "2.", 2) || !strncmp(ver, "3.", 2)))
            cdl_mts_warn(c, doc.root.line, "scene version \"%s\": read as Mitsuba 3", ver);
        for (int i = 0; i < doc.root.nkids && !rc; i++)
            rc = element(c, &doc.root.kids[i]);
        for (int i = 0; i < doc.root.nkids && !rc; i++)
            unreferenced_area(c, &doc.root.kids[i]);
    }
    c->roots[--c->depth] = NULL;
    c->file = outer;
    cdl_xml_free(&doc);
    return rc;
}

int cdl_load_mitsuba(cdl_scene *s, const char *path, const char (*defs)[CDL_DEFINE_LEN], int ndefs,
                     cdl_scene_settings *set, cdl_error *err)
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
    /* Mitsuba picks an emitter uniformly for next-event estimation: power
     * would all but starve a spot beside a constant environment, whose
     * power through the scene's bounds dwarfs it */
    s->light_select_uniform = 1;
    int rc = 0;
    for (int i = 0; i < ndefs && !rc; i++) {
        const char *eq = strchr(defs[i], '=');
        if (!eq || eq == defs[i])
            rc = cdl_error_set(err, CDL_ERR_USAGE, "define", 0, "expected NAME=VALUE, got '%s'", defs[i]);
        else
            rc = cdl_mts_define(c, defs[i], (size_t)(eq - defs[i]), eq + 1, 1);
    }
    if (!rc)
        rc = read_file(c, path, 0);
    if (!rc)
        rc = cdl_mts_sky_finish(c);
    free(c->sky_rgb);
    for (int i = 0; !rc && i < c->nvars; i++)
        if (c->vars[i].given && !c->vars[i].used)
            cdl_warn(path, 0, "define \"%s\": the scene has no such parameter (ignored)", c->vars[i].name);
    if (!rc && !c->saw_sensor) {
        set->has_camera = 1; /* at the origin, looking down +z, 45 degrees along x */
        set->eye = cdl_v3(0, 0, 0);
        set->right = cdl_v3(-1, 0, 0);
        set->up = cdl_v3(0, 1, 0);
        set->fwd = cdl_v3(0, 0, 1);
        double f;
        shorter_axis_fov(c, 0, 45.0, "x", 768, 576, &f);
        set->fov = (float)f;
        rc = rfilter(c, NULL, 0);
    }
    if (!rc && s->ntris == 0 && s->nspheres == 0 && s->ninsts == 0)
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
