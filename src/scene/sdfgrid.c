#include "scene/sdfgrid.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- the interpolant ------------------------------------------------------------------------- */

static double sample(const cdl_sdfgrid *g, int x, int y, int z)
{
    x = x < 0 ? 0 : x >= g->n[0] ? g->n[0] - 1 : x;
    y = y < 0 ? 0 : y >= g->n[1] ? g->n[1] - 1 : y;
    z = z < 0 ? 0 : z >= g->n[2] ? g->n[2] - 1 : z;
    return g->v[((size_t)z * (size_t)g->n[1] + (size_t)y) * (size_t)g->n[0] + (size_t)x];
}

/* Exact at t = 0 and t = 1, so two voxels agree bitwise on their shared face. */
static double lerp(double a, double b, double t)
{
    return a * (1.0 - t) + b * t;
}

/* f indexed x + 2y + 4z from the voxel's lower corner. */
static void corners(const cdl_sdfgrid *g, const int vox[3], double f[8])
{
    for (int i = 0; i < 8; i++)
        f[i] = sample(g, vox[0] + (i & 1), vox[1] + (i >> 1 & 1), vox[2] + (i >> 2));
}

static double trilerp(const double f[8], const double w[3])
{
    return lerp(lerp(lerp(f[0], f[1], w[0]), lerp(f[2], f[3], w[0]), w[1]),
                lerp(lerp(f[4], f[5], w[0]), lerp(f[6], f[7], w[0]), w[1]), w[2]);
}

/* Gradient in object space: each partial is the bilinear interpolant of
 * the differences along the four edges parallel to its axis. */
static void trigrad(const cdl_sdfgrid *g, const double f[8], const double w[3], double out[3])
{
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3, c = (a + 2) % 3, ba = 1 << a, bb = 1 << b, bc = 1 << c;
        double d[4];
        for (int i = 0; i < 4; i++) {
            int lo = (i & 1 ? bb : 0) | (i & 2 ? bc : 0);
            d[i] = f[lo | ba] - f[lo];
        }
        out[a] = lerp(lerp(d[0], d[1], w[b]), lerp(d[2], d[3], w[b]), w[c]) * (g->n[a] - 1);
    }
}

/* The voxel holding object-space p and p's place in it. */
static void locate(const cdl_sdfgrid *g, const double p[3], int vox[3], double w[3])
{
    for (int a = 0; a < 3; a++) {
        double s = (p[a] < 0.0 ? 0.0 : p[a] > 1.0 ? 1.0 : p[a]) * (g->n[a] - 1);
        int v = (int)floor(s);
        vox[a] = v > g->n[a] - 2 ? g->n[a] - 2 : v;
        w[a] = s - vox[a];
    }
}

double cdl_sdfgrid_eval(const cdl_sdfgrid *g, const double p[3], double grad[3])
{
    int vox[3];
    double w[3], f[8];
    locate(g, p, vox, w);
    corners(g, vox, f);
    if (grad)
        trigrad(g, f, w, grad);
    return trilerp(f, w);
}

static void normalize(double v[3])
{
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int a = 0; a < 3; a++)
        v[a] = l > 0.0 ? v[a] / l : 0.0;
}

/* Mitsuba's smooth normal: the eight voxels around the grid vertex nearest
 * to p each give a gradient of finite differences across the voxel along
 * one axis, taken at p's position along the other two (a bilinear
 * interpolant on a sample plane); their normalized values are blended
 * trilinearly by p's position relative to the voxel centres. Voxels below
 * the grid get weight zero; above it the difference vanishes (clamped
 * samples). */
static void smooth(const cdl_sdfgrid *g, const double p[3], double out[3])
{
    int v[3], cell[3];
    double s[3], uvw[3], w[3], d0[3], d1[3];
    for (int a = 0; a < 3; a++) {
        s[a] = p[a] * (g->n[a] - 1);
        v[a] = (int)nearbyint(s[a]) - 1;
        uvw[a] = s[a] - v[a] - 0.5;
        int cf = (int)floor(s[a]);
        cell[a] = cf < 0 ? 0 : cf > g->n[a] - 2 ? g->n[a] - 2 : cf;
        w[a] = s[a] - cell[a];
    }
    for (int a = 0; a < 3; a++) {
        int b = (a + 1) % 3, c = (a + 2) % 3, upper = cell[a] != v[a];
        double pl[3]; /* the plane interpolants at cell[a] + {0, 1} and the neighbour plane */
        int qs[3] = {cell[a], cell[a] + 1, cell[a] + (upper ? -1 : 2)};
        for (int k = 0; k < 3; k++) {
            double f[4];
            for (int i = 0; i < 4; i++) {
                int q[3];
                q[a] = qs[k];
                q[b] = cell[b] + (i & 1);
                q[c] = cell[c] + (i >> 1);
                f[i] = sample(g, q[0], q[1], q[2]);
            }
            pl[k] = lerp(lerp(f[0], f[1], w[b]), lerp(f[2], f[3], w[b]), w[c]);
        }
        double dc = pl[1] - pl[0], dq = upper ? pl[0] - pl[2] : pl[2] - pl[1];
        d0[a] = (upper ? dq : dc) * (g->n[a] - 1);
        d1[a] = (upper ? dc : dq) * (g->n[a] - 1);
    }
    int inside[3];
    for (int a = 0; a < 3; a++) {
        inside[a] = v[a] >= 0;
        if (!inside[a])
            uvw[a] = 1.0;
    }
    out[0] = out[1] = out[2] = 0.0;
    for (int i = 0; i < 8; i++) {
        int ok = 1;
        double n[3], wt = 1.0;
        for (int a = 0; a < 3; a++) {
            int hi = i >> a & 1;
            ok &= hi || inside[a];
            n[a] = hi ? d1[a] : d0[a];
            wt *= hi ? uvw[a] : 1.0 - uvw[a];
        }
        if (!ok)
            continue;
        normalize(n);
        for (int a = 0; a < 3; a++)
            out[a] += wt * n[a];
    }
    normalize(out);
}

void cdl_sdfgrid_normal(const cdl_sdfgrid *g, cdl_sdf_normals how, const double p[3], double out[3])
{
    if (how == CDL_SDF_SMOOTH) {
        smooth(g, p, out);
        return;
    }
    cdl_sdfgrid_eval(g, p, out);
    normalize(out);
}

int cdl_sdfgrid_default_levels(const cdl_sdfgrid *g)
{
    int m = g->n[0] > g->n[1] ? g->n[0] : g->n[1];
    m = m > g->n[2] ? m : g->n[2];
    int k = (128 + (m - 1) / 2) / (m - 1);
    return k < 1 ? 1 : k > 8 ? 8 : k;
}

/* ---- polygonization -------------------------------------------------------------------------- */

/* Vertex ids by key: 8 * (fine grid point) + the offset mask of an edge
 * from that point (0 for the point itself). Open addressing, key + 1
 * stored so that 0 marks a free slot. */
typedef struct vmap {
    uint64_t *keys;
    uint32_t *ids;
    size_t cap, used;
} vmap;

typedef struct builder {
    const cdl_sdfgrid *g;
    cdl_sdf_normals how;
    int k;
    uint64_t gn[3]; /* fine grid points per axis */
    size_t max_tris;
    vmap map;
    float *pos, *nrm;
    uint32_t *idx;
    size_t nv, nt, cap_v, cap_n, cap_t;
    int oom;
} builder;

static size_t hash(uint64_t k, size_t mask)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdull;
    k ^= k >> 33;
    return (size_t)k & mask;
}

static int vmap_grow(vmap *m)
{
    size_t cap = m->cap ? 2 * m->cap : 1u << 12;
    uint64_t *keys = calloc(cap, sizeof *keys);
    uint32_t *ids = malloc(cap * sizeof *ids);
    if (!keys || !ids) {
        free(keys);
        free(ids);
        return -1;
    }
    for (size_t i = 0; i < m->cap; i++)
        if (m->keys[i]) {
            size_t h = hash(m->keys[i], cap - 1);
            while (keys[h])
                h = (h + 1) & (cap - 1);
            keys[h] = m->keys[i];
            ids[h] = m->ids[i];
        }
    free(m->keys);
    free(m->ids);
    m->keys = keys;
    m->ids = ids;
    m->cap = cap;
    return 0;
}

/* The slot of key: found (*found = 1) or free for it. */
static size_t vmap_slot(const vmap *m, uint64_t key, int *found)
{
    size_t h = hash(key + 1, m->cap - 1);
    while (m->keys[h] && m->keys[h] != key + 1)
        h = (h + 1) & (m->cap - 1);
    *found = m->keys[h] != 0;
    return h;
}

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 1024;
    while (c < need)
        c *= 2;
    void *q = realloc(*p, c * elem);
    if (!q)
        return -1;
    *p = q;
    *cap = c;
    return 0;
}

/* A voxel being cut: its corner samples and the interpolant at its fine points. */
typedef struct voxel {
    int at[3];
    double f[8];
    double *fine; /* (k + 1)^3, x fastest */
} voxel;

static void local_point(const builder *b, const int c[3], double w[3])
{
    for (int a = 0; a < 3; a++)
        w[a] = (double)c[a] / b->k;
}

/* The vertex where the surface crosses the edge between fine points ca and
 * cb (local fine coordinates, cb >= ca componentwise) with values fa, fb of
 * opposite classes (< 0 and >= 0); UINT32_MAX when out of memory. */
static uint32_t edge_vertex(builder *b, const voxel *vx, const int ca[3], const int cb[3], double fa, double fb)
{
    const int *at = ca;
    int mask = 0;
    double s;
    if (fa == 0.0 || fb == 0.0) { /* the outside end lies on the surface */
        at = fa == 0.0 ? ca : cb;
        s = fa == 0.0 ? 0.0 : 1.0;
    } else {
        for (int a = 0; a < 3; a++)
            mask |= (cb[a] - ca[a]) << a;
        s = -1.0;
    }
    uint64_t gp[3];
    for (int a = 0; a < 3; a++)
        gp[a] = (uint64_t)vx->at[a] * (uint64_t)b->k + (uint64_t)at[a];
    uint64_t key = ((gp[2] * b->gn[1] + gp[1]) * b->gn[0] + gp[0]) * 8u + (uint64_t)mask;
    if (2 * (b->map.used + 1) > b->map.cap && vmap_grow(&b->map))
        return UINT32_MAX;
    int found;
    size_t slot = vmap_slot(&b->map, key, &found);
    if (found)
        return b->map.ids[slot];
    double wa[3], wb[3], w[3];
    local_point(b, ca, wa);
    local_point(b, cb, wb);
    if (s < 0.0) { /* bisection keeps the bracket; 40 halvings reach 1e-12 of the edge */
        double lo = 0.0, hi = 1.0;
        int neg_lo = fa < 0.0;
        for (int it = 0; it < 40; it++) {
            double mid = 0.5 * (lo + hi);
            for (int a = 0; a < 3; a++)
                w[a] = lerp(wa[a], wb[a], mid);
            if ((trilerp(vx->f, w) < 0.0) == neg_lo)
                lo = mid;
            else
                hi = mid;
        }
        s = 0.5 * (lo + hi);
    }
    if (b->nv >= UINT32_MAX - 1 || grow((void **)&b->pos, &b->cap_v, 3 * (b->nv + 1), sizeof(float)) ||
        grow((void **)&b->nrm, &b->cap_n, 3 * (b->nv + 1), sizeof(float)))
        return UINT32_MAX;
    double p[3], n[3];
    for (int a = 0; a < 3; a++) {
        w[a] = lerp(wa[a], wb[a], s);
        p[a] = (vx->at[a] + w[a]) / (b->g->n[a] - 1);
    }
    if (b->how == CDL_SDF_SMOOTH) {
        smooth(b->g, p, n);
    } else {
        trigrad(b->g, vx->f, w, n);
        normalize(n);
    }
    for (int a = 0; a < 3; a++) {
        b->pos[3 * b->nv + a] = (float)p[a];
        b->nrm[3 * b->nv + a] = (float)n[a];
    }
    b->map.keys[slot] = key + 1;
    b->map.ids[slot] = (uint32_t)b->nv;
    b->map.used++;
    return (uint32_t)b->nv++;
}

/* Appends triangle (i0, i1, i2) facing from `in` towards `out` (object
 * space); a triangle with a repeated vertex is dropped. */
static int emit(builder *b, uint32_t i0, uint32_t i1, uint32_t i2, const double in[3], const double out[3])
{
    if (i0 == i1 || i1 == i2 || i2 == i0)
        return 0;
    if (b->nt >= b->max_tris)
        return 1;
    const float *p0 = b->pos + 3 * (size_t)i0, *p1 = b->pos + 3 * (size_t)i1, *p2 = b->pos + 3 * (size_t)i2;
    double e1[3], e2[3], d = 0.0;
    for (int a = 0; a < 3; a++)
        e1[a] = (double)p1[a] - p0[a], e2[a] = (double)p2[a] - p0[a];
    for (int a = 0; a < 3; a++)
        d += (e1[(a + 1) % 3] * e2[(a + 2) % 3] - e1[(a + 2) % 3] * e2[(a + 1) % 3]) * (out[a] - in[a]);
    if (grow((void **)&b->idx, &b->cap_t, 3 * (b->nt + 1), sizeof(uint32_t)))
        return -1;
    uint32_t *t = b->idx + 3 * b->nt++;
    t[0] = i0;
    t[1] = d < 0.0 ? i2 : i1;
    t[2] = d < 0.0 ? i1 : i2;
    return 0;
}

/* Centroid of the tetrahedron corners in `set` (object space). */
static void centroid(const builder *b, const voxel *vx, const int (*c)[3], const int *set, int n, double out[3])
{
    for (int a = 0; a < 3; a++) {
        double s = 0.0;
        for (int i = 0; i < n; i++)
            s += vx->at[a] + (double)c[set[i]][a] / b->k;
        out[a] = s / n / (b->g->n[a] - 1);
    }
}

/* The surface in one tetrahedron (corners c, values f): a triangle when
 * one corner is alone on its side, a quad when two and two. */
static int tetra(builder *b, const voxel *vx, const int (*c)[3], const double *f)
{
    int in[4], out[4], ni = 0, no = 0;
    for (int i = 0; i < 4; i++) {
        if (f[i] < 0.0)
            in[ni++] = i;
        else
            out[no++] = i;
    }
    if (ni == 0 || no == 0)
        return 0;
    double pin[3], pout[3];
    centroid(b, vx, c, in, ni, pin);
    centroid(b, vx, c, out, no, pout);
    uint32_t v[4];
    int ne = 0;
    /* edges in cyclic order around the lone corner, or around the quad */
    int pairs[4][2];
    if (ni == 2) {
        int q[4][2] = {{in[0], out[0]}, {in[0], out[1]}, {in[1], out[1]}, {in[1], out[0]}};
        memcpy(pairs, q, sizeof q);
        ne = 4;
    } else {
        int lone = ni == 1 ? in[0] : out[0];
        const int *rest = ni == 1 ? out : in;
        for (int i = 0; i < 3; i++)
            pairs[i][0] = lone, pairs[i][1] = rest[i];
        ne = 3;
    }
    for (int e = 0; e < ne; e++) {
        int i = pairs[e][0], j = pairs[e][1];
        /* the corner order of a Kuhn tetrahedron is monotone: the lower index is the lower point */
        int lo = i < j ? i : j, hi = i < j ? j : i;
        if ((v[e] = edge_vertex(b, vx, c[lo], c[hi], f[lo], f[hi])) == UINT32_MAX)
            return -1;
    }
    int rc = emit(b, v[0], v[1], v[2], pin, pout);
    if (!rc && ne == 4)
        rc = emit(b, v[0], v[2], v[3], pin, pout);
    return rc;
}

static int cut_voxel(builder *b, voxel *vx)
{
    const int k = b->k, k1 = k + 1;
    for (int l = 0; l <= k; l++)
        for (int j = 0; j <= k; j++)
            for (int i = 0; i <= k; i++) {
                int c[3] = {i, j, l};
                double w[3];
                local_point(b, c, w);
                vx->fine[((size_t)l * k1 + j) * k1 + i] = trilerp(vx->f, w);
            }
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int l = 0; l < k; l++)
        for (int j = 0; j < k; j++)
            for (int i = 0; i < k; i++)
                for (int t = 0; t < 6; t++) {
                    /* the path (i, j, l) -> +e_a -> +e_b -> +e_c: Kuhn's tetrahedra, one per axis order */
                    int c[4][3] = {{i, j, l}};
                    double f[4];
                    for (int s = 1; s < 4; s++) {
                        memcpy(c[s], c[s - 1], sizeof c[s]);
                        c[s][perm[t][s - 1]]++;
                    }
                    for (int s = 0; s < 4; s++)
                        f[s] = vx->fine[((size_t)c[s][2] * k1 + c[s][1]) * k1 + c[s][0]];
                    int rc = tetra(b, vx, (const int(*)[3])c, f);
                    if (rc)
                        return rc;
                }
    return 0;
}

int cdl_sdfgrid_polygonize(const cdl_sdfgrid *g, int levels, cdl_sdf_normals how, size_t max_tris, cdl_mesh *m,
                           const char *file, int line, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    if (levels < 1 || levels > 64)
        return cdl_error_set(err, CDL_ERR_USAGE, file, line, "sdfgrid: %d subdivisions per voxel (1 to 64)", levels);
    for (int a = 0; a < 3; a++)
        if (g->n[a] < 2)
            return cdl_error_set(err, CDL_ERR_INPUT, file, line, "sdfgrid: %d samples along an axis (at least 2)",
                                 g->n[a]);
    builder b;
    memset(&b, 0, sizeof b);
    b.g = g;
    b.how = how;
    b.k = levels;
    b.max_tris = max_tris < UINT32_MAX / 3 ? max_tris : UINT32_MAX / 3;
    for (int a = 0; a < 3; a++)
        b.gn[a] = (uint64_t)(g->n[a] - 1) * (uint64_t)levels + 1;
    voxel vx;
    vx.fine = malloc(sizeof(double) * (size_t)(levels + 1) * (levels + 1) * (levels + 1));
    int rc = vx.fine ? 0 : -1;
    for (int z = 0; z < g->n[2] - 1 && !rc; z++)
        for (int y = 0; y < g->n[1] - 1 && !rc; y++)
            for (int x = 0; x < g->n[0] - 1 && !rc; x++) {
                vx.at[0] = x, vx.at[1] = y, vx.at[2] = z;
                corners(g, vx.at, vx.f);
                int nonneg = 0, nonpos = 0;
                for (int i = 0; i < 8; i++)
                    nonneg |= vx.f[i] >= 0.0, nonpos |= vx.f[i] <= 0.0;
                if (nonneg && nonpos) /* Mitsuba's occupied voxels */
                    rc = cut_voxel(&b, &vx);
            }
    free(vx.fine);
    free(b.map.keys);
    free(b.map.ids);
    if (!rc && b.nt == 0)
        rc = cdl_error_set(err, CDL_ERR_INPUT, file, line, "sdfgrid: no surface (no sign change in any voxel)");
    else if (rc > 0)
        rc = cdl_error_set(err, CDL_ERR_INPUT, file, line,
                           "sdfgrid: more than %zu triangles at %d subdivisions per voxel", b.max_tris, levels);
    else if (rc < 0)
        rc = cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "sdfgrid: out of memory");
    if (rc) {
        free(b.pos);
        free(b.nrm);
        free(b.idx);
        return rc;
    }
    m->nverts = (uint32_t)b.nv;
    m->ntris = (uint32_t)b.nt;
    m->pos = b.pos;
    m->nrm = b.nrm;
    m->idx = b.idx;
    return 0;
}
