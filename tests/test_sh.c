/* Spherical harmonics for splat's radiance maps: the basis is orthonormal
 * (numeric integration), rotation agrees with evaluating the rotated
 * function, and a material's BSDF table (scene/bsdf_sh.c) agrees with
 * numeric integration: its coefficients against a dense quadrature, and
 * the reflected radiance sum c_lm lambda_lm against int f L cos for a known
 * incident radiance (exact for a Lambertian BSDF, within the band limit's
 * error for glossy ones). */
#include <math.h>
#include <string.h>

#include "core/rng.h"
#include "core/sh.h"
#include "scene/bsdf.h"
#include "scene/bsdf_sh.h"
#include "test_util.h"

/* Dense midpoint rule over the sphere (or the upper hemisphere) in
 * (cos theta, phi). */
#define QM 400
#define QP 800

static void orthonormal(void)
{
    static double g[CDL_SH_N][CDL_SH_N];
    memset(g, 0, sizeof g);
    for (int i = 0; i < QM; i++)
        for (int j = 0; j < QP; j++) {
            double mu = -1.0 + 2.0 * (i + 0.5) / QM, phi = 2.0 * CDL_PI * (j + 0.5) / QP, s = sqrt(1.0 - mu * mu);
            float y[CDL_SH_N];
            cdl_sh_eval(cdl_v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)mu), y);
            double dw = 4.0 * CDL_PI / ((double)QM * QP);
            for (int a = 0; a < CDL_SH_N; a++)
                for (int b = 0; b < CDL_SH_N; b++)
                    g[a][b] += y[a] * y[b] * dw;
        }
    double worst = 0.0;
    for (int a = 0; a < CDL_SH_N; a++)
        for (int b = 0; b < CDL_SH_N; b++)
            worst = fmax(worst, fabs(g[a][b] - (a == b)));
    CHECK(worst < 1e-4, "the 16 basis functions are orthonormal (largest error of the Gram matrix %.2g)", worst);
}

static void rotation(void)
{
    cdl_sh_rot rot;
    CHECK(cdl_sh_rot_init(&rot) == 0, "rotation directions well conditioned");
    cdl_rng r;
    cdl_rng_seed(&r, 4, 4);
    double worst = 0.0;
    for (int k = 0; k < 50; k++) {
        float in[CDL_SH_N * 2], out[CDL_SH_N * 2];
        for (int i = 0; i < CDL_SH_N * 2; i++)
            in[i] = 2.0f * cdl_rng_float(&r) - 1.0f;
        cdl_vec3 n = cdl_normalize(cdl_v3(cdl_rng_float(&r) - 0.5f, cdl_rng_float(&r) - 0.5f, cdl_rng_float(&r) - 0.5f));
        cdl_frame f = cdl_frame_from(n);
        cdl_sh_rotate(&rot, f, in, out, 2);
        for (int t = 0; t < 20; t++) {
            cdl_vec3 v = cdl_normalize(cdl_v3(cdl_rng_float(&r) - 0.5f, cdl_rng_float(&r) - 0.5f, cdl_rng_float(&r) - 0.5f));
            cdl_vec3 w = cdl_add(cdl_add(cdl_scale(f.t, v.x), cdl_scale(f.b, v.y)), cdl_scale(f.n, v.z));
            float yv[CDL_SH_N], yw[CDL_SH_N];
            cdl_sh_eval(v, yv);
            cdl_sh_eval(w, yw);
            for (int c = 0; c < 2; c++) {
                double a = 0.0, b = 0.0;
                for (int i = 0; i < CDL_SH_N; i++) {
                    a += out[i * 2 + c] * yv[i];
                    b += in[i * 2 + c] * yw[i];
                }
                worst = fmax(worst, fabs(a - b));
            }
        }
    }
    CHECK(worst < 1e-4, "rotated coefficients evaluate as the function at the rotated direction (error %.2g)", worst);
}

/* Incident radiance in the local frame (upper hemisphere). */
static double incident(cdl_vec3 w) { return 1.0 + 0.6 * w.x + 0.4 * w.z * w.z + 0.3 * w.y * w.x; }

static void bsdf_table(const char *what, const cdl_material *m, double tol_c, double tol_L)
{
    static cdl_bsdf_sh t;
    cdl_bsdf_sh_build(&t, m);
    cdl_vec3 kd = m->kd, nz = cdl_v3(0, 0, 1);
    cdl_bsdf b;
    cdl_bsdf_init(&b, m, kd, nz, nz);
    double worst_c = 0.0, worst_L = 0.0, scale = 0.0;
    for (int bin = 3; bin < CDL_BSDF_SH_BINS; bin += 7) {
        float co = (float)bin / (CDL_BSDF_SH_BINS - 1), so = sqrtf(1.0f - co * co);
        cdl_vec3 wo = cdl_v3(so, 0.0f, co);
        float c[CDL_SH_N * 3];
        cdl_bsdf_sh_lookup(&t, co, kd, c);
        /* dense quadrature over the upper hemisphere: c_lm (even extension),
         * lambda_lm of L cos, and the true reflected radiance */
        double cq[CDL_SH_N] = {0}, lam[CDL_SH_N] = {0}, Lr = 0.0;
        for (int i = 0; i < QM; i++)
            for (int j = 0; j < QP; j++) {
                double mu = (i + 0.5) / QM, phi = 2.0 * CDL_PI * (j + 0.5) / QP, s = sqrt(1.0 - mu * mu);
                cdl_vec3 wi = cdl_v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)mu);
                double dw = 2.0 * CDL_PI / ((double)QM * QP);
                double f = cdl_bsdf_eval(&b, wo, wi, 0).y, L = incident(wi);
                float y[CDL_SH_N], ym[CDL_SH_N];
                cdl_sh_eval(wi, y);
                cdl_sh_eval(cdl_v3(wi.x, wi.y, -wi.z), ym);
                for (int k = 0; k < CDL_SH_N; k++) {
                    cq[k] += f * (y[k] + ym[k]) * dw;
                    lam[k] += L * mu * y[k] * dw;
                }
                Lr += f * L * mu * dw;
            }
        double Lsh = 0.0;
        for (int k = 0; k < CDL_SH_N; k++) {
            worst_c = fmax(worst_c, fabs(c[k * 3 + 1] - cq[k]));
            scale = fmax(scale, fabs(cq[k]));
            Lsh += c[k * 3 + 1] * lam[k];
        }
        worst_L = fmax(worst_L, fabs(Lsh / Lr - 1.0));
    }
    CHECK(worst_c <= tol_c * scale && worst_L <= tol_L,
          "%s: table coefficients vs quadrature within %.3g of the largest (%.3g), reflected radiance within %.3g "
          "(%.3g)",
          what, worst_c / scale, tol_c, worst_L, tol_L);
}

int main(void)
{
    orthonormal();
    rotation();
    cdl_material d = cdl_material_default(CDL_MAT_DIFFUSE);
    d.kd = cdl_v3(0.6f, 0.5f, 0.4f);
    bsdf_table("Lambert", &d, 1e-2, 2e-3);
    cdl_material p = cdl_material_default(CDL_MAT_PHONG);
    p.kd = cdl_v3(0.3f, 0.3f, 0.3f);
    p.ks = cdl_v3(0.4f, 0.4f, 0.4f);
    p.ns = 8.0f;
    bsdf_table("Phong n = 8", &p, 2e-2, 0.1);
    cdl_material g = cdl_material_default(CDL_MAT_PLASTIC);
    g.kd = cdl_v3(0.4f, 0.4f, 0.4f);
    g.alpha_x = g.alpha_y = 0.3f;
    bsdf_table("GGX plastic, alpha 0.3", &g, 2e-2, 0.1);
    return test_failures ? 1 : 0;
}
