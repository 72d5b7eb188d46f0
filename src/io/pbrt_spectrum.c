/* Spectral values of pbrt files turned into the RGB candela renders with. */
#include <math.h>
#include <string.h>

#include "core/spectrum.h"
#include "io/pbrt_params.h"

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
    return cdl_xyz_to_srgb(x, y, z);
}

cdl_vec3 cdl_pbrt_blackbody(double T, int v4)
{
    /* peak normalization as pbrt's BlackbodyNormalized (Wien's law) */
    double peak = planck(2.8977721e-3 / T * 1e9, T);
    double xyz[3] = {0, 0, 0}, yint = 0.0;
    for (int i = 0; i < CDL_CIE_N; i++) {
        double b = planck(380.0 + 10.0 * i, T) / peak;
        for (int k = 0; k < 3; k++)
            xyz[k] += cdl_cie_xyz[i][k] * b;
        yint += cdl_cie_xyz[i][1];
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
