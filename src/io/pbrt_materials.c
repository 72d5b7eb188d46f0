/* pbrt materials mapped onto candela's material models.
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

/* A spectrum parameter of a material, possibly a texture reference;
 * textures go to *tex when the caller can use them (Kd), else their mean
 * stands for them, with a warning. */
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
        const cdl_pbrt_tex *t;
        if ((rc = cdl_pbrt_texture_ref(c, p, 0, &t)))
            return rc;
        *out = t->value;
        if (t->kind == CDL_PBRT_TEX_SCENE && tex) {
            *tex = t->tex_id;
            *out = cdl_v3(1, 1, 1);
        } else if (t->kind == CDL_PBRT_TEX_SCENE) {
            cdl_pbrt_warn(c, p->line, "texture \"%s\" for \"%s\" is not supported: its mean (%g %g %g) is used",
                          t->name, name, (double)out->x, (double)out->y, (double)out->z);
        }
    } else {
        rc = cdl_pbrt_param_spectrum(&c->ps, p, out, c->err);
    }
    if (!rc && (out->x < 0.0f || out->y < 0.0f || out->z < 0.0f))
        return cdl_pbrt_error(c, p->line, "\"%s\" (%g, %g, %g) must not be negative", name, (double)out->x,
                              (double)out->y, (double)out->z);
    return rc;
}

/* A float parameter, possibly a texture: to *tex when the caller can use
 * it (roughness), else its mean with a warning. Spectra (a v4 "eta") are
 * averaged. */
static int mat_float_tex(cdl_pbrt_ctx *c, const char *name, double def, double *out, int *tex)
{
    cdl_pbrt_param *p = cdl_pbrt_find(&c->ps, name);
    *out = def;
    if (tex)
        *tex = -1;
    if (!p)
        return 0;
    if (p->type == CDL_PT_TEXTURE) {
        const cdl_pbrt_tex *t;
        int rc = cdl_pbrt_texture_ref(c, p, 1, &t);
        if (rc)
            return rc;
        *out = (t->value.x + t->value.y + t->value.z) / 3.0;
        if (t->kind == CDL_PBRT_TEX_SCENE && tex)
            *tex = t->tex_id;
        else if (t->kind == CDL_PBRT_TEX_SCENE)
            cdl_pbrt_warn(c, p->line, "texture \"%s\" for \"%s\" is not supported: its mean %g is used", t->name,
                          name, *out);
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

static int mat_float(cdl_pbrt_ctx *c, const char *name, double def, double *out)
{
    return mat_float_tex(c, name, def, out, NULL);
}

/* roughness / uroughness / vroughness / remaproughness into alpha;
 * *smooth tells whether both raw roughnesses are 0 (pbrt's specular
 * case). Float textures become alpha textures, remapped at each lookup
 * as pbrt does (v3's RoughnessToAlpha, v4's sqrt). */
static int roughness(cdl_pbrt_ctx *c, double def, int v4, cdl_material *m, int *smooth)
{
    double r, u, v;
    int remap, rc, rt, ut, vt;
    if ((rc = mat_float_tex(c, "roughness", def, &r, &rt)) || (rc = mat_float_tex(c, "uroughness", r, &u, &ut)) ||
        (rc = mat_float_tex(c, "vroughness", r, &v, &vt)) ||
        (rc = cdl_pbrt_get_bool(&c->ps, "remaproughness", 1, &remap, c->err)))
        return rc;
    if (!cdl_pbrt_find(&c->ps, "uroughness"))
        ut = rt;
    if (!cdl_pbrt_find(&c->ps, "vroughness"))
        vt = rt;
    if (!(u >= 0.0 && v >= 0.0))
        return cdl_pbrt_error(c, c->line, "roughness (%g, %g) must be >= 0", u, v);
    int mode = !remap ? CDL_ROUGH_ALPHA : v4 ? CDL_ROUGH_PBRT4 : CDL_ROUGH_PBRT3;
    m->alpha_x = cdl_roughness_to_alpha(u, mode);
    m->alpha_y = cdl_roughness_to_alpha(v, mode);
    if (smooth)
        *smooth = u == 0.0 && v == 0.0 && ut < 0 && vt < 0;
    if (ut >= 0 || vt >= 0) {
        m->maps.on = 1;
        m->maps.alpha_tex[0] = ut;
        m->maps.alpha_tex[1] = vt;
        m->maps.alpha_remap = mode;
    }
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

/* pbrt-v3's "bumpmap" and v4's "displacement": a float texture d, the
 * surface displaced by d along the shading normal (candela's bump map
 * with scale 1, cdl_bump_frame); v4's "normalmap" image, which pbrt-v4
 * prefers to a displacement. */
static int maps(cdl_pbrt_ctx *c, cdl_material *m)
{
    cdl_pbrt_param *nm = cdl_pbrt_find(&c->ps, "normalmap"), *d = cdl_pbrt_find(&c->ps, "displacement");
    cdl_pbrt_param *b = cdl_pbrt_find(&c->ps, "bumpmap");
    int rc, tex = -1;
    if (nm && nm->type == CDL_PT_STRING && nm->n == 1 && !*cdl_pbrt_str(&c->ps, nm, 0))
        nm = NULL; /* pbrt-v4's "no normal map" */
    if (nm) {
        if ((rc = cdl_pbrt_normal_map(c, nm, &tex)))
            return rc;
        m->maps.on = 1;
        m->maps.normal_tex = tex;
        return 0;
    }
    int v4 = d != NULL;
    cdl_pbrt_param *p = d ? d : b;
    if (!p)
        return 0;
    if (p->type == CDL_PT_FLOAT || p->type == CDL_PT_INT)
        return 0; /* a constant displacement leaves the normal as it is */
    if (p->type != CDL_PT_TEXTURE)
        return cdl_pbrt_error(c, p->line, "parameter \"%s %s\" should be a float texture", p->tname, p->name);
    const cdl_pbrt_tex *t;
    if ((rc = cdl_pbrt_texture_ref(c, p, 1, &t)))
        return rc;
    if (t->kind == CDL_PBRT_TEX_OTHER)
        cdl_pbrt_warn(c, p->line, "%s \"%s\" of an unsupported texture class is ignored", p->name, t->name);
    if (t->kind != CDL_PBRT_TEX_SCENE)
        return 0;
    m->maps.on = 1;
    m->maps.bump_tex = t->tex_id;
    m->maps.bump_scale = 1.0f;
    /* shapes without vertex normals take the partials (cdl_pbrt_shape_material) */
    m->maps.bump_frame = v4 ? CDL_BUMP_PBRT4_VN : CDL_BUMP_PBRT3_VN;
    return 0;
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
    } else if (!strcmp(type, "glass") || !strcmp(type, "dielectric") || !strcmp(type, "thindielectric")) {
        int v4 = type[0] != 'g';
        *m = cdl_material_default(CDL_MAT_DIELECTRIC);
        if (type[0] == 't') /* as the Mitsuba reader takes Mitsuba's thindielectric */
            cdl_pbrt_warn(c, c->line, "material \"thindielectric\" approximated by a dielectric (light refracts "
                                      "where pbrt's passes straight through)");
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
    return maps(c, m);
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

int cdl_pbrt_shape_material(cdl_pbrt_ctx *c, uint32_t mat, int vnormals, uint32_t *out)
{
    *out = mat;
    const cdl_material *m = &c->s->mats[mat];
    if (!m->maps.on || m->maps.bump_tex < 0 || m->maps.bump_frame == CDL_BUMP_PARTIALS || vnormals)
        return 0;
    /* a shape pbrt gives no vertex normals: the same material displacing
     * the surface partials, made once */
    for (int i = 0; i < c->nvariants; i++)
        if (c->variants[2 * i] == (int32_t)mat) {
            *out = (uint32_t)c->variants[2 * i + 1];
            return 0;
        }
    cdl_material v = *m;
    v.maps.bump_frame = CDL_BUMP_PARTIALS;
    uint32_t id;
    int rc = cdl_pbrt_scene_rc(c, cdl_scene_add_material(c->s, &v, &id, c->err));
    if (rc)
        return rc;
    if (c->nvariants == c->capvariants) {
        int cap = c->capvariants ? 2 * c->capvariants : 8;
        int32_t *p = realloc(c->variants, sizeof *p * 2 * (size_t)cap);
        if (!p)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
        c->variants = p;
        c->capvariants = cap;
    }
    c->variants[2 * c->nvariants] = (int32_t)mat;
    c->variants[2 * c->nvariants++ + 1] = (int32_t)id;
    *out = id;
    return 0;
}
