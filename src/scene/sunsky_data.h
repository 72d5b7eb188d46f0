/* Tables of the daylight model (scene/sunsky.c): Hosek and Wilkie's RGB sky
 * coefficients and the spectral data of Preetham et al.'s sun, as Mitsuba
 * 0.6 ships them. Data only; see sunsky_data.c for their sources and the
 * sky data's license. */
#ifndef CDL_SUNSKY_DATA_H
#define CDL_SUNSKY_DATA_H

/* 2 albedos x 10 turbidities x 6 control points x 9 parameters */
#define CDL_HOSEK_CONFIGS 1080
/* 2 albedos x 10 turbidities x 6 control points */
#define CDL_HOSEK_RADIANCES 120

extern const double cdl_hosek_rgb[3][CDL_HOSEK_CONFIGS];
extern const double cdl_hosek_rgb_rad[3][CDL_HOSEK_RADIANCES];

/* A tabulated spectrum: n samples at increasing wavelengths (nm), zero
 * outside [lambda[0], lambda[n - 1]] and linear in between. */
typedef struct cdl_tab_spectrum {
    int n;
    const double *lambda, *value;
} cdl_tab_spectrum;

extern const cdl_tab_spectrum cdl_sun_k_o;   /* ozone absorption, 1/cm */
extern const cdl_tab_spectrum cdl_sun_k_g;   /* mixed gases absorption, 1/km */
extern const cdl_tab_spectrum cdl_sun_k_wa;  /* water vapour absorption, 1/cm */
extern const cdl_tab_spectrum cdl_sun_solar; /* extraterrestrial solar radiance, W / (m^2 nm sr) */

#endif
