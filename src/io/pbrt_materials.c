/* pbrt materials and textures mapped onto candela's material models.
 * Defaults, parameter names and the roughness remapping are pbrt's:
 * v3 (matte, plastic, metal, mirror, glass, uber) and v4 (diffuse,
 * conductor, dielectric, coateddiffuse) names tell the versions apart. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

int cdl_pbrt_current_material(cdl_pbrt_ctx *c, int32_t *mat)
{
    if (c->gs.mat >= 0) {
        *mat = c->gs.mat;
        return 0;
    }
    if (c->default_mat < 0) { /* pbrt's default material: matte, Kd 0.5 */
        cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
        snprintf(m.name, sizeof m.name, "pbrt-default");
        uint32_t id;
        int rc = cdl_pbrt_scene_rc(c, cdl_scene_add_material(c->s, &m, &id, c->err));
        if (rc)
            return rc;
        c->default_mat = (int32_t)id;
    }
    *mat = c->default_mat;
    return 0;
}

static const cdl_pbrt_tex *find_tex(const cdl_pbrt_ctx *c, const char *name, int is_float)
{
    for (int i = c->ntexs; i-- > 0;)
        if (c->texs[i].is_float == is_float && !strcmp(c->texs[i].name, name))
            return &c->texs[i];
    return NULL;
}

static const cdl_pbrt_tex *texture_ref(cdl_pbrt_ctx *c, const cdl_pbrt_param *p, int is_float)
{
    const char *name = p->n == 1 ? cdl_pbrt_str(&c->ps, p, 0) : "";
    const cdl_pbrt_tex *t = find_tex(c, name, is_float);
    return t ? t : find_tex(c, name, !is_float);
}

static int undefined_tex(cdl_pbrt_ctx *c, const cdl_pbrt_param *p)
{
    if (p->n != 1)
        return cdl_pbrt_error(c, p->line, "parameter \"texture %s\" expects one texture name", p->name);
    return cdl_pbrt_error(c, p->line, "texture \"%s\" (for \"%s\") is not defined",
                          cdl_pbrt_str(&c->ps, p, 0), p->name);
}

/* A spectrum parameter of a material, possibly a texture reference;
 * image textures go to *tex when the caller can use them (Kd). */
static int mat_spectrum(cdl_pbrt_ctx *c, const char *name, cdl_vec3 def, cdl_vec3 *out, int *tex, int *found)
{
    cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, name);
    *out = def;
    if (tex)
        *tex = -1;
    if (found)
        *found = p != NULL;
    if (!p)
        return 0;
    int rc = 0;
    if (p->type == CDL_PT_TEXTURE) {
        const cdl_pbrt_tex *t = texture_ref(c, p, 0);
        if (!t)
            return undefined_tex(c, p);
        if (t->kind == CDL_PBRT_TEX_CONST) {
            *out = t->value;
        } else if (t->kind == CDL_PBRT_TEX_IMAGE && tex && t->tex_id >= 0) {
            *tex = t->tex_id;
            *out = t->value;
        } else if (t->kind == CDL_PBRT_TEX_IMAGE) {
            cdl_pbrt_warn(c, p->line, "image texture \"%s\" for \"%s\" is not supported: the default is used",
                          t->name, name);
        } else {
            cdl_pbrt_warn(c, p->line, "texture \"%s\" for \"%s\" approximated by grey 0.5", t->name, name);
            *out = cdl_v3(0.5f, 0.5f, 0.5f);
        }
    } else {
        rc = cdl_pbrt_param_spectrum(&c->ps, p, out, c->err);
    }
    if (!rc && (out->x < 0.0f || out->y < 0.0f || out->z < 0.0f))
        return cdl_pbrt_error(c, p->line, "\"%s\" (%g, %g, %g) must not be negative", name, (double)out->x,
                              (double)out->y, (double)out->z);
    return rc;
}

/* A float parameter; textures only as constants. Spectra (a v4 "eta")
 * are averaged. */
static int mat_float(cdl_pbrt_ctx *c, const char *name, double def, double *out)
{
    cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type == CDL_PT_TEXTURE) {
        const cdl_pbrt_tex *t = texture_ref(c, p, 1);
        if (!t)
            return undefined_tex(c, p);
        if (t->kind == CDL_PBRT_TEX_CONST)
            *out = (t->value.x + t->value.y + t->value.z) / 3.0;
        else
            cdl_pbrt_warn(c, p->line, "texture \"%s\" for \"%s\" is not a constant: the default %g is used",
                          t->name, name, def);
        return 0;
    }
    if (p->type == CDL_PT_FLOAT || p->type == CDL_PT_INT) {
        if (p->n != 1)
            return cdl_pbrt_error(c, p->line, "parameter \"%s %s\" expects one value, got %zu", p->tname,
                                  p->name, p->n);
        *out = cdl_pbrt_nums(&c->ps, p)[0];
        return 0;
    }
    cdl_vec3 v;
    int rc = cdl_pbrt_param_spectrum(&c->ps, p, &v, c->err);
    *out = (v.x + v.y + v.z) / 3.0;
    return rc;
}

/* pbrt-v3 TrowbridgeReitzDistribution::RoughnessToAlpha; pbrt-v4 uses
 * sqrt(roughness). */
static float rough_to_alpha(double r, int remap, int v4)
{
    if (!remap)
        return (float)r;
    if (v4)
        return (float)sqrt(r);
    double x = log(r > 1e-3 ? r : 1e-3);
    return (float)(1.62142 + 0.819955 * x + 0.1734 * x * x + 0.0171201 * x * x * x +
                   0.000640711 * x * x * x * x);
}

/* roughness / uroughness / vroughness / remaproughness into alpha;
 * *smooth tells whether both raw roughnesses are 0 (pbrt's specular case). */
static int roughness(cdl_pbrt_ctx *c, double def, int v4, cdl_material *m, int *smooth)
{
    double r, u, v;
    int remap, rc;
    if ((rc = mat_float(c, "roughness", def, &r)) || (rc = mat_float(c, "uroughness", r, &u)) ||
        (rc = mat_float(c, "vroughness", r, &v)) ||
        (rc = cdl_pbrt_get_bool(&c->ps, "remaproughness", 1, &remap, c->err)))
        return rc;
    if (!(u >= 0.0 && v >= 0.0))
        return cdl_pbrt_error(c, c->line, "roughness (%g, %g) must be >= 0", u, v);
    m->alpha_x = rough_to_alpha(u, remap, v4);
    m->alpha_y = rough_to_alpha(v, remap, v4);
    if (smooth)
        *smooth = u == 0.0 && v == 0.0;
    return 0;
}

static int eta_param(cdl_pbrt_ctx *c, double *eta)
{
    cdl_pbrt_param *e = cdl_pbrt_find(&c->ps, "eta");
    int rc = mat_float(c, e ? "eta" : "index", 1.5, eta);
    if (e)
        cdl_pbrt_find(&c->ps, "index");
    if (!rc && !(*eta > 0.0))
        return cdl_pbrt_error(c, c->line, "index of refraction %g must be > 0", *eta);
    return rc;
}

static int make(cdl_pbrt_ctx *c, const char *type, cdl_material *m)
{
    const cdl_vec3 half = cdl_v3(0.5f, 0.5f, 0.5f), quarter = cdl_v3(0.25f, 0.25f, 0.25f);
    const cdl_vec3 one = cdl_v3(1, 1, 1), zero = cdl_v3(0, 0, 0);
    int rc = 0, smooth, found;
    double eta, sigma;
    cdl_vec3 v;
    if (!strcmp(type, "matte") || !strcmp(type, "diffuse")) {
        *m = cdl_material_default(CDL_MAT_DIFFUSE);
        if ((rc = mat_spectrum(c, type[0] == 'm' ? "Kd" : "reflectance", half, &m->kd, &m->kd_tex, NULL)) ||
            (rc = mat_float(c, "sigma", 0.0, &sigma)))
            return rc;
        if (!(sigma >= 0.0 && sigma <= 90.0))
            return cdl_pbrt_error(c, c->line, "matte sigma %g must be in [0, 90] degrees", sigma);
        if (sigma > 0.0) { /* pbrt's OrenNayar: the qualitative model */
            m->type = CDL_MAT_ROUGH_DIFFUSE;
            m->sigma = (float)(sigma * 3.14159265358979323846 / 180.0);
        }
    } else if (!strcmp(type, "plastic")) {
        *m = cdl_material_default(CDL_MAT_PLASTIC);
        if ((rc = mat_spectrum(c, "Kd", quarter, &m->kd, &m->kd_tex, NULL)) ||
            (rc = mat_spectrum(c, "Ks", quarter, &m->ks, NULL, NULL)) ||
            (rc = roughness(c, 0.1, 0, m, NULL)))
            return rc;
        m->eta = 1.5f; /* pbrt-v3's plastic coat */
    } else if (!strcmp(type, "uber") || !strcmp(type, "coateddiffuse")) {
        int v4 = type[0] == 'c';
        *m = cdl_material_default(CDL_MAT_PLASTIC);
        cdl_pbrt_warn(c, c->line, "material \"%s\" approximated by plastic", type);
        if ((rc = mat_spectrum(c, v4 ? "reflectance" : "Kd", v4 ? half : quarter, &m->kd, &m->kd_tex, NULL)) ||
            (rc = roughness(c, v4 ? 0.0 : 0.1, v4, m, NULL)) || (rc = eta_param(c, &eta)))
            return rc;
        m->eta = (float)eta;
        if (v4)
            m->ks = one;
        else if ((rc = mat_spectrum(c, "Ks", quarter, &m->ks, NULL, NULL)))
            return rc;
        static const char *const extra[] = {"Kr", "Kt", "opacity", "thickness", "albedo", "g",
                                            "maxdepth", "nsamples"};
        for (size_t i = 0; i < sizeof extra / sizeof extra[0]; i++)
            cdl_pbrt_find(&c->ps, extra[i]);
    } else if (!strcmp(type, "metal") || !strcmp(type, "conductor")) {
        int v4 = type[0] == 'c';
        *m = cdl_material_default(CDL_MAT_CONDUCTOR);
        cdl_vec3 cu_eta, cu_k;
        cdl_pbrt_named_spectrum("metal-Cu-eta", &cu_eta);
        cdl_pbrt_named_spectrum("metal-Cu-k", &cu_k);
        if ((rc = mat_spectrum(c, "eta", cu_eta, &m->eta3, NULL, NULL)) ||
            (rc = mat_spectrum(c, "k", cu_k, &m->k3, NULL, NULL)) ||
            (rc = roughness(c, v4 ? 0.0 : 0.01, v4, m, NULL)))
            return rc;
        if (v4 && (rc = mat_spectrum(c, "reflectance", zero, &v, NULL, &found)))
            return rc;
        if (v4 && found) { /* pbrt-v4: an artist's reflectance becomes eta 1, k = 2 sqrt(r) / sqrt(1 - r) */
            float *r = &v.x;
            float *k = &m->k3.x;
            for (int i = 0; i < 3; i++) {
                float ri = cdl_minf(r[i], 0.9999f);
                k[i] = 2.0f * sqrtf(ri) / sqrtf(1.0f - ri);
            }
            m->eta3 = one;
        }
    } else if (!strcmp(type, "mirror")) {
        *m = cdl_material_default(CDL_MAT_MIRROR);
        rc = mat_spectrum(c, "Kr", cdl_v3(0.9f, 0.9f, 0.9f), &m->ks, NULL, NULL);
    } else if (!strcmp(type, "glass") || !strcmp(type, "dielectric")) {
        int v4 = type[0] == 'd';
        *m = cdl_material_default(CDL_MAT_DIELECTRIC);
        if ((rc = eta_param(c, &eta)) || (rc = roughness(c, 0.0, v4, m, &smooth)))
            return rc;
        if (!v4 && ((rc = mat_spectrum(c, "Kr", one, &m->ks, NULL, NULL)) ||
                    (rc = mat_spectrum(c, "Kt", one, &m->kt, NULL, NULL))))
            return rc;
        m->eta = (float)eta;
        if (!smooth)
            m->type = CDL_MAT_ROUGH_DIELECTRIC;
    } else {
        *m = cdl_material_default(CDL_MAT_DIFFUSE);
        cdl_pbrt_warn(c, c->line, "material \"%s\" is not supported: rendered as matte", type);
        cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, "Kd");
        v = m->kd;
        if (!p)
            p = cdl_pbrt_find(&c->ps, "reflectance");
        if (p && p->type != CDL_PT_TEXTURE && cdl_pbrt_param_spectrum(&c->ps, p, &v, c->err) == 0 &&
            v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f)
            m->kd = v;
        for (size_t i = 0; i < c->ps.n; i++)
            c->ps.p[i].used = 1;
    }
    if (rc)
        return rc;
    const char *bump[] = {"bumpmap", "displacement", "normalmap"};
    for (size_t i = 0; i < 3; i++)
        if (cdl_pbrt_find(&c->ps, bump[i]))
            cdl_pbrt_warn(c, c->line, "material \"%s\": %s ignored", type, bump[i]);
    return 0;
}

int cdl_pbrt_material(cdl_pbrt_ctx *c, const char *type, const char *name, int32_t *mat)
{
    cdl_material m;
    int rc = make(c, type, &m);
    if (rc)
        return rc;
    snprintf(m.name, sizeof m.name, "%s", name ? name : type);
    uint32_t id;
    if ((rc = cdl_pbrt_scene_rc(c, cdl_scene_add_material(c->s, &m, &id, c->err))))
        return rc;
    *mat = (int32_t)id;
    return 0;
}

/* ---- textures ---- */

/* An operand of a "scale" texture: a texture reference or a value. */
static int tex_operand(cdl_pbrt_ctx *c, const char *pname, cdl_pbrt_tex *out)
{
    cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, pname);
    memset(out, 0, sizeof *out);
    out->kind = CDL_PBRT_TEX_CONST;
    out->value = cdl_v3(1, 1, 1);
    out->tex_id = -1;
    if (!p)
        return 0;
    if (p->type == CDL_PT_TEXTURE) {
        const cdl_pbrt_tex *t = texture_ref(c, p, 0);
        if (!t)
            return undefined_tex(c, p);
        out->kind = t->kind;
        out->value = t->value;
        out->tex_id = t->tex_id;
        return 0;
    }
    return cdl_pbrt_param_spectrum(&c->ps, p, &out->value, c->err);
}

static int image_texture(cdl_pbrt_ctx *c, int is_float, cdl_pbrt_tex *t)
{
    cdl_pbrt_params *ps = &c->ps;
    const char *fn, *mapping, *wrap, *enc;
    double sc, us, vs, ud, vd;
    int inv, gamma, rc;
    if ((rc = cdl_pbrt_get_string(ps, "filename", NULL, &fn, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "scale", 1.0, &sc, c->err)) ||
        (rc = cdl_pbrt_get_bool(ps, "invert", 0, &inv, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "mapping", "uv", &mapping, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "wrap", "repeat", &wrap, c->err)) ||
        (rc = cdl_pbrt_get_string(ps, "encoding", "sRGB", &enc, c->err)) ||
        (rc = cdl_pbrt_get_bool(ps, "gamma", 1, &gamma, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "uscale", 1.0, &us, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "vscale", 1.0, &vs, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "udelta", 0.0, &ud, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "vdelta", 0.0, &vd, c->err)))
        return rc;
    if (!fn)
        return cdl_pbrt_error(c, c->line, "imagemap texture \"%s\" needs \"string filename\"", t->name);
    cdl_pbrt_find(ps, "filter");
    cdl_pbrt_find(ps, "maxanisotropy");
    cdl_pbrt_find(ps, "trilinear");
    if (inv || strcmp(mapping, "uv") || strcmp(wrap, "repeat") || us != 1.0 || vs != 1.0 || ud != 0.0 ||
        vd != 0.0)
        cdl_pbrt_warn(c, c->line, "imagemap \"%s\": invert, mapping, wrap and uv scale/offset are ignored "
                                  "(plain repeating uv lookup)", t->name);
    if (!gamma || strcmp(enc, "sRGB"))
        cdl_pbrt_warn(c, c->line, "imagemap \"%s\": 8-bit images are always decoded as sRGB", t->name);
    char path[1024];
    cdl_pbrt_resolve(c, fn, path, sizeof path);
    if ((rc = cdl_pbrt_check_file(c, "texture file", path)))
        return rc;
    t->kind = CDL_PBRT_TEX_IMAGE;
    t->value = cdl_v3((float)sc, (float)sc, (float)sc);
    if (!(t->path = strdup(path)))
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
    if (is_float)
        return 0; /* float images are not looked up (constants only) */
    for (int i = 0; i < c->ntexs; i++) /* one decoded copy per file */
        if (c->texs[i].tex_id >= 0 && c->texs[i].path && !strcmp(c->texs[i].path, path)) {
            t->tex_id = c->texs[i].tex_id;
            return 0;
        }
    if ((rc = cdl_scene_add_texture(c->s, path, &t->tex_id, c->err))) {
        /* name the Texture directive; the image's own message follows */
        cdl_error sub = *c->err;
        return cdl_error_set(c->err, sub.code, c->file, c->line, "texture \"%s\": %s", path, sub.msg);
    }
    return 0;
}

int cdl_pbrt_texture(cdl_pbrt_ctx *c, const char *name, const char *type, const char *cls)
{
    cdl_pbrt_tex t;
    memset(&t, 0, sizeof t);
    t.tex_id = -1;
    int rc = 0;
    if (!strcmp(type, "float"))
        t.is_float = 1;
    else if (strcmp(type, "spectrum") && strcmp(type, "color") && strcmp(type, "rgb"))
        return cdl_pbrt_error(c, c->line, "Texture \"%s\": type \"%s\" must be \"float\" or \"spectrum\"", name,
                              type);
    if (!(t.name = strdup(name)))
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
    if (!strcmp(cls, "imagemap")) {
        rc = image_texture(c, t.is_float, &t);
    } else if (!strcmp(cls, "constant")) {
        double f;
        t.kind = CDL_PBRT_TEX_CONST;
        if (t.is_float) {
            rc = cdl_pbrt_get_float(&c->ps, "value", 1.0, &f, c->err);
            t.value = cdl_v3((float)f, (float)f, (float)f);
        } else {
            rc = cdl_pbrt_get_spectrum(&c->ps, "value", cdl_v3(1, 1, 1), &t.value, NULL, c->err);
        }
    } else if (!strcmp(cls, "scale")) {
        /* v3: tex1 * tex2; v4: tex * scale */
        cdl_pbrt_tex a, b;
        int v4 = cdl_pbrt_find(&c->ps, "tex") != NULL;
        if (!(rc = tex_operand(c, v4 ? "tex" : "tex1", &a)) && !(rc = tex_operand(c, v4 ? "scale" : "tex2", &b))) {
            if (a.kind == CDL_PBRT_TEX_IMAGE && b.kind == CDL_PBRT_TEX_CONST)
                t = (cdl_pbrt_tex){t.name, t.is_float, a.kind, cdl_mul(a.value, b.value), a.tex_id, NULL};
            else if (b.kind == CDL_PBRT_TEX_IMAGE && a.kind == CDL_PBRT_TEX_CONST)
                t = (cdl_pbrt_tex){t.name, t.is_float, b.kind, cdl_mul(a.value, b.value), b.tex_id, NULL};
            else if (a.kind == CDL_PBRT_TEX_CONST && b.kind == CDL_PBRT_TEX_CONST)
                t = (cdl_pbrt_tex){t.name, t.is_float, a.kind, cdl_mul(a.value, b.value), -1, NULL};
            else {
                cdl_pbrt_warn(c, c->line, "scale texture \"%s\" of two non-constant textures: grey 0.5", name);
                t.kind = CDL_PBRT_TEX_OTHER;
                t.value = cdl_v3(0.5f, 0.5f, 0.5f);
            }
        }
    } else {
        cdl_pbrt_warn(c, c->line, "texture class \"%s\" is not supported: \"%s\" is grey 0.5", cls, name);
        t.kind = CDL_PBRT_TEX_OTHER;
        t.value = cdl_v3(0.5f, 0.5f, 0.5f);
        for (size_t i = 0; i < c->ps.n; i++)
            c->ps.p[i].used = 1;
    }
    if (!rc && c->ntexs == c->captexs) {
        int cap = c->captexs ? 2 * c->captexs : 16;
        cdl_pbrt_tex *p = realloc(c->texs, sizeof *p * (size_t)cap);
        if (!p)
            rc = cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        else {
            c->texs = p;
            c->captexs = cap;
        }
    }
    if (rc) {
        free(t.name);
        free(t.path);
        return rc;
    }
    c->texs[c->ntexs++] = t;
    return 0;
}
