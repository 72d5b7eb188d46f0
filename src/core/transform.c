#include "core/transform.h"

#include <math.h>
#include <string.h>

cdl_mat4 cdl_mat4_identity(void)
{
    cdl_mat4 r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < 4; i++)
        r.m[i][i] = 1.0;
    return r;
}

cdl_mat4 cdl_mat4_from_pbrt(const double v[16])
{
    cdl_mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = v[4 * j + i];
    return r;
}

cdl_mat4 cdl_mat4_mul(const cdl_mat4 *a, const cdl_mat4 *b)
{
    cdl_mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] +
                        a->m[i][2] * b->m[2][j] + a->m[i][3] * b->m[3][j];
    return r;
}

cdl_mat4 cdl_mat4_transpose(const cdl_mat4 *a)
{
    cdl_mat4 r;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            r.m[i][j] = a->m[j][i];
    return r;
}

int cdl_mat4_is_finite(const cdl_mat4 *a)
{
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (!isfinite(a->m[i][j]))
                return 0;
    return 1;
}

/* Gauss-Jordan elimination with full pivoting, as pbrt-v3's Inverse(). */
int cdl_mat4_inverse(const cdl_mat4 *a, cdl_mat4 *inv)
{
    int indxc[4], indxr[4], ipiv[4] = {0, 0, 0, 0};
    double minv[4][4];
    memcpy(minv, a->m, sizeof minv);
    if (!cdl_mat4_is_finite(a))
        return -1;
    for (int i = 0; i < 4; i++) {
        int irow = 0, icol = 0;
        double big = 0.0;
        for (int j = 0; j < 4; j++) {
            if (ipiv[j] == 1)
                continue;
            for (int k = 0; k < 4; k++) {
                if (ipiv[k] == 0 && fabs(minv[j][k]) >= big) {
                    big = fabs(minv[j][k]);
                    irow = j;
                    icol = k;
                } else if (ipiv[k] > 1) {
                    return -1;
                }
            }
        }
        ++ipiv[icol];
        if (irow != icol)
            for (int k = 0; k < 4; ++k) {
                double t = minv[irow][k];
                minv[irow][k] = minv[icol][k];
                minv[icol][k] = t;
            }
        indxr[i] = irow;
        indxc[i] = icol;
        if (minv[icol][icol] == 0.0)
            return -1;
        double pivinv = 1.0 / minv[icol][icol];
        minv[icol][icol] = 1.0;
        for (int j = 0; j < 4; j++)
            minv[icol][j] *= pivinv;
        for (int j = 0; j < 4; j++) {
            if (j == icol)
                continue;
            double save = minv[j][icol];
            minv[j][icol] = 0;
            for (int k = 0; k < 4; k++)
                minv[j][k] -= minv[icol][k] * save;
        }
    }
    for (int j = 3; j >= 0; j--) {
        if (indxr[j] == indxc[j])
            continue;
        for (int k = 0; k < 4; k++) {
            double t = minv[k][indxr[j]];
            minv[k][indxr[j]] = minv[k][indxc[j]];
            minv[k][indxc[j]] = t;
        }
    }
    memcpy(inv->m, minv, sizeof minv);
    return cdl_mat4_is_finite(inv) ? 0 : -1;
}

double cdl_mat4_det3(const cdl_mat4 *a)
{
    const double(*m)[4] = a->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

int cdl_mat4_swaps_handedness(const cdl_mat4 *a)
{
    return cdl_mat4_det3(a) < 0.0;
}

cdl_mat4 cdl_mat4_translate(double x, double y, double z)
{
    cdl_mat4 r = cdl_mat4_identity();
    r.m[0][3] = x;
    r.m[1][3] = y;
    r.m[2][3] = z;
    return r;
}

cdl_mat4 cdl_mat4_scale(double x, double y, double z)
{
    cdl_mat4 r = cdl_mat4_identity();
    r.m[0][0] = x;
    r.m[1][1] = y;
    r.m[2][2] = z;
    return r;
}

int cdl_mat4_rotate(double theta, double ax, double ay, double az, cdl_mat4 *out)
{
    double len = sqrt(ax * ax + ay * ay + az * az);
    if (!(len > 0.0) || !isfinite(len) || !isfinite(theta))
        return -1;
    double x = ax / len, y = ay / len, z = az / len;
    double rad = theta * (3.14159265358979323846 / 180.0);
    double s = sin(rad), c = cos(rad);
    cdl_mat4 r = cdl_mat4_identity();
    r.m[0][0] = x * x + (1 - x * x) * c;
    r.m[0][1] = x * y * (1 - c) - z * s;
    r.m[0][2] = x * z * (1 - c) + y * s;
    r.m[1][0] = x * y * (1 - c) + z * s;
    r.m[1][1] = y * y + (1 - y * y) * c;
    r.m[1][2] = y * z * (1 - c) - x * s;
    r.m[2][0] = x * z * (1 - c) - y * s;
    r.m[2][1] = y * z * (1 - c) + x * s;
    r.m[2][2] = z * z + (1 - z * z) * c;
    *out = r;
    return 0;
}

static void cross3(const double a[3], const double b[3], double r[3])
{
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}

static int normalize3(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0) || !isfinite(l))
        return -1;
    v[0] /= l;
    v[1] /= l;
    v[2] /= l;
    return 0;
}

int cdl_mat4_lookat(const double eye[3], const double look[3], const double up[3], cdl_mat4 *out)
{
    double dir[3] = {look[0] - eye[0], look[1] - eye[1], look[2] - eye[2]};
    double u[3] = {up[0], up[1], up[2]}, right[3], nup[3];
    if (normalize3(dir) || normalize3(u))
        return -1;
    cross3(u, dir, right);
    if (normalize3(right))
        return -1; /* pbrt: "up vector and viewing direction are pointing in the same direction" */
    cross3(dir, right, nup);
    cdl_mat4 c2w = cdl_mat4_identity();
    for (int i = 0; i < 3; i++) {
        c2w.m[i][0] = right[i];
        c2w.m[i][1] = nup[i];
        c2w.m[i][2] = dir[i];
        c2w.m[i][3] = eye[i];
    }
    return cdl_mat4_inverse(&c2w, out);
}

void cdl_mat4_point(const cdl_mat4 *a, const double p[3], double out[3])
{
    double r[4];
    for (int i = 0; i < 4; i++)
        r[i] = a->m[i][0] * p[0] + a->m[i][1] * p[1] + a->m[i][2] * p[2] + a->m[i][3];
    if (r[3] != 1.0) {
        r[0] /= r[3];
        r[1] /= r[3];
        r[2] /= r[3];
    }
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

void cdl_mat4_vector(const cdl_mat4 *a, const double v[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = a->m[i][0] * v[0] + a->m[i][1] * v[1] + a->m[i][2] * v[2];
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

void cdl_mat4_normal(const cdl_mat4 *inv, const double n[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = inv->m[0][i] * n[0] + inv->m[1][i] * n[1] + inv->m[2][i] * n[2];
    out[0] = r[0];
    out[1] = r[1];
    out[2] = r[2];
}

cdl_vec3 cdl_mat4_point3(const cdl_mat4 *a, cdl_vec3 p)
{
    double in[3] = {p.x, p.y, p.z}, o[3];
    cdl_mat4_point(a, in, o);
    return cdl_v3((float)o[0], (float)o[1], (float)o[2]);
}

cdl_vec3 cdl_mat4_vector3(const cdl_mat4 *a, cdl_vec3 v)
{
    double in[3] = {v.x, v.y, v.z}, o[3];
    cdl_mat4_vector(a, in, o);
    return cdl_v3((float)o[0], (float)o[1], (float)o[2]);
}

int cdl_mat4_is_similarity(const cdl_mat4 *a, double tol, double *scale)
{
    const double(*m)[4] = a->m;
    if (m[3][0] != 0.0 || m[3][1] != 0.0 || m[3][2] != 0.0 || m[3][3] != 1.0)
        return 0;
    /* columns of the 3x3 part: orthogonal and of equal length */
    double g[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            g[i][j] = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
    double s2 = (g[0][0] + g[1][1] + g[2][2]) / 3.0;
    if (!(s2 > 0.0) || !isfinite(s2))
        return 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (fabs(g[i][j] - (i == j ? s2 : 0.0)) > tol * s2)
                return 0;
    *scale = sqrt(s2);
    return 1;
}
