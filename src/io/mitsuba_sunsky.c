/* Mitsuba's daylight emitters "sunsky", "sky" and "sun" (scene/sunsky.c),
 * rasterized into a lat-long image as Mitsuba 0.6 does and added as the
 * environment light through the reader's lat-long path (as "envmap").
 *
 * Mitsuba 0.6 (a file of version 0.x): the sky's frame is y up with azimuth
 * 0 along -z (toSphere), the parameters are its sky.cpp / sun.cpp /
 * sunsky.cpp ones (resolution, stretch, extend, sunRadiusScale, scale,
 * sunScale, skyScale, albedo 0.2 by default) and a sun below the horizon is
 * an error for the sky. Mitsuba 3 (any other file): its sunsky's frame is z
 * up with azimuth 0 along +x, the sun's size is sun_aperture (degrees), the
 * albedo 0.3 by default, and a sun below the horizon only a warning; its sun
 * disk is Hosek and Wilkie's 2013 solar model with limb darkening, which is
 * approximated here by Mitsuba 0.6's (Preetham's) sun, with a warning.
 *
 * Several of them in one scene (a "sky" and a "sun") are added into one
 * image, committed as the scene's one environment light when the file has
 * been read. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/mitsuba_internal.h"
#include "scene/scene.h"
#include "scene/sunsky.h"

#define PI 3.14159265358979323846
/* Mitsuba 3 has no resolution: its sky is evaluated per direction; this
 * image is fine enough for the sky's smooth gradients */
#define M3_RESOLUTION 1024

/* A property n has, not marked used. */
static cdl_xml_node *peek(cdl_mts_ctx *c, cdl_xml_node *n, const char *name)
{
    cdl_xml_node *p = cdl_mts_prop(c, n, name);
    if (p)
        p->used = 0;
    return p;
}

/* The property's name as the file spells it (sunScale or sun_scale). */
static const char *spelled(const cdl_xml_node *p, const char *name)
{
    const char *s = p ? cdl_xml_attr_get(p, "name") : NULL;
    return s ? s : name;
}

static int ranged(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, double def, double lo, double hi,
                  double *out)
{
    int rc = cdl_mts_float(c, n, name, def, out);
    if (!rc && !(*out >= lo && *out <= hi)) {
        cdl_xml_node *p = peek(c, n, name);
        rc = cdl_mts_error(c, p ? p->line : n->line, "%s %g must be in [%g, %g]", spelled(p, name), *out, lo, hi);
    }
    return rc;
}

static int ranged_int(cdl_mts_ctx *c, cdl_xml_node *n, const char *name, long def, long lo, long hi, long *out)
{
    int rc = cdl_mts_int(c, n, name, def, out);
    if (!rc && !(*out >= lo && *out <= hi)) {
        cdl_xml_node *p = peek(c, n, name);
        rc = cdl_mts_error(c, p ? p->line : n->line, "%s %ld must be in [%ld, %ld]", spelled(p, name), *out, lo, hi);
    }
    return rc;
}

static int days_in_month(long y, long m)
{
    static const int d[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    return m == 2 && leap ? 29 : d[m - 1];
}

static const char *const TIME_PLACE[] = {"latitude", "longitude", "timezone", "year", "month",
                                         "day",      "hour",      "minute",   "second"};

/* The sun's zenith angle and azimuth in the sky's own (Mitsuba 0.6) frame,
 * from sun_direction or the date, time and place. to_local: the world's
 * vectors in the emitter's frame; m3: Mitsuba 3's z-up frame. */
static int sun_position(cdl_mts_ctx *c, cdl_xml_node *n, const cdl_mat4 *to_local, int m3, double *zen,
                        double *az)
{
    int rc, found;
    cdl_vec3 d;
    if ((rc = cdl_mts_vec(c, n, "sun_direction", cdl_v3(0, 1, 0), &d, &found)))
        return rc;
    if (found) {
        for (size_t i = 0; i < sizeof TIME_PLACE / sizeof TIME_PLACE[0]; i++) {
            cdl_xml_node *p = peek(c, n, TIME_PLACE[i]);
            if (!p)
                continue;
            /* Mitsuba 0.6 refuses only these with a direction, and ignores the rest */
            if (m3 || i < 3 || i == 5)
                return cdl_mts_error(c, p->line, "give either sunDirection or the time and place (%s), not both",
                                     TIME_PLACE[i]);
            cdl_mts_warn(c, p->line, "%s ignored: sunDirection gives the sun's position", TIME_PLACE[i]);
            p->used = 1;
        }
        if (peek(c, n, "time"))
            return cdl_mts_error(c, peek(c, n, "time")->line, "give either sunDirection or a time, not both");
        cdl_vec3 l = cdl_mat4_vector3(to_local, d);
        if (!cdl_is_finite3(l) || !(cdl_length(l) > 0.0f))
            return cdl_mts_error(c, n->line, "sunDirection (%g, %g, %g) must be a non-zero vector", (double)d.x,
                                 (double)d.y, (double)d.z);
        l = cdl_normalize(l);
        if (m3) /* z up to the 0.6 frame's y up */
            l = cdl_v3(l.x, l.z, -l.y);
        cdl_sunsky_angles(l, zen, az);
        return 0;
    }
    cdl_sun_time t;
    long year, month, day;
    if ((rc = ranged(c, n, "latitude", 35.6894, -90.0, 90.0, &t.latitude)) ||
        (rc = ranged(c, n, "longitude", 139.6917, -180.0, 360.0, &t.longitude)) ||
        (rc = ranged(c, n, "timezone", 9.0, -14.0, 14.0, &t.timezone)) ||
        (rc = ranged_int(c, n, "year", 2010, 1, 9999, &year)) ||
        (rc = ranged_int(c, n, "month", 7, 1, 12, &month)) ||
        (rc = ranged_int(c, n, "day", 10, 1, 31, &day)) ||
        (rc = ranged(c, n, "hour", 15.0, 0.0, 24.0, &t.hour)) ||
        (rc = ranged(c, n, "minute", 0.0, 0.0, 60.0, &t.minute)) ||
        (rc = ranged(c, n, "second", 0.0, 0.0, 60.0, &t.second)))
        return rc;
    if (day > days_in_month(year, month)) {
        cdl_xml_node *p = peek(c, n, "day");
        return cdl_mts_error(c, p ? p->line : n->line, "day %ld: %04ld-%02ld has %d days", day, year, month,
                             days_in_month(year, month));
    }
    t.year = (int)year;
    t.month = (int)month;
    t.day = (int)day;
    cdl_sun_psa(&t, zen, az);
    if (m3) { /* Mitsuba 3 puts azimuth phi at (cos phi, sin phi) in its z-up frame */
        double st = sin(*zen);
        cdl_vec3 l3 = cdl_v3((float)(cos(*az) * st), (float)(sin(*az) * st), (float)cos(*zen));
        cdl_sunsky_angles(cdl_v3(l3.x, l3.z, -l3.y), zen, az);
    }
    return 0;
}

/* Adds the texels to the image of the daylight emitters read before (one
 * environment light: they must share resolution and frame). */
static int pend(cdl_mts_ctx *c, int line, const char *type, float *rgb, int w, int h, const cdl_vec3 axes[3])
{
    if (!c->sky_rgb) {
        c->sky_rgb = rgb;
        c->sky_w = w;
        c->sky_h = h;
        c->sky_line = line;
        snprintf(c->sky_file, sizeof c->sky_file, "%s", c->file);
        memcpy(c->sky_axes, axes, sizeof c->sky_axes);
        return 0;
    }
    int same = w == c->sky_w && h == c->sky_h;
    for (int k = 0; k < 3; k++)
        same = same && cdl_length(cdl_sub(axes[k], c->sky_axes[k])) < 1e-5f;
    if (!same) {
        free(rgb);
        return cdl_mts_error(c, line,
                             "emitter \"%s\": candela has one environment light, and this one's resolution or "
                             "toWorld differs from the daylight emitter's at line %d",
                             type, c->sky_line);
    }
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++)
        c->sky_rgb[i] += rgb[i];
    free(rgb);
    return 0;
}

int cdl_mts_sky_finish(cdl_mts_ctx *c)
{
    if (!c->sky_rgb)
        return 0;
    const char *outer = c->file;
    c->file = c->sky_file;
    float *rgb = c->sky_rgb;
    c->sky_rgb = NULL;
    int rc = cdl_mts_latlong_light(c, c->sky_line, c->sky_axes, NULL, 1.0f, c->sky_w, c->sky_h, rgb);
    c->file = outer;
    return rc;
}

int cdl_mts_sunsky(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, const cdl_mat4 *to_world)
{
    const int m3 = !c->legacy, is_sky = strcmp(type, "sun") != 0, is_sun = strcmp(type, "sky") != 0;
    int rc;
    cdl_mat4 to_local;
    if (!cdl_mat4_is_finite(to_world) || cdl_mat4_inverse(to_world, &to_local))
        return cdl_mts_error(c, n->line, "emitter \"%s\": to_world is singular", type);
    cdl_sunsky_params p;
    cdl_sunsky_params_init(&p);
    double scale, turb, rscale = 1.0, stretch = 1.0;
    if ((rc = cdl_mts_float(c, n, "scale", 1.0, &scale)) || (rc = ranged(c, n, "turbidity", 3.0, 1.0, 10.0, &turb)))
        return rc;
    if (!(scale >= 0.0 && scale <= 1e12))
        return cdl_mts_error(c, n->line, "scale %g must be in [0, 1e12]", scale);
    p.turbidity = turb;
    p.sky_scale = is_sky ? scale : 0.0;
    p.sun_scale = is_sun ? scale : 0.0;
    if (!strcmp(type, "sunsky") && ((rc = ranged(c, n, "sky_scale", scale, 0.0, 1e12, &p.sky_scale)) ||
                                    (rc = ranged(c, n, "sun_scale", scale, 0.0, 1e12, &p.sun_scale))))
        return rc;
    if (is_sky) {
        cdl_xml_node *a = cdl_mts_prop(c, n, "albedo");
        p.albedo = m3 ? cdl_v3(0.3f, 0.3f, 0.3f) : cdl_v3(0.2f, 0.2f, 0.2f);
        if (a && (rc = cdl_mts_color_node(c, a, &p.albedo)))
            return rc;
        cdl_vec3 v = p.albedo;
        if (!cdl_is_finite3(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f || v.x > 1.0f || v.y > 1.0f || v.z > 1.0f)
            return cdl_mts_error(c, a ? a->line : n->line, "albedo (%g, %g, %g) must be in [0, 1]", (double)v.x,
                                 (double)v.y, (double)v.z);
    } else {
        cdl_mts_prop(c, n, "albedo"); /* Mitsuba's sun reads none */
    }
    int res = m3 ? M3_RESOLUTION : 512;
    if (m3) {
        double ap;
        if ((rc = cdl_mts_float(c, n, "sun_aperture", CDL_SUN_DIAMETER_DEG, &ap)))
            return rc;
        if (!(ap > 0.0 && ap < 180.0))
            return cdl_mts_error(c, n->line, "sun_aperture %g must be in (0, 180) degrees", ap);
        rscale = ap / CDL_SUN_DIAMETER_DEG; /* Mitsuba 3 keeps the sun's power too */
        if (is_sun && p.sun_scale > 0.0)
            cdl_mts_warn(c, n->line, "emitter \"%s\": Mitsuba 3's solar radiance model (Hosek and Wilkie 2013, "
                                     "with limb darkening) is approximated by Mitsuba 0.6's sun",
                         type);
    } else {
        long r;
        int ext;
        if ((rc = ranged_int(c, n, "resolution", 512, 8, 16384, &r)) ||
            (rc = ranged(c, n, "stretch", 1.0, 1.0, 2.0, &stretch)) || (rc = cdl_mts_bool(c, n, "extend", 0, &ext)))
            return rc;
        if (is_sun && (rc = ranged(c, n, "sun_radius_scale", 1.0, 0.0, 100.0, &rscale)))
            return rc;
        res = (int)r;
        p.extend = is_sky && ext;
    }
    p.stretch = stretch;
    p.node_rows = 1; /* cdl_mts_latlong_light's layout: Mitsuba 3's envmap nodes */
    p.width = res;
    p.height = res / 2;
    if ((rc = sun_position(c, n, &to_local, m3, &p.sun_zenith, &p.sun_azimuth)))
        return rc;
    if (p.sun_zenith > 0.5 * PI) {
        double el = 90.0 - p.sun_zenith * 180.0 / PI;
        if (m3) {
            cdl_mts_warn(c, n->line, "emitter \"%s\": the sun is below the horizon (elevation %.2f degrees)", type, el);
            p.sun_above_only = 1;
        } else if (is_sky) {
            return cdl_mts_error(c, n->line,
                                 "emitter \"%s\": the sun is below the horizon (elevation %.2f degrees), which the "
                                 "sky model does not support",
                                 type, el);
        }
    }
    p.sun_radius_scale = rscale;
    /* the map's frame: world images of the sky frame's x, y (up) and z */
    cdl_vec3 axes[3];
    if (m3) { /* Mitsuba 3's local (x, y, z) is the 0.6 frame's (x, -z, y) */
        axes[0] = cdl_mat4_vector3(to_world, cdl_v3(1, 0, 0));
        axes[1] = cdl_mat4_vector3(to_world, cdl_v3(0, 0, 1));
        axes[2] = cdl_scale(cdl_mat4_vector3(to_world, cdl_v3(0, 1, 0)), -1.0f);
    } else {
        axes[0] = cdl_mat4_vector3(to_world, cdl_v3(1, 0, 0));
        axes[1] = cdl_mat4_vector3(to_world, cdl_v3(0, 1, 0));
        axes[2] = cdl_mat4_vector3(to_world, cdl_v3(0, 0, 1));
    }
    /* a sun of radius 0 is a distant light of the disk's irradiance (Mitsuba 0.6's sunsky) */
    if (is_sun && rscale == 0.0 && p.sun_scale > 0.0) {
        cdl_vec3 L = cdl_sun_radiance(p.sun_zenith, p.turbidity);
        float e = (float)(cdl_sun_solid_angle() * p.sun_scale);
        cdl_vec3 s = cdl_sunsky_sun_dir(&p);
        cdl_vec3 d = cdl_add(cdl_add(cdl_scale(axes[0], s.x), cdl_scale(axes[1], s.y)), cdl_scale(axes[2], s.z));
        if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_add_distant_light(c->s, cdl_scale(d, -1.0f),
                                                                          cdl_scale(L, e), c->err))))
            return rc;
        p.sun_scale = 0.0;
        if (!is_sky)
            return 0;
    }
    float *rgb;
    if ((rc = cdl_mts_scene_rc(c, n->line, cdl_sunsky_image(&p, &rgb, c->err))))
        return rc;
    return pend(c, n->line, type, rgb, p.width, p.height, axes);
}
