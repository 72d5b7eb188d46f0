#include "scene/subdiv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Levels multiply the triangles by 4 each; under the fuzzer (ASan, 20 s per
 * input) a tetrahedron at level 12 would pass for a hang. */
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
#define SUBDIV_MAX_TRIS (1u << 16)
#else
#define SUBDIV_MAX_TRIS (1u << 30)
#endif

typedef struct half {
    uint64_t key;   /* min << 32 | max of the endpoints */
    uint32_t tri_k; /* 3 * triangle + k: edge k runs from corner k to k+1 */
} half;

/* The mesh's unique edges and what the rules need of each vertex. */
typedef struct adjacency {
    uint32_t ne;
    uint32_t *ends;   /* 2 per edge */
    uint32_t *opp;    /* 2 per edge: the opposite corners (first two faces) */
    uint32_t *nfaces; /* per edge */
    uint32_t *edge;   /* 3 per triangle: edge of side k */
    uint32_t *valence, *nbound; /* per vertex: edges, boundary edges */
    double *nsum, *bsum;        /* per vertex: 3 each, neighbours' and boundary neighbours' sums */
} adjacency;

static int cmp_half(const void *a, const void *b)
{
    uint64_t x = ((const half *)a)->key, y = ((const half *)b)->key;
    return x < y ? -1 : x > y;
}

static void adjacency_free(adjacency *a)
{
    free(a->ends);
    free(a->opp);
    free(a->nfaces);
    free(a->edge);
    free(a->valence);
    free(a->nbound);
    free(a->nsum);
    free(a->bsum);
    memset(a, 0, sizeof *a);
}

static int adjacency_build(adjacency *a, const double *p, uint32_t nv, const uint32_t *idx, uint32_t nt)
{
    memset(a, 0, sizeof *a);
    size_t nh = 3 * (size_t)nt;
    half *h = malloc(nh * sizeof *h);
    a->ends = malloc(nh * 2 * sizeof *a->ends);
    a->opp = malloc(nh * 2 * sizeof *a->opp);
    a->nfaces = calloc(nh, sizeof *a->nfaces);
    a->edge = malloc(nh * sizeof *a->edge);
    a->valence = calloc(nv, sizeof *a->valence);
    a->nbound = calloc(nv, sizeof *a->nbound);
    a->nsum = calloc(3 * (size_t)nv, sizeof *a->nsum);
    a->bsum = calloc(3 * (size_t)nv, sizeof *a->bsum);
    if (!h || !a->ends || !a->opp || !a->nfaces || !a->edge || !a->valence || !a->nbound || !a->nsum || !a->bsum) {
        free(h);
        adjacency_free(a);
        return -1;
    }
    for (size_t i = 0; i < nh; i++) {
        uint64_t u = idx[i], v = idx[i % 3 == 2 ? i - 2 : i + 1];
        h[i] = (half){u < v ? u << 32 | v : v << 32 | u, (uint32_t)i};
    }
    qsort(h, nh, sizeof *h, cmp_half);
    uint32_t ne = 0;
    for (size_t i = 0; i < nh; i++) {
        if (i == 0 || h[i].key != h[i - 1].key) {
            a->ends[2 * ne] = (uint32_t)(h[i].key >> 32);
            a->ends[2 * ne + 1] = (uint32_t)h[i].key;
            ne++;
        }
        uint32_t e = ne - 1, t = h[i].tri_k / 3, k = h[i].tri_k % 3;
        if (a->nfaces[e] < 2)
            a->opp[2 * e + a->nfaces[e]] = idx[3 * t + (k + 2) % 3];
        a->nfaces[e]++;
        a->edge[h[i].tri_k] = e;
    }
    free(h);
    a->ne = ne;
    for (uint32_t e = 0; e < ne; e++) {
        uint32_t u = a->ends[2 * e], v = a->ends[2 * e + 1];
        int boundary = a->nfaces[e] != 2;
        a->valence[u]++, a->valence[v]++;
        for (int c = 0; c < 3; c++) {
            a->nsum[3 * u + c] += p[3 * v + c];
            a->nsum[3 * v + c] += p[3 * u + c];
            if (boundary) {
                a->bsum[3 * u + c] += p[3 * v + c];
                a->bsum[3 * v + c] += p[3 * u + c];
            }
        }
        if (boundary)
            a->nbound[u]++, a->nbound[v]++;
    }
    return 0;
}

static double beta(uint32_t n)
{
    return n == 3 ? 3.0 / 16.0 : 3.0 / (8.0 * n);
}

/* Vertex v's new position: limit = 0 for the even-vertex rule, 1 for the
 * limit position. A corner (one or more than two boundary edges) stays. */
static void vertex_rule(const adjacency *a, const double *p, uint32_t v, int limit, double *out)
{
    uint32_t n = a->valence[v], nb = a->nbound[v];
    double w = 0.0, wn = 0.0;
    const double *sum = a->nsum;
    if (nb == 0 && n > 0) {
        double b = beta(n);
        wn = limit ? 1.0 / (n + 3.0 / (8.0 * b)) : b;
        w = 1.0 - n * wn;
    } else if (nb == 2) {
        sum = a->bsum;
        wn = limit ? 0.2 : 0.125;
        w = 1.0 - 2.0 * wn;
    } else {
        w = 1.0;
    }
    for (int c = 0; c < 3; c++)
        out[c] = w * p[3 * v + c] + wn * sum[3 * v + c];
}

int cdl_mesh_loop_subdivide(cdl_mesh *m, int levels, const char *file, int line, cdl_error *err)
{
    uint32_t nv = m->nverts, nt = m->ntris;
    double *p = malloc(3 * (size_t)nv * sizeof *p);
    uint32_t *idx = malloc(3 * (size_t)nt * sizeof *idx);
    adjacency a = {0};
    if (!p || !idx)
        goto oom;
    for (size_t i = 0; i < 3 * (size_t)nv; i++)
        p[i] = m->pos[i];
    memcpy(idx, m->idx, 3 * (size_t)nt * sizeof *idx);
    for (int level = 0; level < levels; level++) {
        if ((uint64_t)nt * 4 > SUBDIV_MAX_TRIS)
            return free(p), free(idx),
                   cdl_error_set(err, CDL_ERR_INPUT, file, line,
                                 "loopsubdiv: %d levels of %u triangles make more than %u", levels, m->ntris,
                                 SUBDIV_MAX_TRIS);
        if (adjacency_build(&a, p, nv, idx, nt))
            goto oom;
        uint32_t nv2 = nv + a.ne, nt2 = 4 * nt;
        double *p2 = malloc(3 * (size_t)nv2 * sizeof *p2);
        uint32_t *idx2 = malloc(3 * (size_t)nt2 * sizeof *idx2);
        if (!p2 || !idx2) {
            free(p2);
            free(idx2);
            goto oom;
        }
        for (uint32_t v = 0; v < nv; v++)
            vertex_rule(&a, p, v, 0, p2 + 3 * (size_t)v);
        for (uint32_t e = 0; e < a.ne; e++) {
            const double *u = p + 3 * (size_t)a.ends[2 * e], *v = p + 3 * (size_t)a.ends[2 * e + 1];
            double *o = p2 + 3 * (size_t)(nv + e);
            if (a.nfaces[e] == 2) {
                const double *c = p + 3 * (size_t)a.opp[2 * e], *d = p + 3 * (size_t)a.opp[2 * e + 1];
                for (int k = 0; k < 3; k++)
                    o[k] = 0.375 * (u[k] + v[k]) + 0.125 * (c[k] + d[k]);
            } else {
                for (int k = 0; k < 3; k++)
                    o[k] = 0.5 * (u[k] + v[k]);
            }
        }
        /* each triangle (a, b, c) with edge points ab, bc, ca becomes four,
         * wound as it was */
        for (uint32_t t = 0; t < nt; t++) {
            uint32_t v0 = idx[3 * t], v1 = idx[3 * t + 1], v2 = idx[3 * t + 2];
            uint32_t e01 = nv + a.edge[3 * t], e12 = nv + a.edge[3 * t + 1], e20 = nv + a.edge[3 * t + 2];
            uint32_t *o = idx2 + 12 * (size_t)t;
            uint32_t q[12] = {v0, e01, e20, v1, e12, e01, v2, e20, e12, e01, e12, e20};
            memcpy(o, q, sizeof q);
        }
        adjacency_free(&a);
        free(p);
        free(idx);
        p = p2, idx = idx2, nv = nv2, nt = nt2;
    }
    if (adjacency_build(&a, p, nv, idx, nt))
        goto oom;
    cdl_mesh out = {0};
    int rc = cdl_mesh_alloc(&out, nv, nt, 1, 0, file, line, err);
    if (rc) {
        adjacency_free(&a);
        free(p);
        free(idx);
        return rc;
    }
    for (uint32_t v = 0; v < nv; v++) {
        double q[3];
        vertex_rule(&a, p, v, 1, q);
        for (int c = 0; c < 3; c++)
            out.pos[3 * v + c] = (float)q[c];
    }
    adjacency_free(&a);
    memcpy(out.idx, idx, 3 * (size_t)nt * sizeof *idx);
    /* area-weighted normals of the counter-clockwise limit faces */
    double *n = calloc(3 * (size_t)nv, sizeof *n);
    if (!n) {
        cdl_mesh_free(&out);
        goto oom;
    }
    for (uint32_t t = 0; t < nt; t++) {
        const float *A = out.pos + 3 * (size_t)idx[3 * t], *B = out.pos + 3 * (size_t)idx[3 * t + 1],
                    *C = out.pos + 3 * (size_t)idx[3 * t + 2];
        double e1[3] = {B[0] - A[0], B[1] - A[1], B[2] - A[2]}, e2[3] = {C[0] - A[0], C[1] - A[1], C[2] - A[2]};
        double f[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                n[3 * (size_t)idx[3 * t + k] + c] += f[c];
    }
    for (uint32_t v = 0; v < nv; v++) {
        double *q = n + 3 * (size_t)v, l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
        for (int c = 0; c < 3; c++)
            out.nrm[3 * v + c] = l > 0.0 ? (float)(q[c] / l) : 0.0f;
    }
    free(n);
    free(p);
    free(idx);
    cdl_mesh_free(m);
    *m = out;
    return 0;
oom:
    adjacency_free(&a);
    free(p);
    free(idx);
    return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory");
}
