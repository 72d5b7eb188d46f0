/* The daylight model (scene/sunsky.c): the PSA sun position against a
 * published one, the sky's symmetry about the sun's vertical plane and its
 * peak at the sun, the sun disk's extent and power in the image, and the
 * image's power at several resolutions. */
#include <math.h>
#include <stdlib.h>

#include "scene/envmap.h"
#include "scene/sunsky.h"
#include "test_util.h"

#define PI 3.14159265358979323846

static double deg(double r)
{
    return r * 180.0 / PI;
}

static double lum(cdl_vec3 c)
{
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/* Integral of the image over the sphere, per channel. */
static void image_power(const float *rgb, int w, int h, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    for (int y = 0; y < h; y++) {
        double dw = 2.0 * PI / w * (cos(PI * y / h) - cos(PI * (y + 1) / h));
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++)
                out[k] += rgb[3 * ((size_t)y * w + x) + k] * dw;
    }
}

static void test_psa(void)
{
    /* The worked example of Reda and Andreas, "Solar Position Algorithm for
     * Solar Radiation Applications", NREL/TP-560-34302 (2004, rev. 2008),
     * Table A5.1: Golden, Colorado (39.742476 N, 105.1786 W), 17 October
     * 2003, 12:30:30 local time at UTC-7: topocentric elevation without
     * refraction e0 = 39.872046 degrees (zenith 50.127954), azimuth
     * 194.340241 degrees from north through east. PSA has no refraction
     * and claims 0.5 arcminutes (0.0083 degrees) over 1999-2015. */
    cdl_sun_time t = {2003, 10, 17, 12.0, 30.0, 30.0, 39.742476, -105.1786, -7.0};
    double z, a;
    cdl_sun_psa(&t, &z, &a);
    CHECK(fabs(deg(z) - 50.127954) < 0.01, "PSA zenith %.5f degrees, NREL SPA's 50.12795 (within 0.01)", deg(z));
    CHECK(fabs(deg(a) - 194.340241) < 0.01, "PSA azimuth %.5f degrees, NREL SPA's 194.34024 (within 0.01)", deg(a));
    /* Mitsuba's default (Tokyo, 10 July 2010, 15:00 JST): the sun in the
     * west-south-west, high in the sky */
    cdl_sun_time tokyo = {2010, 7, 10, 15.0, 0.0, 0.0, 35.6894, 139.6917, 9.0};
    cdl_sun_psa(&tokyo, &z, &a);
    CHECK(deg(z) > 35.0 && deg(z) < 55.0 && deg(a) > 240.0 && deg(a) < 280.0,
          "Tokyo 2010-07-10 15:00: zenith %.2f, azimuth %.2f degrees (west, afternoon)", deg(z), deg(a));
    /* the frame: azimuth 90 degrees (east) is +x, 180 (south) is +z */
    cdl_vec3 e = cdl_sunsky_dir(0.5 * PI, 0.5 * PI), s = cdl_sunsky_dir(0.5 * PI, PI);
    CHECK(fabsf(e.x - 1.0f) < 1e-6f && fabsf(s.z - 1.0f) < 1e-6f, "toSphere: east (%g %g %g), south (%g %g %g)",
          (double)e.x, (double)e.y, (double)e.z, (double)s.x, (double)s.y, (double)s.z);
    double z2, a2;
    cdl_sunsky_angles(cdl_sunsky_dir(0.7, 4.0), &z2, &a2);
    CHECK(fabs(z2 - 0.7) < 1e-6 && fabs(a2 - 4.0) < 1e-6, "fromSphere inverts toSphere (%.7f, %.7f)", z2, a2);
}

static void test_sky(void)
{
    const double sz = 50.0 * PI / 180.0, sa = 1.3;
    for (int turb = 1; turb <= 10; turb += 3) {
        cdl_sky_model m;
        cdl_sky_init(&m, turb + 0.5 * (turb < 10), cdl_v3(0.1f, 0.3f, 0.6f), sz, sa, 1.0, 0);
        /* mirror images about the sun's vertical plane */
        double worst = 0.0;
        for (int i = 1; i < 18; i++)
            for (int j = 1; j < 36; j++) {
                double th = i * PI / 36.0, d = j * PI / 36.0;
                cdl_vec3 p = cdl_sky_radiance(&m, th, sa + d), q = cdl_sky_radiance(&m, th, sa - d);
                double r = fabs(lum(p) - lum(q)) / fmax(lum(p), 1e-12);
                worst = fmax(worst, r);
            }
        CHECK(worst < 1e-5, "turbidity %.1f: symmetric about the sun's vertical plane (worst %.2g)",
              turb + 0.5 * (turb < 10), worst);
        /* brightest towards the sun: along the sun's almucantar at the sun
         * itself, and over the upper hemisphere in the sun's half of its
         * vertical plane (clear skies peak at the horizon below the sun, as
         * the model's horizon brightening outgrows its aureole) */
        double best = -1.0, bphi = 0.0, bth = 0.0;
        for (int j = 0; j < 3600; j++) {
            double ph = (j + 0.5) * PI / 1800.0, l = lum(cdl_sky_radiance(&m, sz, ph));
            if (l > best) {
                best = l;
                bphi = ph;
            }
        }
        double dphi = fabs(remainder(bphi - sa, 2.0 * PI));
        double away = lum(cdl_sky_radiance(&m, sz, sa + PI));
        CHECK(deg(dphi) < 0.1 && best > 1.5 * away,
              "turbidity %.1f: along the sun's almucantar brightest %.3g at %.2f degrees of azimuth from the sun "
              "(opposite it %.3g)",
              turb + 0.5 * (turb < 10), best, deg(dphi), away);
        best = -1.0;
        for (int i = 0; i < 90; i++)
            for (int j = 0; j < 360; j++) {
                double th = (i + 0.5) * PI / 180.0, ph = sa + (j + 0.5 - 180.0) * PI / 180.0;
                double l = lum(cdl_sky_radiance(&m, th, ph));
                if (l > best) {
                    best = l;
                    bphi = ph;
                    bth = th;
                }
            }
        CHECK(fabs(bphi - sa) < 1e-2, "turbidity %.1f: the hemisphere's brightest %.3g at zenith angle %.1f, %.2f "
              "degrees of azimuth from the sun",
              turb + 0.5 * (turb < 10), best, deg(bth), deg(fabs(bphi - sa)));
    }
    cdl_sky_model m;
    cdl_sky_init(&m, 3.0, cdl_v3(0.2f, 0.2f, 0.2f), sz, sa, 1.0, 0);
    cdl_vec3 zen = cdl_sky_radiance(&m, 0.0, 0.0), below = cdl_sky_radiance(&m, 0.6 * PI, 0.0);
    CHECK(zen.z > zen.x && lum(below) == 0.0, "zenith (%.4g, %.4g, %.4g) blue, nothing below the horizon",
          (double)zen.x, (double)zen.y, (double)zen.z);
    /* the sun outshines the sky by about 1.6e9 cd/m^2 against some 1e4 */
    cdl_vec3 sun = cdl_sun_radiance(sz, 3.0);
    CHECK(lum(sun) / lum(zen) > 5e4 && lum(sun) / lum(zen) < 5e6 && sun.x > sun.z,
          "sun (%.4g, %.4g, %.4g) at 50 degrees, yellowish, %.3g x the zenith sky", (double)sun.x, (double)sun.y,
          (double)sun.z, lum(sun) / lum(zen));
}

static void test_sun_disk(void)
{
    cdl_error err = {0};
    cdl_sunsky_params p;
    cdl_sunsky_params_init(&p);
    p.sky_scale = 0.0;
    p.sun_zenith = 60.0 * PI / 180.0;
    p.sun_azimuth = 2.0;
    const double r0 = 0.5 * CDL_SUN_DIAMETER_DEG * PI / 180.0;
    cdl_vec3 L = cdl_sun_radiance(p.sun_zenith, p.turbidity);
    double want = lum(L) * cdl_sun_solid_angle();
    for (int pass = 0; pass < 2; pass++) {
        p.sun_radius_scale = pass ? 20.0 : 1.0;
        p.width = pass ? 2048 : 512;
        p.height = p.width / 2;
        float *rgb;
        die_on(cdl_sunsky_image(&p, &rgb, &err), &err);
        double pw[3], covered = 0.0, far = 0.0;
        image_power(rgb, p.width, p.height, pw);
        cdl_vec3 sd = cdl_sunsky_sun_dir(&p);
        for (int y = 0; y < p.height; y++)
            for (int x = 0; x < p.width; x++) {
                if (!(rgb[3 * ((size_t)y * p.width + x) + 1] > 0.0f))
                    continue;
                double th0 = PI * y / p.height, th1 = PI * (y + 1) / p.height;
                covered += 2.0 * PI / p.width * (cos(th0) - cos(th1));
                cdl_vec3 c = cdl_sunsky_dir(0.5 * (th0 + th1), (x + 0.5) * 2.0 * PI / p.width);
                far = fmax(far, acos(fmin(1.0, (double)cdl_dot(c, sd))));
            }
        double pl = 0.2126 * pw[0] + 0.7152 * pw[1] + 0.0722 * pw[2];
        CHECK(fabs(pl / want - 1.0) < 0.01, "radius x%g at %dx%d: the disk's power %.5g, the sun's %.5g", p.sun_radius_scale,
              p.width, p.height, pl, want);
        if (pass) {
            double r = r0 * p.sun_radius_scale, disk = 2.0 * PI * (1.0 - cos(r)), texel = PI / p.height;
            CHECK(fabs(covered / disk - 1.0) < 0.05, "radius %.3f degrees: texels covered %.5g sr, the disk %.5g sr",
                  deg(r), covered, disk);
            CHECK(far < r + 0.75 * texel && far > r - 0.75 * texel,
                  "the farthest lit texel centre %.3f degrees from the sun (radius %.3f)", deg(far), deg(r));
        }
        free(rgb);
    }
}

static void test_power(void)
{
    cdl_error err = {0};
    const double zen[2] = {30.0, 84.0};
    for (int k = 0; k < 2; k++) {
        double pw[3][3];
        for (int i = 0; i < 3; i++) {
            int res = 128 << (2 * i);
            cdl_sunsky_params p;
            cdl_sunsky_params_init(&p);
            p.sun_zenith = zen[k] * PI / 180.0;
            p.sun_azimuth = 0.4;
            p.width = res;
            p.height = res / 2;
            float *rgb;
            die_on(cdl_sunsky_image(&p, &rgb, &err), &err);
            image_power(rgb, p.width, p.height, pw[i]);
            free(rgb);
        }
        /* against 2048 x 1024: the sky's texel-centre rule converges */
        for (int i = 0; i < 2; i++) {
            double worst = 0.0, tol = i ? 0.005 : 0.02;
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(pw[i][c] / pw[2][c] - 1.0));
            CHECK(worst < tol, "sun at %g degrees: power (%.5g, %.5g, %.5g) at %dx%d, within %.2g%% of 2048x1024's "
                  "(%.5g, %.5g, %.5g)",
                  zen[k], pw[i][0], pw[i][1], pw[i][2], 128 << (2 * i), 64 << (2 * i), 100.0 * worst, pw[2][0],
                  pw[2][1], pw[2][2]);
        }
    }
}

/* The reader's image (rows at Mitsuba 3's envmap nodes) as candela's
 * environment map in that layout: the same power as the texel-centred one. */
static void test_node_rows(void)
{
    cdl_error err = {0};
    cdl_sunsky_params p;
    cdl_sunsky_params_init(&p);
    p.sun_zenith = 40.0 * PI / 180.0;
    p.sun_azimuth = 1.0;
    double ref[3];
    float *rgb;
    die_on(cdl_sunsky_image(&p, &rgb, &err), &err);
    image_power(rgb, p.width, p.height, ref);
    free(rgb);
    p.node_rows = 1;
    die_on(cdl_sunsky_image(&p, &rgb, &err), &err);
    const cdl_vec3 frame[3] = {cdl_v3(0, 0, -1), cdl_v3(1, 0, 0), cdl_v3(0, 1, 0)};
    cdl_envmap m;
    die_on(cdl_envmap_init(&m, p.width, p.height, rgb, frame, CDL_ENVMAP_MITSUBA, &err), &err);
    double worst = fmax(fabs(m.flux.x / ref[0] - 1.0), fmax(fabs(m.flux.y / ref[1] - 1.0), fabs(m.flux.z / ref[2] - 1.0)));
    CHECK(worst < 0.01, "Mitsuba's envmap layout: flux (%.5g, %.5g, %.5g), the texel-centred image's (%.5g, %.5g, %.5g)",
          (double)m.flux.x, (double)m.flux.y, (double)m.flux.z, ref[0], ref[1], ref[2]);
    /* the sun where the image says, looked up through the map */
    cdl_vec3 s = cdl_sunsky_sun_dir(&p);
    cdl_vec3 at = cdl_envmap_eval(&m, s), away = cdl_envmap_eval(&m, cdl_v3(-s.x, s.y, -s.z));
    CHECK(at.y > 100.0f * away.y, "the sun through the map: %g, the sky opposite it %g", (double)at.y, (double)away.y);
    cdl_envmap_free(&m);
}

int main(void)
{
    test_psa();
    test_sky();
    test_sun_disk();
    test_power();
    test_node_rows();
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
