#include "transport/vertex_store.h"

#include <stdlib.h>
#include <string.h>

void cdl_vs_init(cdl_vertex_store *vs) { memset(vs, 0, sizeof *vs); }

#define VS_FIELDS(X)                                                                               \
    X(p) X(ns) X(ng) X(ts) X(nb) X(wi) X(beta) X(pdf_fwd) X(pdf_rev) X(rr) X(u) X(v) X(kdh) X(parent) X(mat) X(light) \
    X(depth) X(flags)

void cdl_vs_free(cdl_vertex_store *vs)
{
#define FREE(f) free(vs->f);
    VS_FIELDS(FREE)
#undef FREE
    cdl_vs_init(vs);
}

int cdl_vs_reserve(cdl_vertex_store *vs, uint32_t n, cdl_error *err)
{
    if (n <= vs->cap)
        return 0;
    uint64_t cap = vs->cap ? vs->cap : 16;
    while (cap < n)
        cap *= 2;
    if (cap > UINT32_MAX)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "vertex store too large");
    int ok = 1;
#define GROW(f)                                                                                    \
    {                                                                                              \
        void *q = realloc(vs->f, (size_t)cap * sizeof *vs->f);                                     \
        if (q)                                                                                     \
            vs->f = q;                                                                             \
        else                                                                                       \
            ok = 0;                                                                                \
    }
    VS_FIELDS(GROW)
#undef GROW
    if (!ok)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for %llu path vertices",
                             (unsigned long long)cap);
    vs->cap = (uint32_t)cap;
    return 0;
}

int cdl_vs_append(cdl_vertex_store *dst, const cdl_vertex_store *src, cdl_error *err)
{
    if ((uint64_t)dst->n + src->n > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "vertex store too large");
    int rc = cdl_vs_reserve(dst, dst->n + src->n, err);
    if (rc)
        return rc;
#define COPY(f) memcpy(dst->f + dst->n, src->f, (size_t)src->n * sizeof *src->f);
    VS_FIELDS(COPY)
#undef COPY
    for (uint32_t i = 0; i < src->n; i++)
        if (src->parent[i] >= 0)
            dst->parent[dst->n + i] = src->parent[i] + (int32_t)dst->n;
    dst->n += src->n;
    return 0;
}

size_t cdl_vs_bytes(const cdl_vertex_store *vs)
{
    size_t per = 0;
#define SIZE(f) per += sizeof *vs->f;
    VS_FIELDS(SIZE)
#undef SIZE
    return per * vs->cap;
}

void cdl_vs_bsdf(const cdl_scene *s, const cdl_vertex_store *vs, uint32_t i, cdl_bsdf *b)
{
    cdl_surface sf;
    sf.p = vs->p[i];
    sf.ng = vs->ng[i];
    sf.ns = vs->ns[i];
    sf.ts = vs->ts[i];
    sf.nb = cdl_is_black(vs->nb[i]) ? sf.ns : vs->nb[i];
    sf.u = vs->u[i];
    sf.v = vs->v[i];
    sf.kdh = vs->kdh[i];
    sf.mat = vs->mat[i];
    sf.prim = 0;
    sf.geom = 0;
    sf.light = vs->light[i];
    cdl_scene_bsdf(s, &sf, b);
}
