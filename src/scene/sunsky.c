#include "scene/sunsky.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "core/spectrum.h"
#include "scene/sunsky_data.h"

#define PI 3.14159265358979323846

static double deg(double r)
{
    return r * (180.0 / PI);
}

static double rad(double d)
{
    return d * (PI / 180.0);
}

void cdl_sun_psa(const cdl_sun_time *t, double *zenith, double *azimuth)
{
    /* days since JD 2451545.0 (noon UT, 1 January 2000); the integer
     * divisions are the algorithm's (they truncate) */
    double hours = t->hour - t->timezone + (t->minute + t->second / 60.0) / 60.0;
    int a1 = (t->month - 14) / 12;
    int jdn = (1461 * (t->year + 4800 + a1)) / 4 + (367 * (t->month - 2 - 12 * a1)) / 12 -
              (3 * ((t->year + 4900 + a1) / 100)) / 4 + t->day - 32075;
    double n = (double)jdn - 0.5 + hours / 24.0 - 2451545.0;

    /* ecliptic longitude and obliquity (radians, not reduced) */
    double omega = 2.1429 - 0.0010394594 * n;
    double mean_long = 4.8950630 + 0.017202791698 * n;
    double anomaly = 6.2400600 + 0.0172019699 * n;
    double ecl_long = mean_long + 0.03341607 * sin(anomaly) + 0.00034894 * sin(2.0 * anomaly) - 0.0001134 -
                      0.0000203 * sin(omega);
    double ecl_obl = 0.4090928 - 6.2140e-9 * n + 0.0000396 * cos(omega);

    /* right ascension and declination */
    double sl = sin(ecl_long);
    double ra = atan2(cos(ecl_obl) * sl, cos(ecl_long));
    if (ra < 0.0)
        ra += 2.0 * PI;
    double decl = asin(sin(ecl_obl) * sl);

    /* local coordinates */
    double gmst = 6.6974243242 + 0.0657098283 * n + hours;
    double lmst = rad(gmst * 15.0 + t->longitude);
    double lat = rad(t->latitude);
    double h = lmst - ra;
    double z = acos(cos(lat) * cos(h) * cos(decl) + sin(decl) * sin(lat));
    double az = atan2(-sin(h), tan(decl) * cos(lat) - sin(lat) * cos(h));
    if (az < 0.0)
        az += 2.0 * PI;
    /* parallax: the earth's mean radius over the astronomical unit (km) */
    z += (6371.01 / 149597890.0) * sin(z);
    *zenith = z;
    *azimuth = az;
}

cdl_vec3 cdl_sunsky_dir(double zenith, double azimuth)
{
    double st = sin(zenith);
    return cdl_v3((float)(sin(azimuth) * st), (float)cos(zenith), (float)(-cos(azimuth) * st));
}

void cdl_sunsky_angles(cdl_vec3 d, double *zenith, double *azimuth)
{
    double az = atan2((double)d.x, -(double)d.z);
    if (az < 0.0)
        az += 2.0 * PI;
    double y = d.y < -1.0f ? -1.0 : d.y > 1.0f ? 1.0 : (double)d.y;
    *zenith = acos(y);
    *azimuth = az;
}

/* ---- the sun (Preetham et al., after Iqbal) ---- */

static double tab_eval(const cdl_tab_spectrum *s, double l)
{
    if (l < s->lambda[0] || l > s->lambda[s->n - 1])
        return 0.0;
    for (int i = 1; i < s->n; i++)
        if (l <= s->lambda[i]) {
            double t = (l - s->lambda[i - 1]) / (s->lambda[i] - s->lambda[i - 1]);
            return s->value[i - 1] + t * (s->value[i] - s->value[i - 1]);
        }
    return s->value[s->n - 1];
}

/* The CIE 1931 observer at l nm, linear between its 10 nm samples. */
static void cie(double l, double xyz[3])
{
    double f = (l - 380.0) / 10.0;
    if (f < 0.0 || f > CDL_CIE_N - 1) {
        xyz[0] = xyz[1] = xyz[2] = 0.0;
        return;
    }
    int i = (int)f;
    if (i > CDL_CIE_N - 2)
        i = CDL_CIE_N - 2;
    double t = f - i;
    for (int k = 0; k < 3; k++)
        xyz[k] = (1.0 - t) * cdl_cie_xyz[i][k] + t * cdl_cie_xyz[i + 1][k];
}

cdl_vec3 cdl_sun_radiance(double zenith, double turbidity)
{
    double beta = 0.04608365822050 * turbidity - 0.04586025928522;
    /* relative optical mass (Kasten's air mass); none past 93.885 degrees */
    double zd = 93.885 - deg(zenith);
    if (!(zd > 0.0))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    double m = 1.0 / (cos(zenith) + 0.15 * pow(zd, -1.253));
    if (!(m > 0.0) || !isfinite(m))
        return cdl_v3(0.0f, 0.0f, 0.0f);
    /* the attenuated spectrum at 350, 355, ..., 800 nm */
    double spec[91];
    for (int i = 0; i < 91; i++) {
        double l = 350.0 + 5.0 * i, um = l / 1000.0;
        double tau_r = exp(-m * 0.008735 * pow(um, -4.08));      /* Rayleigh scattering */
        double tau_a = exp(-m * beta * pow(um, -1.3));           /* aerosols, alpha 1.3 */
        double tau_o = exp(-m * tab_eval(&cdl_sun_k_o, l) * 0.35); /* ozone, 0.35 cm */
        double kg = tab_eval(&cdl_sun_k_g, l), kwa = tab_eval(&cdl_sun_k_wa, l);
        double tau_g = exp(-1.41 * kg * m / pow(1.0 + 118.93 * kg * m, 0.45));             /* mixed gases */
        double tau_wa = exp(-0.2385 * kwa * 2.0 * m / pow(1.0 + 20.07 * kwa * 2.0 * m, 0.45)); /* 2 cm of water */
        spec[i] = tab_eval(&cdl_sun_solar, l) * tau_r * tau_a * tau_o * tau_g * tau_wa;
    }
    /* to XYZ over the observer, normalized by the integral of y-bar (Mitsuba
     * 0.6's Spectrum::fromContinuousSpectrum), in 1 nm steps */
    double xyz[3] = {0, 0, 0}, ybar = 0.0;
    for (int l = 360; l <= 830; l++) {
        double c[3], s = 0.0;
        cie((double)l, c);
        if (l >= 350 && l <= 800) {
            int i = (l - 350) / 5;
            double t = (l - 350 - 5 * i) / 5.0;
            s = i >= 90 ? spec[90] : (1.0 - t) * spec[i] + t * spec[i + 1];
        }
        for (int k = 0; k < 3; k++)
            xyz[k] += c[k] * s;
        ybar += c[1];
    }
    cdl_vec3 rgb = cdl_xyz_to_srgb(xyz[0] / ybar, xyz[1] / ybar, xyz[2] / ybar);
    return cdl_v3(fmaxf(rgb.x, 0.0f), fmaxf(rgb.y, 0.0f), fmaxf(rgb.z, 0.0f));
}

double cdl_sun_solid_angle(void)
{
    return 2.0 * PI * (1.0 - cos(rad(0.5 * CDL_SUN_DIAMETER_DEG)));
}

/* ---- the sky (Hosek and Wilkie 2012) ---- */

/* The quintic Bezier of one (albedo, turbidity) block at x = cbrt(solar
 * elevation / (pi / 2)): 6 control points, stride values apart. */
static double bezier(const double *p, int stride, double x)
{
    static const double c[6] = {1, 5, 10, 10, 5, 1};
    double r = 0.0;
    for (int k = 0; k < 6; k++)
        r += c[k] * pow(x, k) * pow(1.0 - x, 5 - k) * p[k * stride];
    return r;
}

void cdl_sky_init(cdl_sky_model *m, double turbidity, cdl_vec3 albedo, double sun_zenith, double sun_azimuth,
                  double stretch, int extend)
{
    m->sun_zenith = sun_zenith;
    m->sun_azimuth = sun_azimuth;
    m->stretch = stretch;
    m->extend = extend;
    double elev = 0.5 * PI - sun_zenith;
    if (elev < 0.0)
        elev = 0.0;
    double x = pow(elev / (0.5 * PI), 1.0 / 3.0);
    int ti = (int)turbidity;
    if (ti < 1)
        ti = 1;
    if (ti > 10)
        ti = 10;
    double tr = turbidity - ti;
    const float alb[3] = {albedo.x, albedo.y, albedo.z};
    for (int ch = 0; ch < 3; ch++) {
        double a = alb[ch];
        /* (albedo, turbidity) weights of the blocks: albedo 0 and 1 at the
         * turbidity below and (unless it is 10) above */
        const int nb = ti == 10 ? 2 : 4;
        const int blk_a[4] = {0, 1, 0, 1}, blk_t[4] = {ti - 1, ti - 1, ti, ti};
        const double w[4] = {(1.0 - a) * (1.0 - tr), a * (1.0 - tr), (1.0 - a) * tr, a * tr};
        for (int i = 0; i < 9; i++)
            m->config[ch][i] = 0.0;
        m->radiance[ch] = 0.0;
        for (int b = 0; b < nb; b++) {
            const double *cfg = cdl_hosek_rgb[ch] + 540 * blk_a[b] + 54 * blk_t[b];
            for (int i = 0; i < 9; i++)
                m->config[ch][i] += w[b] * bezier(cfg + i, 9, x);
            m->radiance[ch] += w[b] * bezier(cdl_hosek_rgb_rad[ch] + 60 * blk_a[b] + 6 * blk_t[b], 1, x);
        }
    }
}

/* The model's radiance function (eq. 9 of Hosek and Wilkie). */
static double hosek(const double *c, double theta, double gamma)
{
    double cg = cos(gamma), ct = cos(theta);
    double exp_m = exp(c[4] * gamma), ray_m = cg * cg;
    double mie_m = (1.0 + cg * cg) / pow(1.0 + c[8] * c[8] - 2.0 * c[8] * cg, 1.5);
    double zenith = sqrt(ct);
    return (1.0 + c[0] * exp(c[1] / (ct + 0.01))) *
           (c[2] + c[3] * exp_m + c[5] * ray_m + c[6] * mie_m + c[7] * zenith);
}

static double smooth_step(double a, double b, double v)
{
    double t = (v - a) / (b - a);
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    return t * t * (3.0 - 2.0 * t);
}

cdl_vec3 cdl_sky_radiance(const cdl_sky_model *m, double theta0, double phi)
{
    double theta = theta0 / m->stretch;
    if (cos(theta) <= 0.0) {
        if (!m->extend)
            return cdl_v3(0.0f, 0.0f, 0.0f);
        theta = 0.5 * PI - 1e-4; /* Mitsuba's "super-unrealistic mode" */
    }
    double cg = cos(theta) * cos(m->sun_zenith) + sin(theta) * sin(m->sun_zenith) * cos(phi - m->sun_azimuth);
    double gamma = acos(cg < -1.0 ? -1.0 : cg > 1.0 ? 1.0 : cg);
    double v[3];
    for (int ch = 0; ch < 3; ch++) {
        /* over the sum of the CIE y-bar samples: Mitsuba's RGB sky */
        v[ch] = hosek(m->config[ch], theta, gamma) * m->radiance[ch] / 106.856980;
        if (!(v[ch] > 0.0))
            v[ch] = 0.0;
    }
    double f = m->extend ? smooth_step(0.0, 1.0, 2.0 - 2.0 * theta0 / PI) : 1.0;
    return cdl_v3((float)(v[0] * f), (float)(v[1] * f), (float)(v[2] * f));
}

/* ---- the image ---- */

void cdl_sunsky_params_init(cdl_sunsky_params *p)
{
    p->turbidity = 3.0;
    p->albedo = cdl_v3(0.2f, 0.2f, 0.2f);
    p->sun_zenith = 0.25 * PI;
    p->sun_azimuth = 0.0;
    p->stretch = 1.0;
    p->extend = 0;
    p->sky_scale = 1.0;
    p->sun_scale = 1.0;
    p->sun_radius_scale = 1.0;
    p->sun_above_only = 0;
    p->width = 512;
    p->height = 256;
    p->node_rows = 0;
}

cdl_vec3 cdl_sunsky_sun_dir(const cdl_sunsky_params *p)
{
    return cdl_sunsky_dir(p->sun_zenith * p->stretch, p->sun_azimuth);
}

/* The (0, 2)-sequence Mitsuba's sample02 draws from: the base-2 radical
 * inverse and the second Sobol dimension. */
static void sample02(uint32_t i, double *u, double *v)
{
    uint32_t r = i;
    r = (r << 16) | (r >> 16);
    r = ((r & 0x00ff00ffu) << 8) | ((r & 0xff00ff00u) >> 8);
    r = ((r & 0x0f0f0f0fu) << 4) | ((r & 0xf0f0f0f0u) >> 4);
    r = ((r & 0x33333333u) << 2) | ((r & 0xccccccccu) >> 2);
    r = ((r & 0x55555555u) << 1) | ((r & 0xaaaaaaaau) >> 1);
    uint32_t s = 0;
    for (uint32_t b = 1u << 31, n = i; n; n >>= 1, b ^= b >> 1)
        if (n & 1u)
            s ^= b;
    *u = r * (1.0 / 4294967296.0);
    *v = s * (1.0 / 4294967296.0);
}

int cdl_sunsky_image(const cdl_sunsky_params *p, float **out, cdl_error *err)
{
    int w = p->width, h = p->height;
    *out = NULL;
    if (w < 2 || h < 2)
        return cdl_error_set(err, CDL_ERR_INPUT, "", 0, "a %dx%d sky image is too small", w, h);
    float *rgb = calloc((size_t)w * (size_t)h * 3, sizeof(float));
    if (!rgb)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a %dx%d sky image", w, h);
    if (p->sky_scale > 0.0) {
        cdl_sky_model sky;
        cdl_sky_init(&sky, p->turbidity, p->albedo, p->sun_zenith, p->sun_azimuth, p->stretch, p->extend);
        for (int y = 0; y < h; y++) {
            double theta = p->node_rows ? y * PI / (h - 1) : (y + 0.5) * PI / h;
            for (int x = 0; x < w; x++) {
                cdl_vec3 L = cdl_sky_radiance(&sky, theta, (x + 0.5) * 2.0 * PI / w);
                float *t = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
                t[0] = (float)(L.x * p->sky_scale);
                t[1] = (float)(L.y * p->sky_scale);
                t[2] = (float)(L.z * p->sky_scale);
            }
        }
    }
    if (p->sun_scale > 0.0 && p->sun_radius_scale > 0.0) {
        cdl_vec3 L = cdl_sun_radiance(p->sun_zenith, p->turbidity);
        /* a cone of directions about the sun: its power is the unscaled
         * disk's, whatever its radius */
        double cos_max = cos(rad(0.5 * CDL_SUN_DIAMETER_DEG) * p->sun_radius_scale);
        double covered = 0.5 * (1.0 - cos_max);
        size_t n = (size_t)fmax(100.0, (double)w * (double)h * covered * 1000.0);
        if (n > 1u << 24)
            n = 1u << 24;
        /* a texel's (or node's) solid angle is 2 pi^2 / (w rows) sin(theta) */
        const double rows = p->node_rows ? h - 1 : h;
        double k = cdl_sun_solid_angle() * p->sun_scale * w * rows / (2.0 * PI * PI * (double)n);
        cdl_frame fr = cdl_frame_from(cdl_sunsky_sun_dir(p));
        for (size_t i = 0; i < n; i++) {
            double u, v;
            sample02((uint32_t)i, &u, &v);
            double ct = (1.0 - u) + u * cos_max, st = sqrt(fmax(0.0, 1.0 - ct * ct));
            double cp = cos(2.0 * PI * v), sp = sin(2.0 * PI * v);
            cdl_vec3 d = cdl_to_world(&fr, cdl_v3((float)(cp * st), (float)(sp * st), (float)ct));
            if (p->sun_above_only && d.y < 0.0f)
                continue;
            double zen, az;
            cdl_sunsky_angles(d, &zen, &az);
            int x = (int)(az * w / (2.0 * PI));
            int y = p->node_rows ? (int)floor(zen * (h - 1) / PI + 0.5) : (int)(zen * h / PI);
            x = x < 0 ? 0 : x >= w ? w - 1 : x;
            y = y < 0 ? 0 : y >= h ? h - 1 : y;
            double f = k / fmax(1e-3, sqrt(fmax(0.0, 1.0 - (double)d.y * d.y)));
            float *t = rgb + 3 * ((size_t)y * (size_t)w + (size_t)x);
            t[0] += (float)(L.x * f);
            t[1] += (float)(L.y * f);
            t[2] += (float)(L.z * f);
        }
    }
    *out = rgb;
    return 0;
}
