#include "core/sh.h"

#include <math.h>
#include <string.h>

void cdl_sh_eval(cdl_vec3 d, float y[CDL_SH_N])
{
    float x = d.x, yy = d.y, z = d.z, z2 = z * z;
    y[0] = 0.282094792f;
    y[1] = 0.488602512f * yy;
    y[2] = 0.488602512f * z;
    y[3] = 0.488602512f * x;
    y[4] = 1.092548431f * x * yy;
    y[5] = 1.092548431f * yy * z;
    y[6] = 0.315391565f * (3.0f * z2 - 1.0f);
    y[7] = 1.092548431f * x * z;
    y[8] = 0.546274215f * (x * x - yy * yy);
    y[9] = 0.590043590f * yy * (3.0f * x * x - yy * yy);
    y[10] = 2.890611442f * x * yy * z;
    y[11] = 0.457045799f * yy * (5.0f * z2 - 1.0f);
    y[12] = 0.373176333f * z * (5.0f * z2 - 3.0f);
    y[13] = 0.457045799f * x * (5.0f * z2 - 1.0f);
    y[14] = 1.445305721f * z * (x * x - yy * yy);
    y[15] = 0.590043590f * x * (x * x - 3.0f * yy * yy);
}

/* Inverts the n x n matrix a in place (Gauss-Jordan, partial pivoting);
 * returns the smallest pivot's magnitude. */
static double invert(double a[7][7], int n)
{
    double inv[7][7], piv = INFINITY;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            inv[i][j] = i == j;
    for (int c = 0; c < n; c++) {
        int p = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        for (int j = 0; j < n; j++) {
            double t = a[c][j];
            a[c][j] = a[p][j];
            a[p][j] = t;
            t = inv[c][j];
            inv[c][j] = inv[p][j];
            inv[p][j] = t;
        }
        double d = a[c][c];
        piv = fabs(d) < piv ? fabs(d) : piv;
        if (d == 0.0)
            return 0.0;
        for (int j = 0; j < n; j++) {
            a[c][j] /= d;
            inv[c][j] /= d;
        }
        for (int r = 0; r < n; r++) {
            if (r == c)
                continue;
            double f = a[r][c];
            for (int j = 0; j < n; j++) {
                a[r][j] -= f * a[c][j];
                inv[r][j] -= f * inv[c][j];
            }
        }
    }
    memcpy(a, inv, sizeof inv);
    return piv;
}

int cdl_sh_rot_init(cdl_sh_rot *r)
{
    memset(r, 0, sizeof *r);
    for (int l = 0; l < CDL_SH_BANDS; l++) {
        int n = 2 * l + 1, o = l * l;
        double a[7][7] = {{0}};
        for (int j = 0; j < n; j++) {
            /* a spiral over the sphere, tilted so no direction is a pole */
            double z = 1.0 - 2.0 * (j + 0.5) / n, s = sqrt(1.0 - z * z), phi = 2.399963 * j + 0.7 * l + 0.3;
            cdl_vec3 u = cdl_normalize(cdl_v3((float)(s * cos(phi)), (float)(s * sin(phi)), (float)(0.9 * z + 0.1)));
            r->u[o + j] = u;
            float y[CDL_SH_N];
            cdl_sh_eval(u, y);
            for (int k = 0; k < n; k++)
                a[j][k] = y[o + k];
        }
        if (!(invert(a, n) > 1e-6))
            return -1;
        for (int k = 0; k < n; k++)
            for (int j = 0; j < n; j++)
                r->inv[o + k][j] = (float)a[k][j];
    }
    return 0;
}

void cdl_sh_rotate(const cdl_sh_rot *r, cdl_frame f, const float *in, float *out, int nc)
{
    for (int l = 0; l < CDL_SH_BANDS; l++) {
        int n = 2 * l + 1, o = l * l;
        float g[7][4]; /* band l of g at M u_j, per channel (nc <= 4) */
        for (int j = 0; j < n; j++) {
            cdl_vec3 u = r->u[o + j];
            cdl_vec3 w = cdl_add(cdl_add(cdl_scale(f.t, u.x), cdl_scale(f.b, u.y)), cdl_scale(f.n, u.z));
            float y[CDL_SH_N];
            cdl_sh_eval(w, y);
            for (int c = 0; c < nc; c++) {
                float s = 0.0f;
                for (int k = 0; k < n; k++)
                    s += in[(o + k) * nc + c] * y[o + k];
                g[j][c] = s;
            }
        }
        for (int k = 0; k < n; k++)
            for (int c = 0; c < nc; c++) {
                float s = 0.0f;
                for (int j = 0; j < n; j++)
                    s += r->inv[o + k][j] * g[j][c];
                out[(o + k) * nc + c] = s;
            }
    }
}
