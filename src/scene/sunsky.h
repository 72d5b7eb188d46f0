/* Daylight as Mitsuba 0.6 models it (src/emitters/sunsky.cpp, sky.cpp,
 * sun.cpp, sunsky/): the sun's position by the PSA algorithm of Blanco-Muriel
 * et al. ("Computing the Solar Vector", Solar Energy 70(5), 2001), Hosek and
 * Wilkie's sky (SIGGRAPH 2012, RGB coefficients) and Preetham et al.'s sun
 * (its solar spectrum attenuated by the atmosphere), rasterized into one RGB
 * lat-long environment image.
 *
 * Directions are in the sky's own frame: y up, and a point of the sky at
 * zenith angle theta and azimuth phi lies at
 *   (sin phi sin theta, cos theta, -cos phi sin theta)
 * (Mitsuba 0.6's toSphere: azimuth 0 is -z, 90 degrees +x). The image's
 * texel (x, y) of a w x h image is the direction at theta = (y + 1/2) pi / h
 * (or y pi / (h - 1), node_rows), phi = (x + 1/2) 2 pi / w; radiances in
 * W / (m^2 sr nm), as Mitsuba's. */
#ifndef CDL_SUNSKY_H
#define CDL_SUNSKY_H

#include "core/error.h"
#include "core/vec.h"

/* The sun's apparent diameter in degrees (Mitsuba's SUN_APP_RADIUS). */
#define CDL_SUN_DIAMETER_DEG 0.5358

/* Local time and place of an observer (PSA). */
typedef struct cdl_sun_time {
    int year, month, day;
    double hour, minute, second;  /* local time */
    double latitude, longitude;   /* degrees, north and east positive */
    double timezone;              /* hours east of UTC */
} cdl_sun_time;

/* The sun's zenith angle and azimuth (radians; the azimuth from north
 * through east, in [0, 2 pi)) by the PSA algorithm, with its parallax
 * correction, as Mitsuba 0.6 computes them. */
void cdl_sun_psa(const cdl_sun_time *t, double *zenith, double *azimuth);

/* Mitsuba 0.6's toSphere and fromSphere in the sky's frame. */
cdl_vec3 cdl_sunsky_dir(double zenith, double azimuth);
void cdl_sunsky_angles(cdl_vec3 d, double *zenith, double *azimuth);

/* The sun's radiance (linear sRGB) through an atmosphere of the given
 * turbidity when it stands at zenith angle zenith. */
cdl_vec3 cdl_sun_radiance(double zenith, double turbidity);

/* Hosek and Wilkie's sky for one sun position, per RGB channel. */
typedef struct cdl_sky_model {
    double config[3][9]; /* the parameters A..I */
    double radiance[3];  /* the overall scale */
    double sun_zenith, sun_azimuth;
    double stretch;      /* Mitsuba's stretch: 1, or up to 2 to reach below the horizon */
    int extend;          /* Mitsuba's extend: the horizon's radiance continued below it */
} cdl_sky_model;

/* turbidity in [1, 10], albedo per channel in [0, 1], the sun's zenith
 * angle at most pi / 2 (the model has no night). */
void cdl_sky_init(cdl_sky_model *m, double turbidity, cdl_vec3 albedo, double sun_zenith, double sun_azimuth,
                  double stretch, int extend);
/* The sky's radiance from (zenith angle theta, azimuth phi). */
cdl_vec3 cdl_sky_radiance(const cdl_sky_model *m, double theta, double phi);

/* What goes into the image. */
typedef struct cdl_sunsky_params {
    double turbidity;        /* [1, 10] */
    cdl_vec3 albedo;         /* the ground's, [0, 1] */
    double sun_zenith, sun_azimuth; /* where the sun is (before stretch) */
    double stretch;          /* [1, 2] */
    int extend;
    double sky_scale;        /* 0: no sky */
    double sun_scale;        /* 0: no sun disk */
    double sun_radius_scale; /* > 0: the disk's radius over the sun's, its power kept */
    int sun_above_only;      /* drop the part of the disk below the horizon (Mitsuba 3) */
    int width, height;       /* the image, width x height texels */
    int node_rows;           /* rows at theta = y pi / (h - 1), the nodes of Mitsuba 3's
                                bilinear envmap; else at (y + 1/2) pi / h, as Mitsuba 0.6 */
} cdl_sunsky_params;

void cdl_sunsky_params_init(cdl_sunsky_params *p);

/* The merged image (Mitsuba 0.6's sunsky): the sky at each texel's centre
 * plus the sun disk spread over the texels it covers by quasi-random
 * directions in it, each texel's share divided by its solid angle. *rgb is
 * malloc'd, width * height * 3 floats, rows from the zenith down. */
int cdl_sunsky_image(const cdl_sunsky_params *p, float **rgb, cdl_error *err);

/* The direction towards the sun in the image (after stretch) and the solid
 * angle of the unscaled disk: the sun as a distant light. */
cdl_vec3 cdl_sunsky_sun_dir(const cdl_sunsky_params *p);
double cdl_sun_solid_angle(void);

#endif
