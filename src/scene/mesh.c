/* Mesh insertion as pbrt-v3 orients triangles: area lights emit from the
 * front face only, so the orientation rule decides what a scene shows. */
#define _POSIX_C_SOURCE 200809L
#include "scene/mesh.h"

#include "scene/attr.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SPHERE_NPHI 96
#define SPHERE_NTHETA 48
#define PI 3.14159265358979323846

int cdl_mesh_alloc(cdl_mesh *m, uint32_t nverts, uint32_t ntris, int has_n, int has_uv, const char *file,
                   int line, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    m->nverts = nverts;
    m->ntris = ntris;
    m->pos = malloc(sizeof(float) * 3 * (size_t)(nverts ? nverts : 1));
    m->idx = malloc(sizeof(uint32_t) * 3 * (size_t)(ntris ? ntris : 1));
    m->nrm = has_n ? malloc(sizeof(float) * 3 * (size_t)(nverts ? nverts : 1)) : NULL;
    m->uv = has_uv ? malloc(sizeof(float) * 2 * (size_t)(nverts ? nverts : 1)) : NULL;
    if (!m->pos || !m->idx || (has_n && !m->nrm) || (has_uv && !m->uv)) {
        cdl_mesh_free(m);
        return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory");
    }
    return 0;
}

void cdl_mesh_free(cdl_mesh *m)
{
    free(m->pos);
    free(m->nrm);
    free(m->uv);
    free(m->idx);
    for (int i = 0; i < m->nattrs; i++)
        free(m->attrs[i].data);
    free(m->attrs);
    memset(m, 0, sizeof *m);
}

cdl_mesh_attr *cdl_mesh_add_attr(cdl_mesh *m, const char *name, int per_face, int dim)
{
    cdl_mesh_attr *a = realloc(m->attrs, sizeof *a * (size_t)(m->nattrs + 1));
    if (!a)
        return NULL;
    m->attrs = a;
    a += m->nattrs;
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%s", name);
    a->per_face = per_face;
    a->dim = dim;
    size_t n = per_face ? m->ntris : m->nverts;
    if (!(a->data = calloc(n ? n * (size_t)dim : 1, sizeof(float))))
        return NULL;
    m->nattrs++;
    return a;
}

int cdl_mesh_sphere(cdl_mesh *m, double r, int flip, const char *file, int line, cdl_error *err)
{
    const int np = SPHERE_NPHI, nth = SPHERE_NTHETA;
    int rc = cdl_mesh_alloc(m, (uint32_t)((np + 1) * (nth + 1)), (uint32_t)(2 * np * nth), 1, 1, file, line, err);
    if (rc)
        return rc;
    float s = flip ? -1.0f : 1.0f;
    for (int j = 0, v = 0; j <= nth; j++) {
        double th = PI * j / nth;
        /* exact poles: their fans degenerate and are dropped, not slivers */
        double st = j == 0 || j == nth ? 0.0 : sin(th), ct = j == 0 ? 1.0 : j == nth ? -1.0 : cos(th);
        for (int i = 0; i <= np; i++, v++) {
            double ph = 2.0 * PI * i / np;
            double n[3] = {st * cos(ph), st * sin(ph), ct};
            for (int k = 0; k < 3; k++) {
                m->pos[3 * v + k] = (float)(r * n[k]);
                m->nrm[3 * v + k] = s * (float)n[k];
            }
            /* pbrt's sphere (u, v): u = phi / 2pi, v = 0 at z = -r */
            m->uv[2 * v] = (float)i / (float)np;
            m->uv[2 * v + 1] = 1.0f - (float)j / (float)nth;
        }
    }
    uint32_t *t = m->idx;
    for (int j = 0; j < nth; j++)
        for (int i = 0; i < np; i++) {
            uint32_t v00 = (uint32_t)(j * (np + 1) + i), v01 = v00 + 1;
            uint32_t v10 = v00 + (uint32_t)(np + 1), v11 = v10 + 1;
            if (j < nth - 1)
                *t++ = v00, *t++ = v10, *t++ = v11;
            if (j > 0)
                *t++ = v00, *t++ = v11, *t++ = v01;
        }
    m->ntris = (uint32_t)((t - m->idx) / 3);
    return 0;
}

int cdl_mesh_disk(cdl_mesh *m, double h, double r, double ri, double phimax, int nseg, const char *file, int line,
                  cdl_error *err)
{
    int ring = ri > 0.0, nv = (nseg + 1) * (ring ? 2 : 1) + !ring;
    int rc = cdl_mesh_alloc(m, (uint32_t)nv, (uint32_t)(nseg * (ring ? 2 : 1)), 0, 1, file, line, err);
    if (rc)
        return rc;
    /* outer ring, then the inner ring or the centre; pbrt's (u, v) =
     * (phi / phimax, (r - rho) / (r - ri)) */
    for (int k = 0; k <= (ring ? 1 : 0); k++)
        for (int i = 0; i <= nseg; i++) {
            double ph = phimax * i / nseg, rho = k ? ri : r;
            int v = k * (nseg + 1) + i;
            m->pos[3 * v] = (float)(rho * cos(ph));
            m->pos[3 * v + 1] = (float)(rho * sin(ph));
            m->pos[3 * v + 2] = (float)h;
            m->uv[2 * v] = (float)i / (float)nseg;
            m->uv[2 * v + 1] = k ? 1.0f : 0.0f;
        }
    uint32_t c = (uint32_t)(nseg + 1), *t = m->idx;
    if (!ring) {
        m->pos[3 * c] = m->pos[3 * c + 1] = 0.0f;
        m->pos[3 * c + 2] = (float)h;
        m->uv[2 * c] = 0.0f;
        m->uv[2 * c + 1] = 1.0f;
    }
    for (uint32_t i = 0; i < (uint32_t)nseg; i++) { /* counter-clockwise seen from +z */
        if (!ring) {
            *t++ = c, *t++ = i, *t++ = i + 1;
        } else {
            *t++ = i, *t++ = i + 1, *t++ = c + i + 1;
            *t++ = i, *t++ = c + i + 1, *t++ = c + i;
        }
    }
    return 0;
}

int cdl_mesh_cylinder(cdl_mesh *m, double r, double zmin, double zmax, double phimax, int nseg, const char *file,
                      int line, cdl_error *err)
{
    int rc = cdl_mesh_alloc(m, (uint32_t)(2 * (nseg + 1)), (uint32_t)(2 * nseg), 0, 1, file, line, err);
    if (rc)
        return rc;
    for (int k = 0; k < 2; k++)
        for (int i = 0; i <= nseg; i++) {
            double ph = phimax * i / nseg;
            int v = k * (nseg + 1) + i;
            m->pos[3 * v] = (float)(r * cos(ph));
            m->pos[3 * v + 1] = (float)(r * sin(ph));
            m->pos[3 * v + 2] = (float)(k ? zmax : zmin);
            m->uv[2 * v] = (float)i / (float)nseg; /* pbrt's (phi / phimax, (z - zmin) / (zmax - zmin)) */
            m->uv[2 * v + 1] = (float)k;
        }
    uint32_t c = (uint32_t)(nseg + 1), *t = m->idx;
    for (uint32_t i = 0; i < (uint32_t)nseg; i++) { /* counter-clockwise seen from outside */
        *t++ = i, *t++ = i + 1, *t++ = c + i + 1;
        *t++ = i, *t++ = c + i + 1, *t++ = c + i;
    }
    return 0;
}

static int same_point(const float *a, const float *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

int cdl_scene_add_mesh(cdl_scene *s, const cdl_mesh *m, const cdl_mat4 *xf, int reverse, uint32_t mat,
                       int32_t emit, const char *file, int line, cdl_error *err)
{
    cdl_mat4 inv;
    if (m->nrm && cdl_mat4_inverse(xf, &inv))
        return cdl_error_set(err, CDL_ERR_INPUT, file, line, "the shape's transform is singular");
    float *p = malloc(sizeof(float) * 3 * (size_t)(m->nverts ? m->nverts : 1));
    float *n = m->nrm ? malloc(sizeof(float) * 3 * (size_t)(m->nverts ? m->nverts : 1)) : NULL;
    if (!p || (m->nrm && !n)) {
        free(p);
        free(n);
        return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory");
    }
    int rc = 0;
    for (uint32_t i = 0; i < m->nverts && !rc; i++) {
        double in[3] = {m->pos[3 * i], m->pos[3 * i + 1], m->pos[3 * i + 2]}, o[3];
        cdl_mat4_point(xf, in, o);
        for (int k = 0; k < 3; k++) {
            if (!isfinite(o[k]) || fabs(o[k]) > CDL_MAX_COORD)
                rc = cdl_error_set(err, CDL_ERR_INPUT, file, line,
                                   "vertex %u is transformed to (%g, %g, %g): not finite or beyond 1e20", i, o[0],
                                   o[1], o[2]);
            p[3 * i + k] = (float)o[k];
        }
        if (n) {
            double nin[3] = {m->nrm[3 * i], m->nrm[3 * i + 1], m->nrm[3 * i + 2]}, no[3];
            cdl_mat4_normal(&inv, nin, no);
            double l = sqrt(no[0] * no[0] + no[1] * no[1] + no[2] * no[2]);
            for (int k = 0; k < 3; k++)
                n[3 * i + k] = l > 0.0 && isfinite(l) ? (float)(no[k] / l) : 0.0f;
        }
    }
    uint32_t first = 0;
    if (!rc)
        rc = cdl_error_place(err, cdl_scene_add_vertices(s, m->nverts, p, n, m->uv, &first, err), s->path, file, line);
    /* the scene triangle of each mesh triangle, for face attributes (not
     * kept inside a shape group, whose triangles move on closing) */
    uint32_t *tri_of = NULL;
    if (!rc && m->nattrs) {
        if (!(tri_of = malloc(sizeof *tri_of * (m->ntris ? m->ntris : 1))))
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory");
        for (uint32_t t = 0; tri_of && t < m->ntris; t++)
            tri_of[t] = UINT32_MAX;
    }
    int flip_all = reverse ^ cdl_mat4_swaps_handedness(xf);
    uint8_t flags = (uint8_t)((n ? CDL_TRI_HAS_N : 0) | (m->uv ? CDL_TRI_HAS_UV : 0));
    for (uint32_t t = 0; t < m->ntris && !rc; t++) {
        uint32_t a = m->idx[3 * t], b = m->idx[3 * t + 1], d = m->idx[3 * t + 2];
        if (a >= m->nverts || b >= m->nverts || d >= m->nverts) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, file, line, "triangle %u: vertex index out of range", t);
            break;
        }
        int flip = flip_all;
        const float *pa = p + 3 * (size_t)a, *pb = p + 3 * (size_t)b, *pd = p + 3 * (size_t)d;
        /* two equal corners: no area (the scene's cross-product test can
         * miss this when the compiler contracts it into FMAs) */
        if (same_point(pa, pb) || same_point(pb, pd) || same_point(pa, pd))
            continue;
        if (n) {
            cdl_vec3 e1 = cdl_v3(pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]);
            cdl_vec3 e2 = cdl_v3(pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]);
            cdl_vec3 sum = cdl_v3(0, 0, 0);
            for (int k = 0; k < 3; k++) {
                const float *nk = n + 3 * (size_t)m->idx[3 * t + k];
                sum = cdl_add(sum, cdl_v3(nk[0], nk[1], nk[2]));
            }
            flip = cdl_dot(cdl_cross(e1, e2), sum) < 0.0f;
        }
        if (flip) {
            uint32_t tmp = b;
            b = d;
            d = tmp;
        }
        uint32_t before = s->ntris;
        rc = cdl_error_place(err, cdl_scene_add_triangle(s, first + a, first + b, first + d, mat, emit, flags, err),
                             s->path, file, line);
        if (tri_of && s->ntris > before && s->open_group < 0)
            tri_of[t] = before;
    }
    if (!rc && tri_of)
        rc = cdl_scene_add_attrs(s, m, first, tri_of, file, line, err);
    free(tri_of);
    free(p);
    free(n);
    return rc;
}
