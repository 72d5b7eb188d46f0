/* pbrt light sources: LightSource point / spot / distant / infinite, and
 * AreaLightSource "diffuse", which sets the emission of the shapes that
 * follow in the same attribute block (pbrt_shapes.c attaches it). */
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

static int check_color(cdl_pbrt_ctx *c, const char *what, cdl_vec3 v)
{
    if (!cdl_is_finite3(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)
        return cdl_pbrt_error(c, c->line, "%s (%g, %g, %g) must be finite and >= 0", what, (double)v.x,
                              (double)v.y, (double)v.z);
    return 0;
}

int cdl_pbrt_area_light(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_params *ps = &c->ps;
    cdl_vec3 L, sc;
    int two, rc;
    if (strcmp(type, "diffuse")) {
        cdl_pbrt_warn(c, c->line, "AreaLightSource \"%s\" is not supported: its shapes do not emit", type);
        for (size_t i = 0; i < ps->n; i++)
            ps->p[i].used = 1;
        c->gs.area = 0;
        return 0;
    }
    if ((rc = cdl_pbrt_get_spectrum(ps, "L", cdl_v3(1, 1, 1), &L, NULL, c->err)) ||
        (rc = cdl_pbrt_get_scale(ps, "scale", &sc, c->err)) ||
        (rc = cdl_pbrt_get_bool(ps, "twosided", 0, &two, c->err)))
        return rc;
    if (cdl_pbrt_find(ps, "power"))
        cdl_pbrt_warn(c, c->line, "AreaLightSource \"power\" ignored: L and scale are used as given");
    if (cdl_pbrt_find(ps, "filename"))
        cdl_pbrt_warn(c, c->line, "AreaLightSource image \"filename\" ignored: constant L is used");
    cdl_pbrt_find(ps, "nsamples");
    cdl_pbrt_find(ps, "samples");
    L = cdl_mul(L, sc);
    if ((rc = check_color(c, "AreaLightSource L", L)))
        return rc;
    c->gs.area = 1;
    c->gs.area_L = L;
    c->gs.area_twosided = two;
    return 0;
}

int cdl_pbrt_light(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_params *ps = &c->ps;
    cdl_error *err = c->err;
    static const double o[3] = {0, 0, 0}, z[3] = {0, 0, 1};
    double from[3], to[3];
    cdl_vec3 v, sc;
    int rc, delta = !strcmp(type, "point") || !strcmp(type, "spot");
    int is_distant = !strcmp(type, "distant"), is_inf = !strcmp(type, "infinite");
    if (!delta && !is_distant && !is_inf) {
        cdl_pbrt_warn(c, c->line, "LightSource \"%s\" is not supported (skipped)", type);
        for (size_t i = 0; i < ps->n; i++)
            ps->p[i].used = 1;
        return 0;
    }
    if ((rc = cdl_pbrt_get_spectrum(ps, delta ? "I" : "L", cdl_v3(1, 1, 1), &v, NULL, err)) ||
        (rc = cdl_pbrt_get_scale(ps, "scale", &sc, err)) ||
        (rc = cdl_pbrt_get_point3(ps, "from", o, from, err)) ||
        (rc = cdl_pbrt_get_point3(ps, "to", z, to, err)))
        return rc;
    v = cdl_mul(v, sc);
    if ((rc = check_color(c, delta ? "LightSource I" : "LightSource L", v)))
        return rc;
    if (cdl_pbrt_find(ps, "power") || cdl_pbrt_find(ps, "illuminance"))
        cdl_pbrt_warn(c, c->line, "LightSource power / illuminance ignored: the intensity is used as given");
    const cdl_mat4 *m = &c->gs.ctm;
    double dir[3] = {to[0] - from[0], to[1] - from[1], to[2] - from[2]}, wd[3], wp[3];
    cdl_mat4_vector(m, dir, wd);
    /* pbrt-v4 places the light at CTM(from); pbrt-v3's point light adds
     * 'from' after the transform, which differs only under rotation/scale */
    cdl_mat4_point(m, from, wp);
    cdl_vec3 P = cdl_v3((float)wp[0], (float)wp[1], (float)wp[2]);
    cdl_vec3 D = cdl_v3((float)wd[0], (float)wd[1], (float)wd[2]);
    if (!strcmp(type, "point")) {
        cdl_pbrt_find(ps, "to");
        return cdl_pbrt_scene_rc(c, cdl_scene_add_point_light(c->s, P, v, err));
    }
    if (is_inf) {
        const char *map, *v4map;
        if ((rc = cdl_pbrt_get_string(ps, "mapname", NULL, &map, err)) ||
            (rc = cdl_pbrt_get_string(ps, "filename", NULL, &v4map, err)))
            return rc;
        cdl_pbrt_find(ps, "samples");
        cdl_pbrt_find(ps, "nsamples");
        if (map && v4map)
            return cdl_pbrt_error(c, c->line, "infinite light: give \"mapname\" (pbrt-v3) or \"filename\" (pbrt-v4), "
                                              "not both");
        int equal_area = !map && v4map;
        if (equal_area)
            map = v4map;
        if (!map)
            return cdl_pbrt_scene_rc(c, cdl_scene_add_infinite_light(c->s, v, err));
        /* in the light's frame (the CTM), scaled by L and scale: pbrt-v3's
         * mapname equirectangular, pbrt-v4's filename equal-area */
        char path[1024];
        cdl_pbrt_resolve(c, map, path, sizeof path);
        cdl_vec3 frame[3];
        for (int k = 0; k < 3; k++) {
            double axis[3] = {k == 0, k == 1, k == 2}, w[3];
            cdl_mat4_vector(m, axis, w);
            frame[k] = cdl_v3((float)w[0], (float)w[1], (float)w[2]);
        }
        cdl_envmap *em = malloc(sizeof *em);
        if (!em)
            return cdl_pbrt_error(c, c->line, "out of memory");
        int layout = equal_area ? CDL_ENVMAP_EQUAL_AREA : CDL_ENVMAP_EQUIRECT;
        if ((rc = cdl_envmap_load(em, path, v, frame, layout, err))) {
            free(em);
            return rc;
        }
        return cdl_pbrt_scene_rc(c, cdl_scene_add_env_light(c->s, cdl_v3(1, 1, 1), em, err));
    }
    if (!(cdl_length(D) > 0.0f) || !cdl_is_finite3(D))
        return cdl_pbrt_error(c, c->line, "LightSource \"%s\": 'from' and 'to' must differ", type);
    if (is_distant) /* the light travels from 'from' towards 'to' */
        return cdl_pbrt_scene_rc(c, cdl_scene_add_distant_light(c->s, D, v, err));
    double cone, cdelta;
    if ((rc = cdl_pbrt_get_float(ps, "coneangle", 30.0, &cone, err)) ||
        (rc = cdl_pbrt_get_float(ps, "conedeltaangle", 5.0, &cdelta, err)))
        return rc;
    if (!(cone > 0.0 && cone <= 180.0))
        return cdl_pbrt_error(c, c->line, "spot coneangle %g must be in (0, 180] degrees", cone);
    if (!(cdelta >= 0.0))
        return cdl_pbrt_error(c, c->line, "spot conedeltaangle %g must not be negative", cdelta);
    if (cdelta > cone) { /* pbrt renders it: the falloff then starts at the axis */
        cdl_pbrt_warn(c, c->line, "spot conedeltaangle %g exceeds coneangle %g: clamped to it", cdelta, cone);
        cdelta = cone;
    }
    return cdl_pbrt_scene_rc(c, cdl_scene_add_spot_light(c->s, P, D, v, (float)cone, (float)cdelta, err));
}
