#include "core/spectrum.h"

/* CIE 1931 2-degree colour matching functions, 380..780 nm in 10 nm steps. */
const double cdl_cie_xyz[CDL_CIE_N][3] = {
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

/* CIE standard illuminant D65, relative, 380..780 nm in 10 nm steps. */
static const double D65[CDL_CIE_N] = {
    49.9755, 54.6482, 82.7549, 91.486,  93.4318, 86.6823, 104.865, 117.008, 117.812, 114.861, 115.923,
    108.811, 109.354, 107.802, 104.79,  107.689, 104.405, 104.046, 100.0,   96.3342, 95.788,  88.6856,
    90.0062, 89.5991, 87.6987, 83.2886, 83.6992, 80.0268, 80.2146, 82.2778, 78.2842, 69.7213, 71.6091,
    74.349,  61.604,  69.8856, 75.087,  63.5927, 46.4182, 66.8054, 63.3828,
};

cdl_vec3 cdl_xyz_to_srgb(double x, double y, double z)
{
    return cdl_v3((float)(3.240479 * x - 1.537150 * y - 0.498535 * z),
                  (float)(-0.969256 * x + 1.875991 * y + 0.041556 * z),
                  (float)(0.055648 * x - 0.204043 * y + 1.057311 * z));
}

static double sample(const double *lambda, const double *value, int n, double l)
{
    if (l <= lambda[0])
        return value[0];
    for (int i = 1; i < n; i++)
        if (l <= lambda[i]) {
            double t = (l - lambda[i - 1]) / (lambda[i] - lambda[i - 1]);
            return value[i - 1] + t * (value[i] - value[i - 1]);
        }
    return value[n - 1];
}

static cdl_vec3 integrate(const double *lambda, const double *value, int n, int reflectance)
{
    double xyz[3] = {0, 0, 0}, norm = 0.0;
    for (int i = 0; i < CDL_CIE_N; i++) {
        double w = reflectance ? D65[i] : 1.0, s = sample(lambda, value, n, 380.0 + 10.0 * i) * w;
        for (int k = 0; k < 3; k++)
            xyz[k] += cdl_cie_xyz[i][k] * s;
        norm += cdl_cie_xyz[i][1] * w;
    }
    return cdl_xyz_to_srgb(xyz[0] / norm, xyz[1] / norm, xyz[2] / norm);
}

cdl_vec3 cdl_spectrum_to_srgb(const double *lambda, const double *value, int n, int reflectance)
{
    cdl_vec3 c = integrate(lambda, value, n, reflectance);
    if (!reflectance)
        return c;
    /* the 10 nm tables put D65 itself a little off sRGB's white: make a
     * constant spectrum exactly grey */
    static const double one_l[1] = {560.0}, one_v[1] = {1.0};
    cdl_vec3 w = integrate(one_l, one_v, 1, 1);
    return cdl_v3(c.x / w.x, c.y / w.y, c.z / w.z);
}
