#include "scene/bsdf_sh.h"

#include <math.h>
#include <string.h>

#include "scene/bsdf.h"

#define GRID_MU 48   /* uniform hemisphere grid: cos(theta) strata */
#define GRID_PHI 96  /* and azimuth strata */
#define N_BSDF 4608  /* BSDF samples per bin (as many as grid cells) */

/* sum f Y over the estimate's directions for one bin and one BSDF */
static void project(const cdl_bsdf *b, cdl_vec3 wo, double acc[CDL_SH_N][3])
{
    const double n_u = (double)GRID_MU * GRID_PHI, n_b = N_BSDF, p_u = 1.0 / (2.0 * CDL_PI);
    memset(acc, 0, sizeof(double) * CDL_SH_N * 3);
    for (int t = 0; t < 2; t++) {
        for (int i = 0; i < (t ? N_BSDF : GRID_MU * GRID_PHI); i++) {
            cdl_vec3 wi, f;
            float pb;
            if (t == 0) { /* the grid: uniform in cos(theta) and azimuth */
                float mu = ((float)(i / GRID_PHI) + 0.5f) / GRID_MU, phi = 2.0f * (float)CDL_PI * ((float)(i % GRID_PHI) + 0.5f) / GRID_PHI;
                float s = sqrtf(fmaxf(0.0f, 1.0f - mu * mu));
                wi = cdl_v3(s * cosf(phi), s * sinf(phi), mu);
                f = cdl_bsdf_eval(b, wo, wi, 0);
                pb = cdl_bsdf_pdf(b, wo, wi);
            } else { /* BSDF sampling, stratified in its first two dimensions */
                int side = 68; /* 68^2 >= N_BSDF */
                float u1 = ((float)(i % side) + 0.5f) / side, u2 = ((float)(i / side % side) + 0.5f) / side;
                double g = (double)i * 0.6180339887498949;
                float u0 = (float)(g - floor(g)); /* lobe choice, independent of u1, u2 */
                cdl_scatter sc;
                if (!cdl_bsdf_sample(b, wo, u0, u1, u2, 0, &sc) || sc.delta || !(sc.wi.z > 0.0f))
                    continue;
                wi = sc.wi;
                f = cdl_bsdf_eval(b, wo, wi, 0);
                pb = cdl_bsdf_pdf(b, wo, wi);
            }
            if (!(wi.z > 0.0f) || cdl_is_black(f))
                continue;
            double w = 1.0 / (n_u * p_u + n_b * (double)pb); /* balance heuristic, both techniques */
            float y[CDL_SH_N];
            cdl_sh_eval(wi, y);
            for (int k = 0; k < CDL_SH_N; k++) {
                int l = k < 1 ? 0 : k < 4 ? 1 : k < 9 ? 2 : 3, m = k - l * (l + 1);
                if ((l + m) & 1)
                    continue; /* odd in z: the even extension cancels it */
                double yk = 2.0 * y[k] * w; /* the mirrored half counts the same */
                acc[k][0] += f.x * yk;
                acc[k][1] += f.y * yk;
                acc[k][2] += f.z * yk;
            }
        }
    }
}

void cdl_bsdf_sh_build(cdl_bsdf_sh *t, const cdl_material *m)
{
    if (m->type == CDL_MAT_DIFFUSE) {
        /* kd / pi everywhere: c_00 = kd / pi sqrt(4 pi), exactly */
        memset(t, 0, sizeof *t);
        for (int i = 0; i < CDL_BSDF_SH_BINS; i++)
            for (int ch = 0; ch < 3; ch++)
                t->dc[i][0][ch] = (float)(2.0 / sqrt(CDL_PI));
        return;
    }
    cdl_vec3 n = cdl_v3(0.0f, 0.0f, 1.0f);
    cdl_bsdf b0, b1;
    cdl_bsdf_init(&b0, m, cdl_v3(0.0f, 0.0f, 0.0f), n, n);
    cdl_bsdf_init(&b1, m, cdl_v3(1.0f, 1.0f, 1.0f), n, n);
    for (int i = 0; i < CDL_BSDF_SH_BINS; i++) {
        float c = (float)i / (CDL_BSDF_SH_BINS - 1), s = sqrtf(1.0f - c * c);
        cdl_vec3 wo = cdl_v3(s, 0.0f, c < 1e-3f ? 1e-3f : c);
        wo = cdl_normalize(wo);
        double a0[CDL_SH_N][3], a1[CDL_SH_N][3];
        project(&b0, wo, a0);
        project(&b1, wo, a1);
        for (int k = 0; k < CDL_SH_N; k++)
            for (int ch = 0; ch < 3; ch++) {
                t->c0[i][k][ch] = (float)a0[k][ch];
                t->dc[i][k][ch] = (float)(a1[k][ch] - a0[k][ch]);
            }
    }
}

void cdl_bsdf_sh_lookup(const cdl_bsdf_sh *t, float cos_o, cdl_vec3 kd, float out[CDL_SH_N * 3])
{
    float x = fminf(fmaxf(cos_o, 0.0f), 1.0f) * (CDL_BSDF_SH_BINS - 1);
    int i = (int)x;
    if (i > CDL_BSDF_SH_BINS - 2)
        i = CDL_BSDF_SH_BINS - 2;
    float f = x - (float)i;
    const float k3[3] = {kd.x, kd.y, kd.z};
    for (int k = 0; k < CDL_SH_N; k++)
        for (int ch = 0; ch < 3; ch++) {
            float a = t->c0[i][k][ch] + k3[ch] * t->dc[i][k][ch];
            float b = t->c0[i + 1][k][ch] + k3[ch] * t->dc[i + 1][k][ch];
            out[k * 3 + ch] = a + f * (b - a);
        }
}
