/* FLIP and HDR-FLIP (see flip.h). The spatial and feature filters are
 * separable: the colour filters are Gaussians in YCxCz (the blue-yellow one
 * a sum of two, filtered as two separable passes), the feature filters the
 * first and second derivatives of a Gaussian on the achromatic channel.
 * Borders clamp to the edge, as in the reference implementation. */
#include "film/flip.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

/* Colour error: exponent qc, cut-off pc, remapped value pt at the cut-off;
 * feature error: filter width w in degrees, exponent qf (section 4 of the
 * FLIP paper). */
static const double QC = 0.7, PC = 0.4, PT = 0.95, GW = 0.082, QF = 0.5;

/* Contrast sensitivity as sums of Gaussians a sqrt(pi/b) exp(-pi^2 x^2 / b)
 * for Y, Cx and Cz (table 1 of the FLIP paper); only Cz has a second one. */
static const double A1[3] = {1.0, 1.0, 34.1}, B1[3] = {0.0047, 0.0053, 0.04};
static const double A2_CZ = 13.5, B2_CZ = 0.025;
static const double B_MAX = 0.04; /* the widest of the b's, for the radius */

/* D65 white and its inverse, as the reference implementation rounds them. */
static const double WHITE[3] = {0.950428545, 1.0, 1.088900371};
static const double INV_WHITE[3] = {1.052156925, 1.0, 0.918357670};

/* ACES fit (Narkowicz) with its 0.6 pre-exposure cancelled:
 * (c0 x^2 + c1 x + c2) / (c3 x^2 + c4 x + c5). */
static const double ACES[6] = {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};

/* matplotlib's magma, in sRGB. */
static const float MAGMA[256][3] = {
    {0.001462, 0.000466, 0.013866}, {0.002258, 0.001295, 0.018331}, {0.003279, 0.002305, 0.023708}, {0.004512, 0.003490, 0.029965},
    {0.005950, 0.004843, 0.037130}, {0.007588, 0.006356, 0.044973}, {0.009426, 0.008022, 0.052844}, {0.011465, 0.009828, 0.060750},
    {0.013708, 0.011771, 0.068667}, {0.016156, 0.013840, 0.076603}, {0.018815, 0.016026, 0.084584}, {0.021692, 0.018320, 0.092610},
    {0.024792, 0.020715, 0.100676}, {0.028123, 0.023201, 0.108787}, {0.031696, 0.025765, 0.116965}, {0.035520, 0.028397, 0.125209},
    {0.039608, 0.031090, 0.133515}, {0.043830, 0.033830, 0.141886}, {0.048062, 0.036607, 0.150327}, {0.052320, 0.039407, 0.158841},
    {0.056615, 0.042160, 0.167446}, {0.060949, 0.044794, 0.176129}, {0.065330, 0.047318, 0.184892}, {0.069764, 0.049726, 0.193735},
    {0.074257, 0.052017, 0.202660}, {0.078815, 0.054184, 0.211667}, {0.083446, 0.056225, 0.220755}, {0.088155, 0.058133, 0.229922},
    {0.092949, 0.059904, 0.239164}, {0.097833, 0.061531, 0.248477}, {0.102815, 0.063010, 0.257854}, {0.107899, 0.064335, 0.267289},
    {0.113094, 0.065492, 0.276784}, {0.118405, 0.066479, 0.286321}, {0.123833, 0.067295, 0.295879}, {0.129380, 0.067935, 0.305443},
    {0.135053, 0.068391, 0.315000}, {0.140858, 0.068654, 0.324538}, {0.146785, 0.068738, 0.334011}, {0.152839, 0.068637, 0.343404},
    {0.159018, 0.068354, 0.352688}, {0.165308, 0.067911, 0.361816}, {0.171713, 0.067305, 0.370771}, {0.178212, 0.066576, 0.379497},
    {0.184801, 0.065732, 0.387973}, {0.191460, 0.064818, 0.396152}, {0.198177, 0.063862, 0.404009}, {0.204935, 0.062907, 0.411514},
    {0.211718, 0.061992, 0.418647}, {0.218512, 0.061158, 0.425392}, {0.225302, 0.060445, 0.431742}, {0.232077, 0.059889, 0.437695},
    {0.238826, 0.059517, 0.443256}, {0.245543, 0.059352, 0.448436}, {0.252220, 0.059415, 0.453248}, {0.258857, 0.059706, 0.457710},
    {0.265447, 0.060237, 0.461840}, {0.271994, 0.060994, 0.465660}, {0.278493, 0.061978, 0.469190}, {0.284951, 0.063168, 0.472451},
    {0.291366, 0.064553, 0.475462}, {0.297740, 0.066117, 0.478243}, {0.304081, 0.067835, 0.480812}, {0.310382, 0.069702, 0.483186},
    {0.316654, 0.071690, 0.485380}, {0.322899, 0.073782, 0.487408}, {0.329114, 0.075972, 0.489287}, {0.335308, 0.078236, 0.491024},
    {0.341482, 0.080564, 0.492631}, {0.347636, 0.082946, 0.494121}, {0.353773, 0.085373, 0.495501}, {0.359898, 0.087831, 0.496778},
    {0.366012, 0.090314, 0.497960}, {0.372116, 0.092816, 0.499053}, {0.378211, 0.095332, 0.500067}, {0.384299, 0.097855, 0.501002},
    {0.390384, 0.100379, 0.501864}, {0.396467, 0.102902, 0.502658}, {0.402548, 0.105420, 0.503386}, {0.408629, 0.107930, 0.504052},
    {0.414709, 0.110431, 0.504662}, {0.420791, 0.112920, 0.505215}, {0.426877, 0.115395, 0.505714}, {0.432967, 0.117855, 0.506160},
    {0.439062, 0.120298, 0.506555}, {0.445163, 0.122724, 0.506901}, {0.451271, 0.125132, 0.507198}, {0.457386, 0.127522, 0.507448},
    {0.463508, 0.129893, 0.507652}, {0.469640, 0.132245, 0.507809}, {0.475780, 0.134577, 0.507921}, {0.481929, 0.136891, 0.507989},
    {0.488088, 0.139186, 0.508011}, {0.494258, 0.141462, 0.507988}, {0.500438, 0.143719, 0.507920}, {0.506629, 0.145958, 0.507806},
    {0.512831, 0.148179, 0.507648}, {0.519045, 0.150383, 0.507443}, {0.525270, 0.152569, 0.507192}, {0.531507, 0.154739, 0.506895},
    {0.537755, 0.156894, 0.506551}, {0.544015, 0.159033, 0.506159}, {0.550287, 0.161158, 0.505719}, {0.556571, 0.163269, 0.505230},
    {0.562866, 0.165368, 0.504692}, {0.569172, 0.167454, 0.504105}, {0.575490, 0.169530, 0.503466}, {0.581819, 0.171596, 0.502777},
    {0.588158, 0.173652, 0.502035}, {0.594508, 0.175701, 0.501241}, {0.600868, 0.177743, 0.500394}, {0.607238, 0.179779, 0.499492},
    {0.613617, 0.181811, 0.498536}, {0.620005, 0.183840, 0.497524}, {0.626401, 0.185867, 0.496456}, {0.632805, 0.187893, 0.495332},
    {0.639216, 0.189921, 0.494150}, {0.645633, 0.191952, 0.492910}, {0.652056, 0.193986, 0.491611}, {0.658483, 0.196027, 0.490253},
    {0.664915, 0.198075, 0.488836}, {0.671349, 0.200133, 0.487358}, {0.677786, 0.202203, 0.485819}, {0.684224, 0.204286, 0.484219},
    {0.690661, 0.206384, 0.482558}, {0.697098, 0.208501, 0.480835}, {0.703532, 0.210638, 0.479049}, {0.709962, 0.212797, 0.477201},
    {0.716387, 0.214982, 0.475290}, {0.722805, 0.217194, 0.473316}, {0.729216, 0.219437, 0.471279}, {0.735616, 0.221713, 0.469180},
    {0.742004, 0.224025, 0.467018}, {0.748378, 0.226377, 0.464794}, {0.754737, 0.228772, 0.462509}, {0.761077, 0.231214, 0.460162},
    {0.767398, 0.233705, 0.457755}, {0.773695, 0.236249, 0.455289}, {0.779968, 0.238851, 0.452765}, {0.786212, 0.241514, 0.450184},
    {0.792427, 0.244242, 0.447543}, {0.798608, 0.247040, 0.444848}, {0.804752, 0.249911, 0.442102}, {0.810855, 0.252861, 0.439305},
    {0.816914, 0.255895, 0.436461}, {0.822926, 0.259016, 0.433573}, {0.828886, 0.262229, 0.430644}, {0.834791, 0.265540, 0.427671},
    {0.840636, 0.268953, 0.424666}, {0.846416, 0.272473, 0.421631}, {0.852126, 0.276106, 0.418573}, {0.857763, 0.279857, 0.415496},
    {0.863320, 0.283729, 0.412403}, {0.868793, 0.287728, 0.409303}, {0.874176, 0.291859, 0.406205}, {0.879464, 0.296125, 0.403118},
    {0.884651, 0.300530, 0.400047}, {0.889731, 0.305079, 0.397002}, {0.894700, 0.309773, 0.393995}, {0.899552, 0.314616, 0.391037},
    {0.904281, 0.319610, 0.388137}, {0.908884, 0.324755, 0.385308}, {0.913354, 0.330052, 0.382563}, {0.917689, 0.335500, 0.379915},
    {0.921884, 0.341098, 0.377376}, {0.925937, 0.346844, 0.374959}, {0.929845, 0.352734, 0.372677}, {0.933606, 0.358764, 0.370541},
    {0.937221, 0.364929, 0.368567}, {0.940687, 0.371224, 0.366762}, {0.944006, 0.377643, 0.365136}, {0.947180, 0.384178, 0.363701},
    {0.950210, 0.390820, 0.362468}, {0.953099, 0.397563, 0.361438}, {0.955849, 0.404400, 0.360619}, {0.958464, 0.411324, 0.360014},
    {0.960949, 0.418323, 0.359630}, {0.963310, 0.425390, 0.359469}, {0.965549, 0.432519, 0.359529}, {0.967671, 0.439703, 0.359810},
    {0.969680, 0.446936, 0.360311}, {0.971582, 0.454210, 0.361030}, {0.973381, 0.461520, 0.361965}, {0.975082, 0.468861, 0.363111},
    {0.976690, 0.476226, 0.364466}, {0.978210, 0.483612, 0.366025}, {0.979645, 0.491014, 0.367783}, {0.981000, 0.498428, 0.369734},
    {0.982279, 0.505851, 0.371874}, {0.983485, 0.513280, 0.374198}, {0.984622, 0.520713, 0.376698}, {0.985693, 0.528148, 0.379371},
    {0.986700, 0.535582, 0.382210}, {0.987646, 0.543015, 0.385210}, {0.988533, 0.550446, 0.388365}, {0.989363, 0.557873, 0.391671},
    {0.990138, 0.565296, 0.395122}, {0.990871, 0.572706, 0.398714}, {0.991558, 0.580107, 0.402441}, {0.992196, 0.587502, 0.406299},
    {0.992785, 0.594891, 0.410283}, {0.993326, 0.602275, 0.414390}, {0.993834, 0.609644, 0.418613}, {0.994309, 0.616999, 0.422950},
    {0.994738, 0.624350, 0.427397}, {0.995122, 0.631696, 0.431951}, {0.995480, 0.639027, 0.436607}, {0.995810, 0.646344, 0.441361},
    {0.996096, 0.653659, 0.446213}, {0.996341, 0.660969, 0.451160}, {0.996580, 0.668256, 0.456192}, {0.996775, 0.675541, 0.461314},
    {0.996925, 0.682828, 0.466526}, {0.997077, 0.690088, 0.471811}, {0.997186, 0.697349, 0.477182}, {0.997254, 0.704611, 0.482635},
    {0.997325, 0.711848, 0.488154}, {0.997351, 0.719089, 0.493755}, {0.997351, 0.726324, 0.499428}, {0.997341, 0.733545, 0.505167},
    {0.997285, 0.740772, 0.510983}, {0.997228, 0.747981, 0.516859}, {0.997138, 0.755190, 0.522806}, {0.997019, 0.762398, 0.528821},
    {0.996898, 0.769591, 0.534892}, {0.996727, 0.776795, 0.541039}, {0.996571, 0.783977, 0.547233}, {0.996369, 0.791167, 0.553499},
    {0.996162, 0.798348, 0.559820}, {0.995932, 0.805527, 0.566202}, {0.995680, 0.812706, 0.572645}, {0.995424, 0.819875, 0.579140},
    {0.995131, 0.827052, 0.585701}, {0.994851, 0.834213, 0.592307}, {0.994524, 0.841387, 0.598983}, {0.994222, 0.848540, 0.605696},
    {0.993866, 0.855711, 0.612482}, {0.993545, 0.862859, 0.619299}, {0.993170, 0.870024, 0.626189}, {0.992831, 0.877168, 0.633109},
    {0.992440, 0.884330, 0.640099}, {0.992089, 0.891470, 0.647116}, {0.991688, 0.898627, 0.654202}, {0.991332, 0.905763, 0.661309},
    {0.990930, 0.912915, 0.668481}, {0.990570, 0.920049, 0.675675}, {0.990175, 0.927196, 0.682926}, {0.989815, 0.934329, 0.690198},
    {0.989434, 0.941470, 0.697519}, {0.989077, 0.948604, 0.704863}, {0.988717, 0.955742, 0.712242}, {0.988367, 0.962878, 0.719649},
    {0.988033, 0.970012, 0.727077}, {0.987691, 0.977154, 0.734536}, {0.987387, 0.984288, 0.742002}, {0.987053, 0.991438, 0.749504},
};

void cdl_flip_magma(float v, float rgb[3])
{
    if (!(v >= 0.0f))
        v = 0.0f;
    if (v > 1.0f)
        v = 1.0f;
    int i = (int)(v * 255.0f + 0.5f);
    for (int c = 0; c < 3; c++)
        rgb[c] = cdl_srgb_decode(MAGMA[i][c]);
}

/* ---- colour spaces ------------------------------------------------------ */

static void rgb_to_xyz(const double *c, double *o)
{
    o[0] = (10135552.0 * c[0] + 8788810.0 * c[1] + 4435075.0 * c[2]) / 24577794.0;
    o[1] = (2613072.0 * c[0] + 8788810.0 * c[1] + 887015.0 * c[2]) / 12288897.0;
    o[2] = (1425312.0 * c[0] + 8788810.0 * c[1] + 70074185.0 * c[2]) / 73733382.0;
}

static void xyz_to_rgb(const double *c, double *o)
{
    o[0] = 3.241003275 * c[0] - 1.537398934 * c[1] - 0.498615861 * c[2];
    o[1] = -0.969224334 * c[0] + 1.875930071 * c[1] + 0.041554224 * c[2];
    o[2] = 0.055639423 * c[0] - 0.204011202 * c[1] + 1.057148933 * c[2];
}

/* YCxCz: CIELAB without the cube root, linear in XYZ, so that the
 * contrast sensitivity filters act on linear values. */
static void xyz_to_ycxcz(const double *c, double *o)
{
    double x = c[0] * INV_WHITE[0], y = c[1] * INV_WHITE[1], z = c[2] * INV_WHITE[2];
    o[0] = 116.0 * y - 16.0;
    o[1] = 500.0 * (x - y);
    o[2] = 200.0 * (y - z);
}

static void ycxcz_to_xyz(const double *c, double *o)
{
    double y = (c[0] + 16.0) / 116.0;
    o[0] = (y + c[1] / 500.0) * WHITE[0];
    o[1] = y * WHITE[1];
    o[2] = (y - c[2] / 200.0) * WHITE[2];
}

static double lab_f(double t)
{
    const double d = 6.0 / 29.0;
    return t > d * d * d ? cbrt(t) : t / (3.0 * d * d) + 4.0 / 29.0;
}

/* CIELAB with Hunt's adjustment: chroma scaled by 0.01 L (eq. 3 of FLIP). */
static void xyz_to_lab_hunt(const double *c, double *o)
{
    double fx = lab_f(c[0] * INV_WHITE[0]), fy = lab_f(c[1] * INV_WHITE[1]), fz = lab_f(c[2] * INV_WHITE[2]);
    double l = 116.0 * fy - 16.0;
    o[0] = l;
    o[1] = 0.01 * l * 500.0 * (fx - fy);
    o[2] = 0.01 * l * 200.0 * (fy - fz);
}

void cdl_flip_lab_hunt(const double rgb[3], double lab[3])
{
    double xyz[3];
    rgb_to_xyz(rgb, xyz);
    xyz_to_lab_hunt(xyz, lab);
}

/* HyAB: city-block in L, Euclidean in (a, b) (eq. 4 of FLIP). */
static double hyab(const double *p, const double *q)
{
    return fabs(p[0] - q[0]) + hypot(p[1] - q[1], p[2] - q[2]);
}

double cdl_flip_cmax(void)
{
    const double green[3] = {0, 1, 0}, blue[3] = {0, 0, 1};
    double g[3], b[3];
    cdl_flip_lab_hunt(green, g);
    cdl_flip_lab_hunt(blue, b);
    return pow(hyab(g, b), QC);
}

/* Eq. 5 of FLIP: errors below pc cmax take [0, pt], the rest (pt, 1]. */
static double remap(double d, double cmax)
{
    double pccmax = PC * cmax;
    d = pow(d, QC);
    return d < pccmax ? d * PT / pccmax : PT + (d - pccmax) / (cmax - pccmax) * (1.0 - PT);
}

double cdl_flip_color_remap(double hyab_distance)
{
    return remap(hyab_distance, cdl_flip_cmax());
}

/* ---- filters -------------------------------------------------------------- */

int cdl_flip_spatial_radius(double ppd)
{
    return (int)ceil(3.0 * sqrt(B_MAX / (2.0 * PI * PI)) * ppd);
}

static double feature_sigma(double ppd)
{
    return 0.5 * GW * ppd; /* in pixels */
}

int cdl_flip_feature_radius(double ppd)
{
    return (int)ceil(3.0 * feature_sigma(ppd));
}

/* 1D weights, 2r+1 each: Y and Cx sum to 1; the two Cz components are
 * square roots of the 2D Gaussians' amplitudes, normalised together so the
 * 2D sum g1(x) g1(y) + g2(x) g2(y) is 1. */
static void spatial_filters(double ppd, int r, double *wy, double *wcx, double *wz1, double *wz2)
{
    double sy = 0, scx = 0, s1 = 0, s2 = 0;
    for (int i = -r; i <= r; i++) {
        double x2 = (i / ppd) * (i / ppd);
        double *o[4] = {wy + i + r, wcx + i + r, wz1 + i + r, wz2 + i + r};
        *o[0] = A1[0] * sqrt(PI / B1[0]) * exp(-PI * PI * x2 / B1[0]);
        *o[1] = A1[1] * sqrt(PI / B1[1]) * exp(-PI * PI * x2 / B1[1]);
        *o[2] = sqrt(A1[2] * sqrt(PI / B1[2])) * exp(-PI * PI * x2 / B1[2]);
        *o[3] = sqrt(A2_CZ * sqrt(PI / B2_CZ)) * exp(-PI * PI * x2 / B2_CZ);
        sy += *o[0];
        scx += *o[1];
        s1 += *o[2];
        s2 += *o[3];
    }
    double nz = 1.0 / sqrt(s1 * s1 + s2 * s2);
    for (int i = 0; i <= 2 * r; i++) {
        wy[i] /= sy;
        wcx[i] /= scx;
        wz1[i] *= nz;
        wz2[i] *= nz;
    }
}

/* Gaussian g (sums to 1), its first derivative dg and second ddg, whose
 * positive weights sum to 1 and negative ones to -1 (section 4.2 of FLIP). */
static void feature_filters(double ppd, int r, double *g, double *dg, double *ddg)
{
    double sd = feature_sigma(ppd), sg = 0, dpos = 0, dneg = 0, ddpos = 0, ddneg = 0;
    for (int i = -r; i <= r; i++) {
        double w = exp(-(double)(i * i) / (2.0 * sd * sd));
        double d = -i * w, dd = ((double)(i * i) / (sd * sd) - 1.0) * w;
        g[i + r] = w;
        dg[i + r] = d;
        ddg[i + r] = dd;
        sg += w;
        *(d > 0 ? &dpos : &dneg) += fabs(d);
        *(dd > 0 ? &ddpos : &ddneg) += fabs(dd);
    }
    for (int i = 0; i <= 2 * r; i++) {
        g[i] /= sg;
        dg[i] /= dg[i] > 0 ? dpos : dneg;
        ddg[i] /= ddg[i] > 0 ? ddpos : ddneg;
    }
}

static inline int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static inline double clamp01(double v)
{
    return v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v;
}

/* ---- LDR-FLIP --------------------------------------------------------------- */

/* Buffers of one LDR-FLIP evaluation: YCxCz of both images (3 floats a
 * pixel) and the horizontal pass of each (4 floats a pixel). */
typedef struct flip_work {
    float *ycc[2], *row[2];
    double *wy, *wcx, *wz1, *wz2, *g, *dg, *ddg;
    int rs, rf;
} flip_work;

static void work_free(flip_work *k)
{
    for (int i = 0; i < 2; i++) {
        free(k->ycc[i]);
        free(k->row[i]);
    }
    free(k->wy);
    free(k->g);
}

static int work_alloc(flip_work *k, size_t n, double ppd)
{
    memset(k, 0, sizeof *k);
    k->rs = cdl_flip_spatial_radius(ppd);
    k->rf = cdl_flip_feature_radius(ppd);
    size_t ns = 2 * (size_t)k->rs + 1, nf = 2 * (size_t)k->rf + 1;
    for (int i = 0; i < 2; i++) {
        k->ycc[i] = malloc(3 * n * sizeof(float));
        k->row[i] = malloc(4 * n * sizeof(float));
    }
    k->wy = malloc(4 * ns * sizeof(double));
    k->g = malloc(3 * nf * sizeof(double));
    if (!k->ycc[0] || !k->ycc[1] || !k->row[0] || !k->row[1] || !k->wy || !k->g) {
        work_free(k);
        return -1;
    }
    k->wcx = k->wy + ns;
    k->wz1 = k->wcx + ns;
    k->wz2 = k->wz1 + ns;
    k->dg = k->g + nf;
    k->ddg = k->dg + nf;
    spatial_filters(ppd, k->rs, k->wy, k->wcx, k->wz1, k->wz2);
    feature_filters(ppd, k->rf, k->g, k->dg, k->ddg);
    return 0;
}

/* Colour error of each pixel into out: the images filtered by the contrast
 * sensitivity functions, clamped to [0, 1] in linear RGB, compared in
 * Hunt-adjusted CIELAB by HyAB and remapped (section 4.1 of FLIP). */
static void color_error(flip_work *k, int w, int h, float *out)
{
    int r = k->rs;
    for (int im = 0; im < 2; im++) {
        const float *src = k->ycc[im];
        float *dst = k->row[im];
#pragma omp parallel for schedule(static)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double s[4] = {0, 0, 0, 0};
                for (int i = -r; i <= r; i++) {
                    const float *p = src + 3 * ((size_t)y * w + clampi(x + i, 0, w - 1));
                    s[0] += k->wy[i + r] * p[0];
                    s[1] += k->wcx[i + r] * p[1];
                    s[2] += k->wz1[i + r] * p[2];
                    s[3] += k->wz2[i + r] * p[2];
                }
                float *o = dst + 4 * ((size_t)y * w + x);
                for (int c = 0; c < 4; c++)
                    o[c] = (float)s[c];
            }
    }
    double cmax = cdl_flip_cmax();
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double lab[2][3];
            for (int im = 0; im < 2; im++) {
                double s[4] = {0, 0, 0, 0};
                for (int i = -r; i <= r; i++) {
                    const float *p = k->row[im] + 4 * ((size_t)clampi(y + i, 0, h - 1) * w + x);
                    s[0] += k->wy[i + r] * p[0];
                    s[1] += k->wcx[i + r] * p[1];
                    s[2] += k->wz1[i + r] * p[2];
                    s[3] += k->wz2[i + r] * p[3];
                }
                double ycc[3] = {s[0], s[1], s[2] + s[3]}, xyz[3], rgb[3];
                ycxcz_to_xyz(ycc, xyz);
                xyz_to_rgb(xyz, rgb);
                for (int c = 0; c < 3; c++)
                    rgb[c] = clamp01(rgb[c]);
                cdl_flip_lab_hunt(rgb, lab[im]);
            }
            out[(size_t)y * w + x] = (float)remap(hyab(lab[0], lab[1]), cmax);
        }
}

/* Edges and points of the achromatic channel (normalised to [0, 1]), their
 * largest difference to the power qf, and the FLIP value
 * colour error ^ (1 - feature error) (eq. 8 of FLIP), over out. */
static void feature_error(flip_work *k, int w, int h, float *out)
{
    int r = k->rf;
    for (int im = 0; im < 2; im++) {
        const float *src = k->ycc[im];
        float *dst = k->row[im];
#pragma omp parallel for schedule(static)
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double d = 0, dd = 0, g = 0;
                for (int i = -r; i <= r; i++) {
                    double v = (src[3 * ((size_t)y * w + clampi(x + i, 0, w - 1))] + 16.0) / 116.0;
                    d += k->dg[i + r] * v;
                    dd += k->ddg[i + r] * v;
                    g += k->g[i + r] * v;
                }
                float *o = dst + 4 * ((size_t)y * w + x);
                o[0] = (float)d;
                o[1] = (float)dd;
                o[2] = (float)g;
            }
    }
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double edge[2], point[2];
            for (int im = 0; im < 2; im++) {
                double dx = 0, ddx = 0, dy = 0, ddy = 0;
                for (int i = -r; i <= r; i++) {
                    const float *p = k->row[im] + 4 * ((size_t)clampi(y + i, 0, h - 1) * w + x);
                    dx += k->g[i + r] * p[0];
                    ddx += k->g[i + r] * p[1];
                    dy += k->dg[i + r] * p[2];
                    ddy += k->ddg[i + r] * p[2];
                }
                edge[im] = hypot(dx, dy);
                point[im] = hypot(ddx, ddy);
            }
            double de = fabs(edge[0] - edge[1]), dp = fabs(point[0] - point[1]);
            double f = pow((de > dp ? de : dp) / sqrt(2.0), QF);
            float *o = out + (size_t)y * w + x;
            *o = (float)pow(*o, 1.0 - f);
        }
}

/* LDR-FLIP of two linear RGB images in [0, 1] (k's ycc buffers filled here). */
static void ldr_flip(flip_work *k, const float *test, const float *ref, int w, int h, float *out)
{
    size_t n = (size_t)w * h;
    const float *src[2] = {ref, test};
    for (int im = 0; im < 2; im++)
#pragma omp parallel for schedule(static)
        for (size_t p = 0; p < n; p++) {
            double rgb[3] = {src[im][3 * p], src[im][3 * p + 1], src[im][3 * p + 2]}, xyz[3], ycc[3];
            rgb_to_xyz(rgb, xyz);
            xyz_to_ycxcz(xyz, ycc);
            for (int c = 0; c < 3; c++)
                k->ycc[im][3 * p + c] = (float)ycc[c];
        }
    color_error(k, w, h, out);
    feature_error(k, w, h, out);
}

/* ---- HDR-FLIP ----------------------------------------------------------------- */

double cdl_flip_aces(double x)
{
    return (ACES[0] * x * x + ACES[1] * x + ACES[2]) / (ACES[3] * x * x + ACES[4] * x + ACES[5]);
}

/* The larger root of (c0 - t c3) x^2 + (c1 - t c4) x + (c2 - t c5) = 0. */
double cdl_flip_aces_inverse_085(void)
{
    const double t = 0.85;
    double a = ACES[0] - t * ACES[3], b = ACES[1] - t * ACES[4], c = ACES[2] - t * ACES[5];
    if (a == 0.0)
        return -c / b;
    double d1 = -0.5 * b / a;
    return d1 + sqrt(d1 * d1 - c / a);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static double luminance(const float *c)
{
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

int cdl_flip_exposure_range(const cdl_image *ref, cdl_flip_exposures *out)
{
    size_t n = (size_t)ref->width * ref->height, npos = 0;
    float *lum = malloc(n * sizeof *lum);
    if (!lum)
        return -1;
    double ymax = -HUGE_VAL;
    for (size_t p = 0; p < n; p++) {
        double l = luminance(ref->rgb + 3 * p);
        if (l > ymax)
            ymax = l;
        lum[p] = (float)l;
        npos += l > 0.0;
    }
    /* The element at n/2 of the sorted luminances, as the reference's
     * nth_element; when it is not positive (a mostly black image) the
     * median of the positive ones instead, so that the range stays finite. */
    qsort(lum, n, sizeof *lum, cmp_float);
    double ymed = lum[n / 2];
    if (!(ymed > 0.0) && npos)
        ymed = lum[n - npos + npos / 2];
    free(lum);
    double xm = cdl_flip_aces_inverse_085();
    if (!(ymax > 0.0) || !(ymed > 0.0)) { /* a black reference: one exposure, twice */
        *out = (cdl_flip_exposures){0.0, 0.0, 2};
        return 0;
    }
    out->start = log2(xm / ymax);
    out->stop = log2(xm / ymed);
    double span = ceil(out->stop - out->start);
    out->count = span > 2.0 ? (int)span : 2;
    return 0;
}

/* ---- entry point ------------------------------------------------------------- */

static int check_inputs(const cdl_image *test, const cdl_image *ref, double ppd, cdl_error *err)
{
    if (!test || !ref || !test->rgb || !ref->rgb)
        return cdl_error_set(err, CDL_ERR_USAGE, NULL, 0, "FLIP: no image");
    if (test->width != ref->width || test->height != ref->height)
        return cdl_error_set(err, CDL_ERR_INPUT, NULL, 0, "image sizes differ: test %dx%d, reference %dx%d",
                             test->width, test->height, ref->width, ref->height);
    if (!isfinite(ppd) || (ppd > 0 && (ppd < CDL_FLIP_PPD_MIN || ppd > CDL_FLIP_PPD_MAX)))
        return cdl_error_set(err, CDL_ERR_USAGE, NULL, 0,
                             "FLIP: pixels per degree must lie in [%g, %g] (or be <= 0 for the default %.4g), got %g",
                             CDL_FLIP_PPD_MIN, CDL_FLIP_PPD_MAX, CDL_FLIP_PPD_DEFAULT, ppd);
    size_t n = 3 * (size_t)test->width * test->height;
    for (int which = 0; which < 2; which++) {
        const float *p = which ? ref->rgb : test->rgb;
        for (size_t i = 0; i < n; i++)
            if (!isfinite(p[i]))
                return cdl_error_set(err, CDL_ERR_INPUT, NULL, 0, "%s image has a non-finite value at pixel (%zu, %zu)",
                                     which ? "reference" : "test", i / 3 % test->width, i / 3 / test->width);
    }
    return 0;
}

int cdl_flip(const cdl_image *test, const cdl_image *ref, int hdr, double ppd, float *map, double *mean,
             cdl_flip_exposures *exp, cdl_error *err)
{
    int rc = check_inputs(test, ref, ppd, err);
    if (rc)
        return rc;
    if (ppd <= 0)
        ppd = CDL_FLIP_PPD_DEFAULT;
    int w = test->width, h = test->height;
    size_t n = (size_t)w * h;
    flip_work k;
    float *img[2] = {malloc(3 * n * sizeof(float)), malloc(3 * n * sizeof(float))};
    float *err_map = malloc(n * sizeof(float)), *tmp = hdr ? malloc(n * sizeof(float)) : NULL;
    if (!img[0] || !img[1] || !err_map || (hdr && !tmp) || work_alloc(&k, n, ppd)) {
        free(img[0]);
        free(img[1]);
        free(err_map);
        free(tmp);
        return cdl_error_set(err, CDL_ERR_SYSTEM, NULL, 0, "FLIP: out of memory for %dx%d pixels", w, h);
    }
    const float *src[2] = {test->rgb, ref->rgb};
    if (!hdr) {
        for (int im = 0; im < 2; im++)
            for (size_t i = 0; i < 3 * n; i++)
                img[im][i] = (float)clamp01(src[im][i]);
        ldr_flip(&k, img[0], img[1], w, h, err_map);
    } else {
        /* The largest LDR-FLIP over the exposures, each tone mapped by the
         * ACES fit and clamped (section 2 of HDR-FLIP). */
        cdl_flip_exposures e;
        if (cdl_flip_exposure_range(ref, &e)) {
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, NULL, 0, "FLIP: out of memory for %dx%d pixels", w, h);
            e.count = 0;
        }
        if (exp)
            *exp = e;
        double step = (e.stop - e.start) / (e.count - 1);
        for (size_t p = 0; p < n; p++)
            err_map[p] = 0.0f;
        for (int j = 0; !rc && j < e.count; j++) {
            double m = exp2(e.start + j * step);
            for (int im = 0; im < 2; im++)
                for (size_t i = 0; i < 3 * n; i++)
                    img[im][i] = (float)clamp01(cdl_flip_aces(src[im][i] * m));
            ldr_flip(&k, img[0], img[1], w, h, tmp);
            for (size_t p = 0; p < n; p++)
                if (tmp[p] > err_map[p])
                    err_map[p] = tmp[p];
        }
    }
    double sum = 0.0;
    for (size_t p = 0; p < n; p++)
        sum += err_map[p];
    if (mean && !rc)
        *mean = sum / (double)n;
    if (map && !rc)
        memcpy(map, err_map, n * sizeof(float));
    work_free(&k);
    free(img[0]);
    free(img[1]);
    free(err_map);
    free(tmp);
    return rc;
}
