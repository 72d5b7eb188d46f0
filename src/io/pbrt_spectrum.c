/* Spectral values of pbrt files turned into the RGB candela renders with. */
#include <math.h>
#include <string.h>

#include "io/pbrt_params.h"

/* CIE 1931 2-degree colour matching functions, 380..780 nm in 10 nm steps. */
#define CIE_N 41
static const double CIE[CIE_N][3] = {
    {0.001368, 0.000039, 0.006450}, {0.004243, 0.000120, 0.020050}, {0.014310, 0.000396, 0.067850},
    {0.043510, 0.001210, 0.207400}, {0.134380, 0.004000, 0.645600}, {0.283900, 0.011600, 1.385600},
    {0.348280, 0.023000, 1.747060}, {0.336200, 0.038000, 1.772110}, {0.290800, 0.060000, 1.669200},
    {0.195360, 0.090980, 1.287640}, {0.095640, 0.139020, 0.812950}, {0.032010, 0.208020, 0.465180},
    {0.004900, 0.323000, 0.272000}, {0.009300, 0.503000, 0.158200}, {0.063270, 0.710000, 0.078250},
    {0.165500, 0.862000, 0.042160}, {0.290400, 0.954000, 0.020300}, {0.433450, 0.994950, 0.008750},
    {0.594500, 0.995000, 0.003900}, {0.762100, 0.952000, 0.002100}, {0.916300, 0.870000, 0.001650},
    {1.026300, 0.757000, 0.001100}, {1.062200, 0.631000, 0.000800}, {1.002600, 0.503000, 0.000340},
    {0.854450, 0.381000, 0.000190}, {0.642400, 0.265000, 0.000050}, {0.447900, 0.175000, 0.000020},
    {0.283500, 0.107000, 0.000000}, {0.164900, 0.061000, 0.000000}, {0.087400, 0.032000, 0.000000},
    {0.046770, 0.017000, 0.000000}, {0.022700, 0.008210, 0.000000}, {0.011359, 0.004102, 0.000000},
    {0.005790, 0.002091, 0.000000}, {0.002899, 0.001047, 0.000000}, {0.001440, 0.000520, 0.000000},
    {0.000690, 0.000249, 0.000000}, {0.000332, 0.000120, 0.000000}, {0.000166, 0.000060, 0.000000},
    {0.000083, 0.000030, 0.000000}, {0.000042, 0.000015, 0.000000},
};

/* Planck's law with pbrt-v3's constants; lambda in nm. */
static double planck(double lambda_nm, double T)
{
    const double c = 299792458.0, h = 6.62606957e-34, kb = 1.3806488e-23;
    double l = lambda_nm * 1e-9;
    return (2.0 * h * c * c) / (l * l * l * l * l * (exp((h * c) / (l * kb * T)) - 1.0));
}

/* pbrt-v3's XYZToRGB (sRGB primaries, D65 white). */
cdl_vec3 cdl_pbrt_xyz_to_rgb(double x, double y, double z)
{
    return cdl_v3((float)(3.240479 * x - 1.537150 * y - 0.498535 * z),
                  (float)(-0.969256 * x + 1.875991 * y + 0.041556 * z),
                  (float)(0.055648 * x - 0.204043 * y + 1.057311 * z));
}

cdl_vec3 cdl_pbrt_blackbody(double T, int v4)
{
    /* peak normalization as pbrt's BlackbodyNormalized (Wien's law) */
    double peak = planck(2.8977721e-3 / T * 1e9, T);
    double xyz[3] = {0, 0, 0}, yint = 0.0;
    for (int i = 0; i < CIE_N; i++) {
        double b = planck(380.0 + 10.0 * i, T) / peak;
        for (int k = 0; k < 3; k++)
            xyz[k] += CIE[i][k] * b;
        yint += CIE[i][1];
    }
    /* v3: divide by the integral of y-bar (an equal-energy 1 has Y = 1);
     * v4: lights are scaled to luminance 1 (SpectrumToPhotometric) */
    double norm = v4 ? xyz[1] : yint;
    if (!(norm > 0.0))
        return cdl_v3(0, 0, 0);
    cdl_vec3 rgb = cdl_pbrt_xyz_to_rgb(xyz[0] / norm, xyz[1] / norm, xyz[2] / norm);
    /* very cold or hot bodies fall outside sRGB: clip the negative lobe */
    return cdl_v3(cdl_maxf(rgb.x, 0.0f), cdl_maxf(rgb.y, 0.0f), cdl_maxf(rgb.z, 0.0f));
}

/* Complex indices of refraction of metals, projected to RGB (the values
 * Bitterli's pbrt exports carry, e.g. copper in veach-mis). */
static const struct {
    const char *metal;
    float eta[3], k[3];
} METALS[] = {
    {"Cu", {0.2004376970f, 0.9240334304f, 1.1022119527f}, {3.9129485033f, 2.4528477015f, 2.1421879552f}},
    {"Au", {0.1431189557f, 0.3749570432f, 1.4424785571f}, {3.9831604247f, 2.3857207478f, 1.6032152899f}},
    {"Ag", {0.1552646489f, 0.1167232965f, 0.1383806959f}, {4.8283433224f, 3.1222459278f, 2.1469504455f}},
    {"Al", {1.6574599595f, 0.8803689579f, 0.5212287346f}, {9.2238691996f, 6.2695232477f, 4.8370012281f}},
};

/* pbrt-v4's named glasses at the sodium d line (dispersion dropped). */
static const struct {
    const char *name;
    float eta;
} GLASSES[] = {
    {"glass-BK7", 1.5168f},  {"glass-BAF10", 1.6700f}, {"glass-FK51A", 1.4866f},
    {"glass-LASF9", 1.8503f}, {"glass-F5", 1.6727f},    {"glass-F10", 1.7283f},
    {"glass-F11", 1.7847f},
};

int cdl_pbrt_named_spectrum(const char *name, cdl_vec3 *rgb)
{
    if (!strncmp(name, "metal-", 6)) {
        const char *m = name + 6, *dash = strrchr(m, '-');
        if (!dash || (strcmp(dash, "-eta") && strcmp(dash, "-k")))
            return -1;
        int is_k = !strcmp(dash, "-k");
        for (size_t i = 0; i < sizeof METALS / sizeof METALS[0]; i++)
            if (strlen(METALS[i].metal) == (size_t)(dash - m) && !strncmp(m, METALS[i].metal, (size_t)(dash - m))) {
                const float *v = is_k ? METALS[i].k : METALS[i].eta;
                *rgb = cdl_v3(v[0], v[1], v[2]);
                return 0;
            }
        /* other pbrt-v4 metals (CuZn, MgO, TiO2): copper stands in */
        const float *v = is_k ? METALS[0].k : METALS[0].eta;
        *rgb = cdl_v3(v[0], v[1], v[2]);
        return !strncmp(m, "CuZn-", 5) || !strncmp(m, "MgO-", 4) || !strncmp(m, "TiO2-", 5) ? 1 : -1;
    }
    for (size_t i = 0; i < sizeof GLASSES / sizeof GLASSES[0]; i++)
        if (!strcmp(name, GLASSES[i].name)) {
            *rgb = cdl_v3(GLASSES[i].eta, GLASSES[i].eta, GLASSES[i].eta);
            return 0;
        }
    if (!strncmp(name, "stdillum-", 9)) {
        /* lights are normalized to luminance 1 in pbrt-v4, and D65 is the
         * sRGB white: exactly white; the others only roughly */
        *rgb = cdl_v3(1, 1, 1);
        return strcmp(name, "stdillum-D65") ? 1 : 0;
    }
    return -1;
}
