/* Mitsuba bsdfs and textures as candela's materials (emitters:
 * mitsuba_emitters.c).
 * Defaults are Mitsuba 3's; what candela has no model for is approximated
 * with a warning. Plastic and roughplastic are Mitsuba's own coated model
 * (scene/plastic.h); they and the rough conductors and dielectrics use
 * Mitsuba's microfacet model (scene/microfacet_mts.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/mitsuba_internal.h"
#include "io/pbrt_params.h"
#include "scene/microfacet_mts.h"
#include "scene/plastic.h"
#include "scene/scene.h"

/* Mitsuba's named indices of refraction (its ior.h table). */
static const struct {
    const char *name;
    double ior;
} IORS[] = {{"vacuum", 1.0},        {"helium", 1.000036},      {"hydrogen", 1.000132},   {"air", 1.000277},
            {"carbon dioxide", 1.00045}, {"water", 1.3330},    {"acetone", 1.36},        {"ethanol", 1.361},
            {"carbon tetrachloride", 1.461}, {"glycerol", 1.4729}, {"benzene", 1.501},   {"silicone oil", 1.52045},
            {"bromine", 1.661},     {"water ice", 1.31},       {"fused quartz", 1.458},  {"pyrex", 1.470},
            {"acrylic glass", 1.49}, {"polypropylene", 1.49},  {"bk7", 1.5046},          {"sodium chloride", 1.544},
            {"amber", 1.55},        {"pet", 1.5750},           {"diamond", 2.419}};

static int ior_prop(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double *out)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (!p)
        return 0;
    p->used = 0; /* read again as a float or a string */
    if (!strcmp(p->name, "string")) {
        char s[64];
        int rc = cdl_mts_string(c, n, name, NULL, s, sizeof s);
        if (rc)
            return rc;
        for (size_t i = 0; i < sizeof IORS / sizeof IORS[0]; i++)
            if (!strcmp(s, IORS[i].name)) {
                *out = IORS[i].ior;
                return 0;
            }
        return cdl_mts_error(c, p->line, "%s \"%s\" is not a known material (give a number)", name, s);
    }
    int rc = cdl_mts_float(c, n, name, def, out);
    if (!rc && !(*out > 0.0 && *out < 100.0))
        rc = cdl_mts_error(c, p->line, "%s %g must be in (0, 100)", name, *out);
    return rc;
}

/* A color property that may be a texture (tex != NULL) or must be constant. */
/* An id on a bsdf or texture declared inside another element: Mitsuba
 * knows it from there on, as one declared at the top. */
static int nested_id(cdl_mts_ctx *c, const cdl_xml_node *n, cdl_mts_kind kind, int32_t mat, int tex, cdl_vec3 value)
{
    int rc = 0;
    const char *id = cdl_mts_attr(c, n, "id", &rc);
    if (rc || !id || !*id)
        return rc;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", id);
    cdl_mts_id v = {buf, kind, mat, tex, value};
    return cdl_mts_add_id(c, n, &v);
}

int cdl_mts_color_prop(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_vec3 def, cdl_vec3 *out, int *tex)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *out = def;
    if (tex)
        *tex = -1;
    if (!p)
        return 0;
    int t = -1, rc = 0;
    cdl_vec3 v = def;
    if (!strcmp(p->name, "ref")) {
        int rc2 = 0;
        const char *id = cdl_mts_attr(c, p, "id", &rc2);
        if (rc2)
            return rc2;
        const cdl_mts_id *d = id ? cdl_mts_find_id(c, id) : NULL;
        if (!d)
            return cdl_mts_error(c, p->line, "%s: <ref id=\"%s\"> is not declared before", name, id ? id : "");
        if (d->kind != CDL_MTS_TEXTURE)
            return cdl_mts_error(c, p->line, "%s: \"%s\" is not a texture", name, id);
        t = d->tex;
        v = d->value;
    } else if (!strcmp(p->name, "texture")) {
        rc = cdl_mts_texture(c, p, &t, &v);
        if (!rc)
            rc = nested_id(c, p, CDL_MTS_TEXTURE, -1, t, v);
    } else {
        rc = cdl_mts_color_node(c, p, &v);
    }
    if (rc)
        return rc;
    if (!cdl_is_finite3(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)
        return cdl_mts_error(c, p->line, "%s (%g, %g, %g) must be finite and >= 0", name, (double)v.x, (double)v.y,
                             (double)v.z);
    if (t >= 0 && !tex) {
        cdl_mts_warn(c, p->line, "%s: a texture is supported only for reflectances here; its scale is used", name);
        t = -1;
    }
    *out = v;
    if (tex)
        *tex = t;
    return 0;
}

/* A conductor's eta. Mitsuba takes a negative one and its Fresnel term
 * reads only eta squared: the magnitude, with a warning. */
static int conductor_eta(cdl_mts_ctx *c, cdl_xml_node *n, cdl_vec3 def, cdl_vec3 *out)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, "eta");
    if (!p || !strcmp(p->name, "ref") || !strcmp(p->name, "texture"))
        return cdl_mts_color_prop(c, n, "eta", def, out, NULL);
    cdl_vec3 v;
    int rc = cdl_mts_color_node(c, p, &v);
    if (rc)
        return rc;
    if (!cdl_is_finite3(v))
        return cdl_mts_error(c, p->line, "eta must be finite");
    if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f) {
        cdl_mts_warn(c, p->line, "conductor eta (%g, %g, %g) is negative: its magnitude is used (the same Fresnel term)",
                     (double)v.x, (double)v.y, (double)v.z);
        v = cdl_v3(fabsf(v.x), fabsf(v.y), fabsf(v.z));
    }
    *out = v;
    return 0;
}

/* Reflectances above 1 create energy: clamped, with a warning. */
static cdl_vec3 at_most_one(cdl_mts_ctx *c, int line, const char *what, cdl_vec3 v)
{
    if (v.x > 1.0f || v.y > 1.0f || v.z > 1.0f) {
        cdl_mts_warn(c, line, "%s (%g, %g, %g) reflects more than all light: clamped to 1", what, (double)v.x,
                     (double)v.y, (double)v.z);
        v = cdl_v3(fminf(v.x, 1.0f), fminf(v.y, 1.0f), fminf(v.z, 1.0f));
    }
    return v;
}

/* alpha, alpha_u, alpha_v and distribution of the rough models. */
static int roughness(cdl_mts_ctx *c, cdl_xml_node *n, int rough, cdl_material *m)
{
    double a, au, av;
    char dist[32];
    int rc;
    int ta, tu, tv;
    if ((rc = cdl_mts_float_or_texture(c, n, "alpha", rough ? 0.1 : 0.0, &a, &ta)) ||
        (rc = cdl_mts_float_or_texture(c, n, "alpha_u", a, &au, &tu)) ||
        (rc = cdl_mts_float_or_texture(c, n, "alpha_v", a, &av, &tv)) ||
        (rc = cdl_mts_string(c, n, "distribution", "beckmann", dist, sizeof dist)))
        return rc;
    m->maps.alpha_tex[0] = tu >= 0 ? tu : (cdl_mts_prop(c, n, "alpha_u") ? -1 : ta);
    m->maps.alpha_tex[1] = tv >= 0 ? tv : (cdl_mts_prop(c, n, "alpha_v") ? -1 : ta);
    m->maps.on = 1;
    if (!(au >= 0.0 && av >= 0.0 && au <= 10.0 && av <= 10.0))
        return cdl_mts_error(c, n->line, "alpha (%g, %g) must be in [0, 10]", au, av);
    if (rough && strcmp(dist, "ggx") && strcmp(dist, "beckmann") && strcmp(dist, "phong"))
        return cdl_mts_error(c, n->line, "distribution \"%s\" must be ggx, beckmann or phong", dist);
    /* sampling only: candela always samples the visible normals, which
     * changes the noise, not the image */
    cdl_mts_prop(c, n, "sample_visible");
    m->alpha_x = (float)au;
    m->alpha_y = (float)av;
    m->mf = strcmp(dist, "ggx") ? CDL_MF_BECKMANN : CDL_MF_GGX;
    if (rough && !strcmp(dist, "phong"))
        cdl_mts_warn(c, n->line, "distribution \"phong\" (Mitsuba 0.6) read as beckmann");
    return 0;
}

/* int_ior / ext_ior as one relative index. */
static int rel_ior(cdl_mts_ctx *c, cdl_xml_node *n, double int_def, float *eta)
{
    double in, ext;
    int rc;
    if ((rc = ior_prop(c, n, "int_ior", int_def, &in)) || (rc = ior_prop(c, n, "ext_ior", 1.000277, &ext)))
        return rc;
    *eta = (float)(in / ext);
    return 0;
}

/* A mesh attribute is read at the hit as a reflectance or a blend weight
 * only: elsewhere its value is 1 (scene/attr.h). */
static int reads_attr(const cdl_scene *s, int tex)
{
    if (tex >= 0 && s->texs[tex].type == CDL_TEX_SCALE)
        tex = s->texs[tex].sub[0];
    return tex >= 0 && s->texs[tex].type == CDL_TEX_ATTRIBUTE;
}

int cdl_mts_add_material(cdl_mts_ctx *c, int line, const cdl_material *m, uint32_t *idx)
{
    int slots[5 + CDL_PR_NPARAMS] = {m->maps.alpha_tex[0], m->maps.alpha_tex[1], m->maps.bump_tex,
                                     m->maps.normal_tex, m->opacity_tex};
    int n = 5;
    if (m->type == CDL_MAT_PRINCIPLED)
        for (int k = 0; k < CDL_PR_NPARAMS; k++)
            slots[n++] = m->pr.tex[k];
    for (int k = 0; k < n; k++)
        if ((k < 4 ? m->maps.on : k == 4 ? m->masked : 1) && reads_attr(c->s, slots[k])) {
            cdl_mts_warn(c, line, "a mesh_attribute is read as a reflectance or a blend weight only: 1 here");
            break;
        }
    return cdl_mts_scene_rc(c, line, cdl_scene_add_material(c->s, m, idx, c->err));
}

int cdl_mts_child_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, int strict, int32_t *mat, int *found)
{
    *found = 0;
    for (int i = 0; i < n->nkids; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (!strcmp(k->name, "bsdf")) {
            k->used = 1;
            *found = 1;
            int rc = cdl_mts_bsdf(c, k, mat);
            return rc ? rc : nested_id(c, k, CDL_MTS_BSDF, *mat, -1, cdl_v3(0, 0, 0));
        }
        if (!strcmp(k->name, "ref")) {
            int rc = 0;
            const char *id = cdl_mts_attr(c, k, "id", &rc);
            if (rc)
                return rc;
            const cdl_mts_id *d = id ? cdl_mts_find_id(c, id) : NULL;
            const cdl_xml_node *decl = id && (!d || d->kind == CDL_MTS_OTHER) ? cdl_mts_find_decl(c, id) : NULL;
            if (decl && strcmp(decl->name, "bsdf"))
                continue; /* an emitter or a medium: the shape's business */
            if (strict && !d)
                return cdl_mts_error(c, k->line, "<ref id=\"%s\"> is not declared before", id ? id : "");
            if (strict && d->kind != CDL_MTS_BSDF)
                return cdl_mts_error(c, k->line, "<ref id=\"%s\"> in a shape must name a bsdf", id);
            if (!d || d->kind != CDL_MTS_BSDF)
                continue; /* a texture reference of a wrapper */
            k->used = 1;
            *found = 1;
            *mat = d->mat;
            return 0;
        }
    }
    return 0;
}

int cdl_mts_default_material(cdl_mts_ctx *c, int32_t *mat)
{
    if (c->default_mat < 0) {
        cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
        uint32_t id;
        m.one_sided = 1; /* Mitsuba's default bsdf, a diffuse one */
        snprintf(m.name, sizeof m.name, "mitsuba-default");
        int rc = cdl_scene_add_material(c->s, &m, &id, c->err);
        if (rc)
            return rc;
        c->default_mat = (int32_t)id;
    }
    *mat = c->default_mat;
    return 0;
}

static int conductor(cdl_mts_ctx *c, cdl_xml_node *n, int rough, cdl_material *m)
{
    char metal[32];
    int rc;
    *m = cdl_material_default(CDL_MAT_CONDUCTOR);
    if ((rc = cdl_mts_string(c, n, "material", "none", metal, sizeof metal)))
        return rc;
    if (!strcmp(metal, "none")) { /* a perfect mirror: Fresnel 1 at every angle */
        m->eta3 = cdl_v3(0, 0, 0);
        m->k3 = cdl_v3(1, 1, 1);
    } else {
        if (cdl_mts_named_conductor(metal, &m->eta3, &m->k3)) {
            cdl_mts_warn(c, n->line, "conductor material \"%s\" is not in candela's table: copper is used", metal);
            cdl_pbrt_named_spectrum("metal-Cu-eta", &m->eta3);
            cdl_pbrt_named_spectrum("metal-Cu-k", &m->k3);
        }
    }
    if ((rc = conductor_eta(c, n, m->eta3, &m->eta3)) || (rc = cdl_mts_color_prop(c, n, "k", m->k3, &m->k3, NULL)) ||
        (rc = cdl_mts_color_prop(c, n, "specular_reflectance", cdl_v3(1, 1, 1), &m->ks, NULL)) ||
        (rc = roughness(c, n, rough, m)))
        return rc;
    m->ks = at_most_one(c, n->line, "specular_reflectance", m->ks);
    if (!rough)
        m->mf = CDL_MF_PBRT; /* a mirror (alpha 0) */
    return 0;
}

/* Mitsuba's Texture::mean(): the channels' mean of a constant, the mean
 * luminance of a bitmap (times candela's constant factor). */
static float texture_mean(cdl_mts_ctx *c, cdl_vec3 v, int tex)
{
    float k = (v.x + v.y + v.z) / 3.0f;
    if (tex < 0 || tex >= (int)c->s->ntexs)
        return k;
    const cdl_texture *t = &c->s->texs[tex];
    double sum = 0.0;
    size_t np = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < np; i++)
        sum += cdl_luminance(cdl_v3(t->rgb[3 * i], t->rgb[3 * i + 1], t->rgb[3 * i + 2]));
    return np ? k * (float)(sum / (double)np) : k;
}

static int plastic(cdl_mts_ctx *c, cdl_xml_node *n, int rough, cdl_material *m)
{
    *m = cdl_material_default(rough ? CDL_MAT_ROUGH_COATED : CDL_MAT_COATED);
    cdl_xml_node *ksn = cdl_mts_prop(c, n, "specular_reflectance");
    int rc, ks_given = ksn != NULL;
    if (ksn)
        ksn->used = 0; /* read below */
    if ((rc = cdl_mts_color_prop(c, n, "diffuse_reflectance", cdl_v3(0.5f, 0.5f, 0.5f), &m->kd, &m->kd_tex)) ||
        (rc = cdl_mts_color_prop(c, n, "specular_reflectance", cdl_v3(1, 1, 1), &m->ks, NULL)) ||
        (rc = rel_ior(c, n, 1.49, &m->eta)) || (rc = roughness(c, n, rough, m)) ||
        (rc = cdl_mts_bool(c, n, "nonlinear", 0, &m->nonlinear)))
        return rc;
    m->ks = at_most_one(c, n->line, "specular_reflectance", m->ks);
    m->kd = at_most_one(c, n->line, "diffuse reflectance", m->kd);
    if (fabsf(m->eta - 1.0f) < 1e-6f)
        return cdl_mts_error(c, n->line, "bsdf \"%s\": int_ior and ext_ior must differ", rough ? "roughplastic" : "plastic");
    if (rough && m->alpha_x != m->alpha_y)
        return cdl_mts_error(c, n->line, "bsdf \"roughplastic\": anisotropic roughness is not supported (nor by Mitsuba)");
    float d = texture_mean(c, m->kd, m->kd_tex), sm = ks_given ? (m->ks.x + m->ks.y + m->ks.z) / 3.0f : 1.0f;
    m->spec_weight = d + sm > 0.0f ? sm / (d + sm) : 0.5f;
    cdl_coat_prepare(m);
    return 0;
}

/* mask: the nested material (a copy) with an opacity, a constant or the
 * luminance of a texture. */
static int mask(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat)
{
    cdl_vec3 v;
    int tex, rc, found;
    int32_t inner;
    if ((rc = cdl_mts_color_prop(c, n, "opacity", cdl_v3(0.5f, 0.5f, 0.5f), &v, &tex)) ||
        (rc = cdl_mts_child_bsdf(c, n, 0, &inner, &found)))
        return rc;
    if (!found)
        return cdl_mts_error(c, n->line, "bsdf \"mask\" needs a nested <bsdf> or <ref>");
    if (inner < 0) { /* a null bsdf stays invisible */
        *mat = inner;
        return 0;
    }
    cdl_material m = c->s->mats[inner];
    float op = cdl_luminance(v);
    if (m.masked && m.opacity_tex >= 0 && tex >= 0) {
        cdl_mts_warn(c, n->line, "bsdf \"mask\" inside a textured mask: the inner texture is used, this one's scale only");
        tex = m.opacity_tex;
    }
    if (m.masked) {
        op *= m.opacity;
        if (tex < 0)
            tex = m.opacity_tex;
    }
    m.masked = 1;
    m.opacity = cdl_minf(1.0f, op);
    m.opacity_tex = tex;
    const char *id = cdl_xml_attr_get(n, "id");
    snprintf(m.name, sizeof m.name, "%.63s", id ? id : "mask");
    cdl_mts_warn_unused(c, n, "mask");
    uint32_t idx;
    if ((rc = cdl_mts_add_material(c, n->line, &m, &idx)))
        return rc;
    *mat = (int32_t)idx;
    return 0;
}

/* Mitsuba 3's principled and principledthin: every parameter but eta and
 * the sampling rates may be a texture (its scale times its value at the
 * hit). Out-of-range constants would make lobe weights negative: clamped
 * to Mitsuba's documented ranges, with a warning. */
static int principled(cdl_mts_ctx *c, cdl_xml_node *n, int thin, cdl_material *m)
{
    static const struct {
        const char *name;
        int slot, where; /* where: 0 both, 1 principled only, 2 thin only */
        float max;
    } P[] = {{"roughness", CDL_PR_ROUGHNESS, 0, 1},   {"anisotropic", CDL_PR_ANISOTROPIC, 0, 1},
             {"metallic", CDL_PR_METALLIC, 1, 1},     {"spec_trans", CDL_PR_SPEC_TRANS, 0, 1},
             {"spec_tint", CDL_PR_SPEC_TINT, 0, 1},   {"sheen", CDL_PR_SHEEN, 0, 1},
             {"sheen_tint", CDL_PR_SHEEN_TINT, 0, 1}, {"flatness", CDL_PR_FLATNESS, 0, 1},
             {"clearcoat", CDL_PR_CLEARCOAT, 1, 1},   {"clearcoat_gloss", CDL_PR_CC_GLOSS, 1, 1},
             {"diff_trans", CDL_PR_DIFF_TRANS, 2, 2}, {"eta", CDL_PR_ETA, 2, 100}};
    static const char *const RATES[2][CDL_PR_NRATES] = {
        {"diffuse_reflectance_sampling_rate", "main_specular_sampling_rate", "clearcoat_sampling_rate", NULL},
        {"diffuse_reflectance_sampling_rate", "specular_reflectance_sampling_rate",
         "specular_transmittance_sampling_rate", "diffuse_transmittance_sampling_rate"}};
    int rc;
    *m = cdl_material_default(CDL_MAT_PRINCIPLED);
    m->pr = cdl_principled_default(thin);
    if ((rc = cdl_mts_color_prop(c, n, "base_color", cdl_v3(0.5f, 0.5f, 0.5f), &m->kd, &m->kd_tex)))
        return rc;
    m->kd = at_most_one(c, n->line, "base_color", m->kd);
    for (size_t i = 0; i < sizeof P / sizeof P[0]; i++) {
        if (P[i].where == (thin ? 1 : 2))
            continue;
        float def = m->pr.value[P[i].slot];
        cdl_vec3 v;
        if ((rc = cdl_mts_color_prop(c, n, P[i].name, cdl_v3(def, def, def), &v, &m->pr.tex[P[i].slot])))
            return rc;
        /* a colour where a float belongs: its luminance (Mitsuba's eval_1) */
        float x = 0.212671f * v.x + 0.715160f * v.y + 0.072169f * v.z;
        if (x > P[i].max || (P[i].slot == CDL_PR_ETA && !(x > 0.0f))) {
            cdl_mts_warn(c, n->line, "%s %g is outside Mitsuba's range [0, %g]: clamped", P[i].name, (double)x,
                         (double)P[i].max);
            x = x > P[i].max ? P[i].max : 1.0f;
        }
        m->pr.value[P[i].slot] = x;
    }
    for (int i = 0; i < CDL_PR_NRATES; i++) {
        double r;
        if (!RATES[thin][i])
            continue;
        if ((rc = cdl_mts_float(c, n, RATES[thin][i], 1.0, &r)))
            return rc;
        if (!(r >= 0.0 && r <= 1e6))
            return cdl_mts_error(c, n->line, "%s %g must be in [0, 1e6]", RATES[thin][i], r);
        m->pr.rate[i] = (float)r;
    }
    if (thin)
        return 0;
    /* principled: eta, or specular with eta = 2 / (1 - sqrt(0.08 specular)) - 1 */
    cdl_xml_node *pt = cdl_mts_prop(c, n, "spec_trans");
    int has_trans = pt && (strcmp(pt->name, "float") || m->pr.value[CDL_PR_SPEC_TRANS] != 0.0f);
    cdl_xml_node *pe = cdl_mts_prop(c, n, "eta"), *ps = cdl_mts_prop(c, n, "specular");
    double x;
    if (pe && ps)
        return cdl_mts_error(c, n->line, "principled: give either eta or specular, not both");
    if (pe) {
        pe->used = 0;
        if ((rc = cdl_mts_float(c, n, "eta", 1.5, &x)))
            return rc;
        if (!(x > 0.0 && x < 100.0))
            return cdl_mts_error(c, pe->line, "eta %g must be in (0, 100)", x);
        if (has_trans && x == 1.0)
            x = 1.001; /* Mitsuba: eta 1 is not plausible for transmission */
    } else if (ps) {
        ps->used = 0;
        if ((rc = cdl_mts_float(c, n, "specular", 0.5, &x)))
            return rc;
        if (!(x >= 0.0 && x <= 10.0))
            return cdl_mts_error(c, ps->line, "specular %g must be in [0, 10]", x);
        if (has_trans && x == 0.0)
            x = 1e-3; /* as Mitsuba: specular 0 means eta 1 */
        x = 2.0 / (1.0 - sqrt(0.08 * x)) - 1.0;
    } else {
        x = m->pr.value[CDL_PR_ETA];
    }
    m->pr.value[CDL_PR_ETA] = (float)x;
    return 0;
}

/* Mitsuba's blendbsdf: (1 - weight) first + weight second, chosen per hit
 * (scene/attr.h); two plain diffuse bsdfs blend their reflectances. */
static int blend(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat)
{
    int32_t kid[2];
    int nk = 0, rc, tex;
    double w;
    if ((rc = cdl_mts_float_or_texture(c, n, "weight", 0.5, &w, &tex)))
        return rc;
    if (!(w >= 0.0 && w <= 1.0) && tex < 0)
        return cdl_mts_error(c, n->line, "blendbsdf weight %g must be in [0, 1]", w);
    for (int i = 0; i < n->nkids && !rc; i++) {
        cdl_xml_node *k = &n->kids[i];
        const cdl_mts_id *d = NULL;
        if (!strcmp(k->name, "ref")) {
            const char *id = cdl_mts_attr(c, k, "id", &rc);
            if (rc || !id || !(d = cdl_mts_find_id(c, id)) || d->kind != CDL_MTS_BSDF)
                continue; /* the weight's texture, or an error reported by it */
        } else if (strcmp(k->name, "bsdf")) {
            continue;
        }
        if (nk == 2)
            return cdl_mts_error(c, k->line, "blendbsdf blends two bsdfs");
        k->used = 1;
        if (d) {
            kid[nk++] = d->mat;
        } else if (!(rc = cdl_mts_bsdf(c, k, &kid[nk])))
            rc = nested_id(c, k, CDL_MTS_BSDF, kid[nk++], -1, cdl_v3(0, 0, 0));
    }
    if (rc)
        return rc;
    if (nk != 2)
        return cdl_mts_error(c, n->line, "blendbsdf needs two nested bsdfs (<bsdf> or <ref>), not %d", nk);
    if (kid[0] < 0 || kid[1] < 0) {
        cdl_mts_warn(c, n->line, "blendbsdf of a null bsdf: the other one is rendered");
        *mat = kid[0] < 0 ? kid[1] : kid[0];
        return 0;
    }
    cdl_material m = cdl_material_default(CDL_MAT_BLEND);
    m.blend[0] = kid[0];
    m.blend[1] = kid[1];
    m.blend_w = tex >= 0 ? 1.0f : (float)w;
    m.blend_tex = tex;
    const cdl_material *a = &c->s->mats[kid[0]], *b = &c->s->mats[kid[1]];
    uint32_t idx;
    if (a->type == CDL_MAT_DIFFUSE && b->type == CDL_MAT_DIFFUSE && !a->masked && !b->masked && !a->maps.on &&
        !b->maps.on) {
        cdl_material d = cdl_material_default(CDL_MAT_DIFFUSE);
        d.kd = cdl_v3(1.0f, 1.0f, 1.0f);
        d.hit_kd = 1;
        d.one_sided = a->one_sided && b->one_sided;
        snprintf(d.name, sizeof d.name, "blend-of-diffuse");
        if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_add_material(c->s, &d, &idx, c->err))))
            return rc;
        m.blend_as = (int)idx;
    }
    const char *id = cdl_xml_attr_get(n, "id");
    snprintf(m.name, sizeof m.name, "%.63s", id ? id : "blendbsdf");
    cdl_mts_warn_unused(c, n, "bsdf \"blendbsdf\"");
    if ((rc = cdl_mts_add_material(c, n->line, &m, &idx)))
        return rc;
    *mat = (int32_t)idx;
    return 0;
}

/* twosided: the nested bsdf on both sides. One made inside is two-sided
 * already; one referred to (declared one-sided) is copied. A second
 * nested bsdf (Mitsuba 3: a different back side) is not rendered. */
static int two_sided(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat)
{
    int nb = 0;
    for (int k = 0; k < n->nkids; k++)
        nb += !strcmp(n->kids[k].name, "bsdf") || !strcmp(n->kids[k].name, "ref");
    if (nb > 1)
        cdl_mts_warn(c, n->line, "bsdf \"twosided\" with a second bsdf for the back side: the first is used on both");
    if (*mat < 0 || !c->s->mats[*mat].one_sided)
        return 0;
    cdl_material m = c->s->mats[*mat];
    m.one_sided = 0;
    uint32_t idx;
    int rc = cdl_mts_add_material(c, n->line, &m, &idx);
    if (!rc)
        *mat = (int32_t)idx;
    return rc;
}

int cdl_mts_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat)
{
    char type[64];
    int rc = cdl_mts_type(c, n, type, sizeof type), found;
    if (rc)
        return rc;
    n->used = 1;
    /* wrappers: the surface is the nested bsdf's */
    if (!strcmp(type, "mask"))
        return mask(c, n, mat);
    if (!strcmp(type, "blendbsdf"))
        return blend(c, n, mat);
    static const char *const wrap[] = {"twosided", "bumpmap", "normalmap", "coating", "roughcoating"};
    if (!strcmp(type, "bumpmap") || !strcmp(type, "normalmap"))
        return cdl_mts_perturbed_bsdf(c, n, type, mat);
    for (size_t i = 0; i < sizeof wrap / sizeof wrap[0]; i++)
        if (!strcmp(type, wrap[i])) {
            c->in_twosided += i == 0;
            rc = cdl_mts_child_bsdf(c, n, 0, mat, &found);
            c->in_twosided -= i == 0;
            if (rc)
                return rc;
            if (!found)
                return cdl_mts_error(c, n->line, "bsdf \"%s\" needs a nested <bsdf> or <ref>", type);
            if (i == 0 && (rc = two_sided(c, n, mat)))
                return rc;
            if (i > 0) {
                cdl_mts_warn(c, n->line, "bsdf \"%s\": only its (first) nested bsdf is rendered", type);
                for (int k = 0; k < n->nkids; k++)
                    n->kids[k].used = 1;
            }
            cdl_mts_warn_unused(c, n, type);
            return 0;
        }
    cdl_material m;
    int rough = !strncmp(type, "rough", 5);
    if (!strcmp(type, "diffuse") || !strcmp(type, "roughdiffuse")) {
        m = cdl_material_default(CDL_MAT_DIFFUSE);
        rc = cdl_mts_color_prop(c, n, "reflectance", cdl_v3(0.5f, 0.5f, 0.5f), &m.kd, &m.kd_tex);
        if (!rc && type[0] == 'r') {
            /* Mitsuba 0.6: sigma = alpha / sqrt(2), the full model unless
             * use_fast_approx */
            double alpha;
            int fast;
            if (!cdl_mts_prop(c, n, "reflectance") && cdl_mts_prop(c, n, "diffuse_reflectance"))
                rc = cdl_mts_color_prop(c, n, "diffuse_reflectance", cdl_v3(0.5f, 0.5f, 0.5f), &m.kd, &m.kd_tex);
            if (!rc && !(rc = cdl_mts_float(c, n, "alpha", 0.2, &alpha)) &&
                !(rc = cdl_mts_bool(c, n, "use_fast_approx", 0, &fast))) {
                if (!(alpha >= 0.0 && alpha <= 10.0))
                    return cdl_mts_error(c, n->line, "roughdiffuse alpha %g must be in [0, 10]", alpha);
                m.type = CDL_MAT_ROUGH_DIFFUSE;
                m.sigma = (float)(alpha / sqrt(2.0));
                m.on_full = !fast;
            }
        }
    } else if (!strcmp(type, "plastic") || !strcmp(type, "roughplastic")) {
        rc = plastic(c, n, rough, &m);
    } else if (!strcmp(type, "conductor") || !strcmp(type, "roughconductor")) {
        rc = conductor(c, n, rough, &m);
    } else if (!strcmp(type, "dielectric") || !strcmp(type, "roughdielectric") || !strcmp(type, "thindielectric")) {
        m = cdl_material_default(rough ? CDL_MAT_ROUGH_DIELECTRIC : CDL_MAT_DIELECTRIC);
        if (type[0] == 't')
            cdl_mts_warn(c, n->line, "bsdf \"thindielectric\": rendered as a dielectric interface");
        if (!(rc = rel_ior(c, n, 1.5046, &m.eta)) &&
            !(rc = cdl_mts_color_prop(c, n, "specular_reflectance", cdl_v3(1, 1, 1), &m.ks, NULL)) &&
            !(rc = cdl_mts_color_prop(c, n, "specular_transmittance", cdl_v3(1, 1, 1), &m.kt, NULL)))
            rc = roughness(c, n, rough, &m);
        m.ks = at_most_one(c, n->line, "specular_reflectance", m.ks);
        m.kt = at_most_one(c, n->line, "specular_transmittance", m.kt);
        if (!rough)
            m.mf = CDL_MF_PBRT;
    } else if (!strcmp(type, "phong")) {
        double e = 30.0;
        m = cdl_material_default(CDL_MAT_PHONG);
        if (!(rc = cdl_mts_color_prop(c, n, "diffuse_reflectance", cdl_v3(0.5f, 0.5f, 0.5f), &m.kd, &m.kd_tex)) &&
            !(rc = cdl_mts_color_prop(c, n, "specular_reflectance", cdl_v3(0.2f, 0.2f, 0.2f), &m.ks, NULL)) &&
            !(rc = cdl_mts_float(c, n, "exponent", 30.0, &e)) && !(e >= 0.0 && e <= 1e6))
            rc = cdl_mts_error(c, n->line, "phong exponent %g must be in [0, 1e6]", e);
        m.ns = (float)e;
        float sc = cdl_phong_energy_scale(&m);
        if (!rc && sc < 1.0f) {
            cdl_mts_warn(c, n->line, "phong: diffuse + specular reflect more than all light; scaled by %.3f",
                         (double)sc);
            m.kd = cdl_scale(m.kd, sc);
            m.ks = cdl_scale(m.ks, sc);
        }
    } else if (!strcmp(type, "principled") || !strcmp(type, "principledthin")) {
        rc = principled(c, n, type[10] == 't', &m);
    } else if (!strcmp(type, "null")) {
        cdl_mts_warn_unused(c, n, "bsdf \"null\"");
        *mat = -1;
        return 0;
    } else {
        cdl_mts_warn(c, n->line, "bsdf \"%s\" is not supported: rendered as diffuse", type);
        m = cdl_material_default(CDL_MAT_DIFFUSE);
        /* the base colour under its usual names (principled: base_color) */
        cdl_xml_node *p = cdl_mts_prop(c, n, "reflectance");
        if (!p)
            p = cdl_mts_prop(c, n, "diffuse_reflectance");
        if (!p)
            p = cdl_mts_prop(c, n, "base_color");
        if (p)
            p->used = 0;
        if (p && cdl_mts_color_prop(c, n, cdl_xml_attr_get(p, "name"), m.kd, &m.kd, &m.kd_tex))
            return CDL_ERR_INPUT;
        for (int k = 0; k < n->nkids; k++)
            n->kids[k].used = 1;
    }
    if (rc)
        return rc;
    if (m.type == CDL_MAT_DIFFUSE || m.type == CDL_MAT_COATED || m.type == CDL_MAT_ROUGH_COATED ||
        m.type == CDL_MAT_PHONG)
        m.kd = at_most_one(c, n->line, "diffuse reflectance", m.kd);
    /* Mitsuba's opaque bsdfs reflect on the front side only */
    m.one_sided = !c->in_twosided;
    if (!c->in_twosided && !c->said_one_sided && m.type == CDL_MAT_PRINCIPLED) {
        cdl_mts_warn(c, n->line,
                     "bsdf \"%s\" outside a twosided wrapper: Mitsuba renders its back face black, candela "
                     "reflects on both sides (said once per file)", type);
        c->said_one_sided = 1;
    }
    const char *id = cdl_xml_attr_get(n, "id");
    snprintf(m.name, sizeof m.name, "%.63s", id ? id : type);
    cdl_mts_warn_unused(c, n, type);
    uint32_t idx;
    if ((rc = cdl_mts_add_material(c, n->line, &m, &idx)))
        return rc;
    *mat = (int32_t)idx;
    return 0;
}

int cdl_mts_texture(cdl_mts_ctx *c, cdl_xml_node *n, int *tex, cdl_vec3 *value)
{
    char type[64];
    int rc = cdl_mts_type(c, n, type, sizeof type);
    if (rc)
        return rc;
    n->used = 1;
    *tex = -1;
    *value = cdl_v3(1, 1, 1);
    if (!strcmp(type, "bitmap") || !strcmp(type, "checkerboard") || !strcmp(type, "scale") ||
        !strcmp(type, "rawconstant") || !strcmp(type, "mesh_attribute")) {
        if ((rc = cdl_mts_texture_plugin(c, n, type, tex, value)))
            return rc;
    } else {
        cdl_mts_warn(c, n->line, "texture \"%s\" is not supported: a constant 0.5", type);
        *value = cdl_v3(0.5f, 0.5f, 0.5f);
        for (int k = 0; k < n->nkids; k++)
            n->kids[k].used = 1;
    }
    cdl_mts_warn_unused(c, n, type);
    return 0;
}
