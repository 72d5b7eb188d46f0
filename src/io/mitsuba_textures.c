/* Mitsuba textures (bitmap, checkerboard, scale, rawconstant,
 * mesh_attribute), textured
 * roughness, the bumpmap and normalmap wrappers and Mitsuba's named
 * conductors, as Mitsuba 3 defines them (src/textures/, src/bsdfs/). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/mitsuba_internal.h"
#include "io/pbrt_params.h"
#include "scene/scene.h"

/* Mitsuba's uv is (u, 1 - v) of candela's (its OBJ reader flips v);
 * to_uv's x and y rows (a 4x4 loses its z row and column) follow. */
static int uv_map(cdl_mts_ctx *c, cdl_xml_node *n, cdl_texture *t)
{
    cdl_mat4 m;
    int rc = cdl_mts_transform(c, n, "to_uv", &m);
    if (rc)
        return rc;
    cdl_vec3 o = cdl_mat4_point3(&m, cdl_v3(0, 0, 0));
    cdl_vec3 ex = cdl_sub(cdl_mat4_point3(&m, cdl_v3(1, 0, 0)), o);
    cdl_vec3 ey = cdl_sub(cdl_mat4_point3(&m, cdl_v3(0, 1, 0)), o);
    t->m[0] = ex.x;
    t->m[1] = -ey.x;
    t->m[2] = o.x + ey.x;
    t->m[3] = ex.y;
    t->m[4] = -ey.y;
    t->m[5] = o.y + ey.y;
    for (int i = 0; i < 6; i++)
        if (!isfinite(t->m[i]) || fabsf(t->m[i]) > 1e6f)
            return cdl_mts_error(c, n->line, "to_uv is out of range");
    return 0;
}

static int add(cdl_mts_ctx *c, int line, cdl_texture *t, int *tex)
{
    return cdl_mts_scene_rc(c, line, cdl_scene_add_texture_data(c->s, t, tex, c->err));
}

static int bitmap(cdl_mts_ctx *c, cdl_xml_node *n, int *tex)
{
    char fn[1024], path[1024], wrap[32], filter[32];
    int raw, rc;
    if ((rc = cdl_mts_string(c, n, "filename", NULL, fn, sizeof fn)) ||
        (rc = cdl_mts_bool(c, n, "raw", 0, &raw)) ||
        (rc = cdl_mts_string(c, n, "wrap_mode", "repeat", wrap, sizeof wrap)) ||
        (rc = cdl_mts_string(c, n, "filter_type", "bilinear", filter, sizeof filter)))
        return rc;
    if (!fn[0])
        return cdl_mts_error(c, n->line, "texture \"bitmap\" needs a \"filename\"");
    int w = !strcmp(wrap, "repeat") ? CDL_WRAP_REPEAT
            : !strcmp(wrap, "mirror") ? CDL_WRAP_MIRROR
            : !strcmp(wrap, "clamp")  ? CDL_WRAP_CLAMP
                                      : -1;
    if (w < 0)
        return cdl_mts_error(c, n->line, "wrap_mode \"%s\" must be repeat, mirror or clamp", wrap);
    if (strcmp(filter, "bilinear") && strcmp(filter, "nearest"))
        return cdl_mts_error(c, n->line, "filter_type \"%s\" must be bilinear or nearest", filter);
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_BITMAP);
    if ((rc = uv_map(c, n, &t)) || (rc = cdl_mts_path(c, n->line, fn, path, sizeof path)))
        return rc;
    float m[6];
    memcpy(m, t.m, sizeof m);
    rc = cdl_texture_load_image(&t, path, raw, c->err);
    if (rc)
        return cdl_mts_scene_rc(c, n->line, rc);
    memcpy(t.m, m, sizeof m);
    t.wrap = w;
    t.nearest = !strcmp(filter, "nearest");
    /* storage details that do not change the values candela looks up */
    static const char *const fine[] = {"gamma", "cache", "max_anisotropy", "format", "channel", "accel"};
    for (size_t i = 0; i < sizeof fine / sizeof fine[0]; i++)
        cdl_mts_prop(c, n, fine[i]);
    return add(c, n->line, &t, tex);
}

/* A texture-valued property of a texture: a nested <texture>, a <ref> to
 * one, or a constant (*sub = -1, *value). */
static int operand(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, cdl_vec3 def, int *sub, cdl_vec3 *value)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *sub = -1;
    *value = def;
    if (!p)
        return 0;
    if (!strcmp(p->name, "texture"))
        return cdl_mts_texture(c, p, sub, value);
    if (!strcmp(p->name, "ref")) {
        int rc = 0;
        const char *id = cdl_mts_attr(c, p, "id", &rc);
        if (rc)
            return rc;
        const cdl_mts_id *d = id ? cdl_mts_find_id(c, id) : NULL;
        if (!d || d->kind != CDL_MTS_TEXTURE)
            return cdl_mts_error(c, p->line, "%s: <ref id=\"%s\"> is not a texture declared before", name,
                                 id ? id : "");
        *sub = d->tex;
        *value = d->value;
        return 0;
    }
    int rc = cdl_mts_color_node(c, p, value);
    if (!rc && !cdl_is_finite3(*value))
        rc = cdl_mts_error(c, p->line, "%s must be finite", name);
    return rc;
}

/* A constant operand becomes part of the texture; a texture operand whose
 * value is not 1 (a constant of Mitsuba's) is folded in as a scale. */
static int fold(cdl_mts_ctx *c, int line, int *sub, cdl_vec3 value)
{
    if (*sub < 0 || (value.x == 1.0f && value.y == 1.0f && value.z == 1.0f))
        return 0;
    if (value.x != value.y || value.y != value.z)
        cdl_mts_warn(c, line, "a colored factor on a texture: its mean is used");
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_SCALE);
    t.sub[0] = *sub;
    t.scale = (value.x + value.y + value.z) / 3.0f;
    return add(c, line, &t, sub);
}

static int checkerboard(cdl_mts_ctx *c, cdl_xml_node *n, int *tex)
{
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_CHECKER);
    int rc;
    if ((rc = operand(c, n, "color0", cdl_v3(0.4f, 0.4f, 0.4f), &t.sub[0], &t.a)) ||
        (rc = operand(c, n, "color1", cdl_v3(0.2f, 0.2f, 0.2f), &t.sub[1], &t.b)) ||
        (rc = fold(c, n->line, &t.sub[0], t.a)) || (rc = fold(c, n->line, &t.sub[1], t.b)) ||
        (rc = uv_map(c, n, &t)))
        return rc;
    return add(c, n->line, &t, tex);
}

/* Mitsuba 0.6's scale texture: a nested texture (or value) times scale. */
static int scale_texture(cdl_mts_ctx *c, cdl_xml_node *n, int *tex)
{
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_SCALE);
    double sc;
    int rc = cdl_mts_float(c, n, "scale", 1.0, &sc);
    if (rc)
        return rc;
    if (!(fabs(sc) < 1e12))
        return cdl_mts_error(c, n->line, "scale %g out of range", sc);
    t.scale = (float)sc;
    for (int i = 0; i < n->nkids && t.sub[0] < 0; i++) {
        cdl_xml_node *k = &n->kids[i];
        const char *name = cdl_xml_attr_get(k, "name");
        if ((!strcmp(k->name, "texture") || !strcmp(k->name, "ref")) && name && *name)
            rc = operand(c, n, name, t.a, &t.sub[0], &t.a);
        else if (!strcmp(k->name, "texture")) {
            k->used = 1;
            rc = cdl_mts_texture(c, k, &t.sub[0], &t.a);
        }
        if (rc)
            return rc;
    }
    if (t.sub[0] < 0 && (rc = operand(c, n, "value", t.a, &t.sub[0], &t.a)))
        return rc;
    if ((rc = fold(c, n->line, &t.sub[0], t.a)))
        return rc;
    return add(c, n->line, &t, tex);
}

/* Mitsuba 3's mesh_attribute: a shape's "vertex_*" (interpolated) or
 * "face_*" attribute, times scale; read at the hit (scene/attr.h). */
static int mesh_attribute(cdl_mts_ctx *c, cdl_xml_node *n, int *tex)
{
    char name[256];
    double sc;
    int rc;
    if ((rc = cdl_mts_string(c, n, "name", NULL, name, sizeof name)) || (rc = cdl_mts_float(c, n, "scale", 1.0, &sc)))
        return rc;
    if (strncmp(name, "vertex_", 7) && strncmp(name, "face_", 5))
        return cdl_mts_error(c, n->line, "mesh_attribute name \"%s\" must start with vertex_ or face_", name);
    if (strlen(name) >= CDL_ATTR_NAME)
        return cdl_mts_error(c, n->line, "mesh_attribute name \"%s\" is longer than %d characters", name,
                             CDL_ATTR_NAME - 1);
    if (!(fabs(sc) < 1e12))
        return cdl_mts_error(c, n->line, "scale %g out of range", sc);
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_ATTRIBUTE);
    snprintf(t.attr, sizeof t.attr, "%s", name);
    t.scale = (float)sc;
    return add(c, n->line, &t, tex);
}

int cdl_mts_texture_plugin(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, int *tex, cdl_vec3 *value)
{
    *tex = -1;
    *value = cdl_v3(1, 1, 1);
    if (!strcmp(type, "bitmap"))
        return bitmap(c, n, tex);
    if (!strcmp(type, "checkerboard"))
        return checkerboard(c, n, tex);
    if (!strcmp(type, "scale"))
        return scale_texture(c, n, tex);
    if (!strcmp(type, "mesh_attribute"))
        return mesh_attribute(c, n, tex);
    /* rawconstant: a value used as it is (a normal map's (0.5, 0.5, 1)) */
    cdl_xml_node *p = cdl_mts_prop(c, n, "value");
    if (!p)
        return cdl_mts_error(c, n->line, "texture \"%s\" needs a \"value\"", type);
    int rc = 0;
    if (!strcmp(p->name, "vector") || !strcmp(p->name, "point")) {
        p->used = 0;
        rc = cdl_mts_vec(c, n, "value", *value, value, NULL);
    } else {
        rc = cdl_mts_color_node(c, p, value);
    }
    if (!rc && !cdl_is_finite3(*value))
        rc = cdl_mts_error(c, p->line, "value must be finite");
    if (rc)
        return rc;
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_CONST);
    t.a = *value;
    *value = cdl_v3(1, 1, 1);
    return add(c, n->line, &t, tex);
}

int cdl_mts_float_or_texture(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double *out, int *tex)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    *tex = -1;
    *out = def;
    if (!p)
        return 0;
    if (strcmp(p->name, "texture") && strcmp(p->name, "ref")) {
        p->used = 0;
        return cdl_mts_float(c, n, name, def, out);
    }
    p->used = 0;
    cdl_vec3 v;
    int rc = operand(c, n, name, cdl_v3((float)def, (float)def, (float)def), tex, &v);
    if (!rc && *tex < 0)
        *out = cdl_tex_luminance(v);
    if (!rc)
        rc = fold(c, p->line, tex, v);
    return rc;
}

int cdl_mts_perturbed_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, int32_t *mat)
{
    int found, rc, tex = -1;
    double scale = 1.0;
    cdl_vec3 v;
    if ((rc = cdl_mts_child_bsdf(c, n, 0, mat, &found)))
        return rc;
    if (!found)
        return cdl_mts_error(c, n->line, "bsdf \"%s\" needs a nested <bsdf> or <ref>", type);
    int bump = !strcmp(type, "bumpmap");
    if (bump) {
        if ((rc = cdl_mts_float(c, n, "scale", 1.0, &scale)))
            return rc;
        if (!(fabs(scale) < 1e6))
            return cdl_mts_error(c, n->line, "bumpmap scale %g out of range", scale);
        /* the one texture child, whatever its name */
        for (int i = 0; i < n->nkids && tex < 0 && !rc; i++) {
            cdl_xml_node *k = &n->kids[i];
            const char *name = cdl_xml_attr_get(k, "name");
            if (!strcmp(k->name, "texture") || (!strcmp(k->name, "ref") && name && *name)) {
                if (name && *name)
                    rc = operand(c, n, name, cdl_v3(0, 0, 0), &tex, &v);
                else {
                    k->used = 1;
                    rc = cdl_mts_texture(c, k, &tex, &v);
                }
            }
        }
    } else {
        rc = operand(c, n, "normalmap", cdl_v3(0.5f, 0.5f, 1.0f), &tex, &v);
    }
    if (rc)
        return rc;
    if (tex < 0)
        return cdl_mts_error(c, n->line, "bsdf \"%s\" needs a <texture>", type);
    cdl_mts_prop(c, n, "flip_invalid_normals");
    cdl_mts_prop(c, n, "use_shadowing_function");
    cdl_mts_warn_unused(c, n, type);
    if (*mat < 0)
        return 0; /* over a null bsdf: nothing to perturb */
    cdl_material m = c->s->mats[*mat];
    if (m.maps.bump_tex >= 0 || m.maps.normal_tex >= 0)
        cdl_mts_warn(c, n->line, "bsdf \"%s\" over another bump or normal map: only the outer one is used", type);
    if (!m.maps.on)
        m.maps.alpha_tex[0] = m.maps.alpha_tex[1] = -1;
    m.maps.on = 1;
    m.maps.bump_tex = m.maps.normal_tex = -1;
    if (bump) {
        m.maps.bump_tex = tex;
        m.maps.bump_scale = (float)scale;
    } else {
        m.maps.normal_tex = tex;
    }
    uint32_t idx;
    if ((rc = cdl_mts_add_material(c, n->line, &m, &idx)))
        return rc;
    *mat = (int32_t)idx;
    return 0;
}

/* Mitsuba's conductors that pbrt lacks, as Mitsuba 3 makes them in RGB
 * modes (ior.h): the .spd spectrum of data/ior integrated against the CIE
 * 1931 curves without an illuminant, to linear sRGB. */
static const struct {
    const char *name;
    float eta[3], k[3];
} CONDUCTORS[] = {
    {"a-C", {2.9430134f, 2.2276976f, 1.9647945f}, {0.8872724f, 0.7994568f, 0.8139083f}},
};

int cdl_mts_named_conductor(const char *name, cdl_vec3 *eta, cdl_vec3 *k)
{
    for (size_t i = 0; i < sizeof CONDUCTORS / sizeof CONDUCTORS[0]; i++)
        if (!strcmp(name, CONDUCTORS[i].name)) {
            *eta = cdl_v3(CONDUCTORS[i].eta[0], CONDUCTORS[i].eta[1], CONDUCTORS[i].eta[2]);
            *k = cdl_v3(CONDUCTORS[i].k[0], CONDUCTORS[i].k[1], CONDUCTORS[i].k[2]);
            return 0;
        }
    char ne[48], nk[48];
    snprintf(ne, sizeof ne, "metal-%s-eta", name);
    snprintf(nk, sizeof nk, "metal-%s-k", name);
    int r1 = cdl_pbrt_named_spectrum(ne, eta), r2 = cdl_pbrt_named_spectrum(nk, k);
    return r1 < 0 || r2 < 0 || r1 == 1 ? -1 : 0;
}
