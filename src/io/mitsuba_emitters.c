/* Mitsuba emitters as candela's lights: area emitters on shapes, the
 * environment map, spot and projector (point, directional and constant
 * lights too), with Mitsuba 3's defaults; sunsky is mitsuba_sunsky.c. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/mitsuba_internal.h"
#include "scene/scene.h"

static int check_emission(cdl_mts_ctx *c, int line, const char *what, cdl_vec3 v)
{
    if (!cdl_is_finite3(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f || cdl_max3(v) > 1e12f)
        return cdl_mts_error(c, line, "%s (%g, %g, %g) must be finite, >= 0 and <= 1e12", what, (double)v.x,
                             (double)v.y, (double)v.z);
    return 0;
}

int cdl_mts_area(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *emit)
{
    char type[64];
    cdl_vec3 L;
    int rc = cdl_mts_type(c, n, type, sizeof type);
    if (rc)
        return rc;
    n->used = 1;
    if (strcmp(type, "area"))
        return cdl_mts_error(c, n->line, "emitter \"%s\" inside a <shape>: only \"area\" belongs there", type);
    int tex;
    if ((rc = cdl_mts_color_prop(c, n, "radiance", cdl_v3(1, 1, 1), &L, &tex)) ||
        (rc = check_emission(c, n->line, "area radiance", L)))
        return rc;
    cdl_mts_prop(c, n, "sampling_weight");
    cdl_mts_warn_unused(c, n, "emitter \"area\"");
    /* Mitsuba's area emitters shine from the front face only; a bitmap
     * radiance is looked up at the surface's uv as a reflectance is */
    if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_add_emitter(c->s, L, 0, emit, c->err))))
        return rc;
    c->s->emitters[*emit].tex = tex;
    return 0;
}

int cdl_mts_latlong_light(cdl_mts_ctx *c, int line, const cdl_vec3 axes[3], const char *path, float scale, int w,
                          int h, float *rgb)
{
    /* Mitsuba's map is y-up with u = atan2(x, -z) / 2 pi: pbrt-v3's z-up
     * frame with x' = -z, y' = x, z' = y */
    cdl_vec3 frame[3] = {cdl_scale(axes[2], -1.0f), axes[0], axes[1]};
    /* the texel layout of Mitsuba's lat-long maps, one place for envmap and sunsky */
    const int layout = CDL_ENVMAP_MITSUBA;
    cdl_envmap *em = malloc(sizeof *em);
    if (!em) {
        free(rgb);
        return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, line, "out of memory");
    }
    int rc;
    if (path) {
        rc = cdl_envmap_load(em, path, cdl_v3(scale, scale, scale), frame, layout, c->err);
    } else {
        rc = cdl_envmap_init(em, w, h, rgb, frame, layout, c->err);
        if (rc == CDL_ERR_INPUT) /* refused before it took the texels over */
            free(rgb);
        rc = cdl_mts_scene_rc(c, line, rc);
    }
    if (rc) {
        free(em);
        return rc;
    }
    return cdl_mts_scene_rc(c, line, cdl_scene_add_env_light(c->s, cdl_v3(1, 1, 1), em, c->err));
}

static int envmap(cdl_mts_ctx *c, cdl_xml_node *n, const cdl_mat4 *m)
{
    char fn[1024], path[1024];
    double scale;
    int rc;
    if ((rc = cdl_mts_string(c, n, "filename", NULL, fn, sizeof fn)) ||
        (rc = cdl_mts_float(c, n, "scale", 1.0, &scale)))
        return rc;
    if (!fn[0])
        return cdl_mts_error(c, n->line, "emitter \"envmap\" needs a \"filename\"");
    if (!(scale >= 0.0 && scale <= 1e12))
        return cdl_mts_error(c, n->line, "envmap scale %g must be in [0, 1e12]", scale);
    if ((rc = cdl_mts_path(c, n->line, fn, path, sizeof path)))
        return rc;
    cdl_mts_prop(c, n, "gamma");
    cdl_mts_prop(c, n, "cache");
    cdl_mts_prop(c, n, "filter_type");
    cdl_vec3 axes[3] = {cdl_mat4_vector3(m, cdl_v3(1, 0, 0)), cdl_mat4_vector3(m, cdl_v3(0, 1, 0)),
                        cdl_mat4_vector3(m, cdl_v3(0, 0, 1))};
    return cdl_mts_latlong_light(c, n->line, axes, path, (float)scale, 0, 0, NULL);
}

/* The unit frame of a spot or projector: to_world's x, y and z axes. */
static int light_frame(cdl_mts_ctx *c, cdl_xml_node *n, const cdl_mat4 *m, cdl_light *l)
{
    l->p = cdl_mat4_point3(m, cdl_v3(0, 0, 0));
    cdl_vec3 x = cdl_mat4_vector3(m, cdl_v3(1, 0, 0)), y = cdl_mat4_vector3(m, cdl_v3(0, 1, 0)),
             z = cdl_mat4_vector3(m, cdl_v3(0, 0, 1));
    float lx = cdl_length(x), ly = cdl_length(y), lz = cdl_length(z);
    if (!(lx > 0.0f && ly > 0.0f && lz > 0.0f) || !isfinite(lx + ly + lz))
        return cdl_mts_error(c, n->line, "emitter to_world is singular");
    l->ax = cdl_scale(x, 1.0f / lx);
    l->ay = cdl_scale(y, 1.0f / ly);
    l->n = cdl_scale(z, 1.0f / lz);
    if (fabsf(cdl_dot(l->ax, l->ay)) > 1e-3f || fabsf(cdl_dot(l->ax, l->n)) > 1e-3f ||
        fabsf(cdl_dot(l->ay, l->n)) > 1e-3f)
        return cdl_mts_error(c, n->line, "emitter to_world must keep right angles (rotations, translations, scales)");
    return 0;
}

/* Mitsuba 3's spot: intensity linear in the angle between beam_width and
 * cutoff_angle, times an optional texture projected over the cutoff cone. */
static int spot(cdl_mts_ctx *c, cdl_xml_node *n, const cdl_mat4 *m)
{
    double cut, beam;
    cdl_light l;
    cdl_vec3 k;
    int rc;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_SPOT;
    l.spot_linear = 1;
    if ((rc = cdl_mts_color_prop(c, n, "intensity", cdl_v3(1, 1, 1), &l.L, NULL)) ||
        (rc = check_emission(c, n->line, "spot intensity", l.L)) ||
        (rc = cdl_mts_float(c, n, "cutoff_angle", 20.0, &cut)) ||
        (rc = cdl_mts_float(c, n, "beam_width", cut * 0.75, &beam)) ||
        (rc = cdl_mts_color_prop(c, n, "texture", cdl_v3(1, 1, 1), &k, &l.tex_id)))
        return rc;
    if (!(cut > 0.0 && cut < 90.0))
        return cdl_mts_error(c, n->line, "spot cutoff_angle %g must be in (0, 90) degrees", cut);
    if (!(beam >= 0.0 && beam <= cut))
        return cdl_mts_error(c, n->line, "spot beam_width %g must be in [0, cutoff_angle = %g]", beam, cut);
    l.L = cdl_mul(l.L, k); /* a constant texture scales the intensity */
    if ((rc = light_frame(c, n, m, &l)))
        return rc;
    l.cutoff = (float)(cut * CDL_PI / 180.0);
    l.beam = (float)(beam * CDL_PI / 180.0);
    l.cos_total = cosf(l.cutoff);
    l.cos_falloff = cosf(l.beam);
    l.tan_x = l.tan_y = tanf(l.cutoff);
    cdl_mts_warn_unused(c, n, "emitter \"spot\"");
    return cdl_mts_scene_rc(c, n->line, cdl_scene_add_light(c->s, &l, c->err));
}

/* Mitsuba 3's projector: a perspective camera run backwards; the
 * irradiance (an image or a constant) at distance 1 along its axis, times
 * pi scale (Mitsuba's normalization: a white diffuse plane at distance 1
 * then has radiance irradiance * scale). */
static int projector(cdl_mts_ctx *c, cdl_xml_node *n, const cdl_mat4 *m)
{
    double scale, fov;
    char axis[32], fl[32];
    cdl_light l;
    cdl_vec3 E;
    int rc;
    memset(&l, 0, sizeof l);
    l.type = CDL_LIGHT_PROJECTOR;
    if ((rc = cdl_mts_color_prop(c, n, "irradiance", cdl_v3(1, 1, 1), &E, &l.tex_id)) ||
        (rc = check_emission(c, n->line, "projector irradiance", E)) ||
        (rc = cdl_mts_float(c, n, "scale", 1.0, &scale)) || (rc = cdl_mts_float(c, n, "fov", 0.0, &fov)) ||
        (rc = cdl_mts_string(c, n, "fov_axis", "x", axis, sizeof axis)) ||
        (rc = cdl_mts_string(c, n, "focal_length", "50mm", fl, sizeof fl)))
        return rc;
    if (!cdl_mts_prop(c, n, "irradiance"))
        return cdl_mts_error(c, n->line, "emitter \"projector\" needs an \"irradiance\"");
    if (!(scale >= 0.0 && scale <= 1e12))
        return cdl_mts_error(c, n->line, "projector scale %g must be in [0, 1e12]", scale);
    /* the image's aspect is the texture's (a constant: square) */
    double aspect = 1.0;
    if (l.tex_id >= 0)
        aspect = (double)c->s->texs[l.tex_id].w / (double)c->s->texs[l.tex_id].h;
    if (!cdl_mts_prop(c, n, "fov")) {
        double f = strtod(fl, NULL);
        if (!(f > 0.0 && f < 1e6))
            return cdl_mts_error(c, n->line, "focal_length \"%s\" must be a positive length in mm", fl);
        fov = 2.0 * atan(sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * f)) * 180.0 / CDL_PI;
        snprintf(axis, sizeof axis, "diagonal");
    }
    if (!(fov > 0.0 && fov < 180.0))
        return cdl_mts_error(c, n->line, "projector fov %g must be in (0, 180) degrees", fov);
    double along;
    if (!strcmp(axis, "x"))
        along = aspect;
    else if (!strcmp(axis, "y"))
        along = 1.0;
    else if (!strcmp(axis, "diagonal"))
        along = sqrt(1.0 + aspect * aspect);
    else if (!strcmp(axis, "smaller"))
        along = aspect < 1.0 ? aspect : 1.0;
    else if (!strcmp(axis, "larger"))
        along = aspect > 1.0 ? aspect : 1.0;
    else
        return cdl_mts_error(c, n->line, "fov_axis \"%s\" must be x, y, diagonal, smaller or larger", axis);
    if ((rc = light_frame(c, n, m, &l)))
        return rc;
    double tx = tan(fov * CDL_PI / 360.0) * aspect / along;
    l.tan_x = (float)tx;
    l.tan_y = (float)(tx / aspect);
    l.L = cdl_scale(E, (float)(CDL_PI * scale));
    cdl_mts_warn_unused(c, n, "emitter \"projector\"");
    return cdl_mts_scene_rc(c, n->line, cdl_scene_add_light(c->s, &l, c->err));
}

int cdl_mts_emitter(cdl_mts_ctx *c, cdl_xml_node *n)
{
    char type[64];
    int rc = cdl_mts_type(c, n, type, sizeof type), found;
    if (rc)
        return rc;
    n->used = 1;
    cdl_mat4 m;
    cdl_vec3 v, p, d;
    if ((rc = cdl_mts_transform(c, n, "to_world", &m)))
        return rc;
    cdl_mts_prop(c, n, "sampling_weight");
    if (!strcmp(type, "area")) {
        if (!cdl_xml_attr_get(n, "id"))
            return cdl_mts_error(c, n->line, "emitter \"area\" must be inside a <shape> or have an id that "
                                             "shapes refer to");
        for (int k = 0; k < n->nkids; k++) /* read where a shape refers to it */
            n->kids[k].used = 1;
        return 0;
    }
    if (!strcmp(type, "point")) {
        if ((rc = cdl_mts_color_prop(c, n, "intensity", cdl_v3(1, 1, 1), &v, NULL)) ||
            (rc = check_emission(c, n->line, "point intensity", v)) ||
            (rc = cdl_mts_vec(c, n, "position", cdl_mat4_point3(&m, cdl_v3(0, 0, 0)), &p, NULL)))
            return rc;
        cdl_mts_warn_unused(c, n, "emitter \"point\"");
        return cdl_mts_scene_rc(c, n->line, cdl_scene_add_point_light(c->s, p, v, c->err));
    }
    if (!strcmp(type, "spot"))
        return spot(c, n, &m);
    if (!strcmp(type, "projector"))
        return projector(c, n, &m);
    if (!strcmp(type, "directional")) {
        if ((rc = cdl_mts_color_prop(c, n, "irradiance", cdl_v3(1, 1, 1), &v, NULL)) ||
            (rc = check_emission(c, n->line, "directional irradiance", v)) ||
            (rc = cdl_mts_vec(c, n, "direction", cdl_mat4_vector3(&m, cdl_v3(0, 0, 1)), &d, &found)))
            return rc;
        if (!(cdl_length(d) > 0.0f))
            return cdl_mts_error(c, n->line, "directional: the direction is zero");
        cdl_mts_warn_unused(c, n, "emitter \"directional\"");
        return cdl_mts_scene_rc(c, n->line, cdl_scene_add_distant_light(c->s, d, v, c->err));
    }
    if (!strcmp(type, "constant")) {
        if ((rc = cdl_mts_color_prop(c, n, "radiance", cdl_v3(1, 1, 1), &v, NULL)) ||
            (rc = check_emission(c, n->line, "constant radiance", v)))
            return rc;
        cdl_mts_warn_unused(c, n, "emitter \"constant\"");
        return cdl_mts_scene_rc(c, n->line, cdl_scene_add_infinite_light(c->s, v, c->err));
    }
    if (!strcmp(type, "envmap")) {
        if ((rc = envmap(c, n, &m)))
            return rc;
        cdl_mts_warn_unused(c, n, "emitter \"envmap\"");
        return 0;
    }
    if (!strcmp(type, "sunsky") || !strcmp(type, "sky") || !strcmp(type, "sun")) {
        if ((rc = cdl_mts_sunsky(c, n, type, &m)))
            return rc;
        char what[80];
        snprintf(what, sizeof what, "emitter \"%s\"", type);
        cdl_mts_warn_unused(c, n, what);
        return 0;
    }
    cdl_mts_warn(c, n->line, "emitter \"%s\" is not supported (ignored)", type);
    for (int k = 0; k < n->nkids; k++)
        n->kids[k].used = 1;
    return 0;
}
