#include "transport/importance.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "scene/bsdf.h"

#define CHUNK 1024u

typedef struct chunk_out {
    float *pts;
    uint32_t n, cap;
} chunk_out;

/* Raster point of importon path i: stratified over the image, one
 * jittered sample per cell of a grid of about `paths` cells. */
static void raster_point(const cdl_camera *cam, uint64_t i, uint64_t paths, cdl_sampler *smp, float *x,
                         float *y)
{
    float jx, jy;
    cdl_sampler_2d(smp, &jx, &jy);
    double aspect = (double)cam->width / (double)cam->height;
    uint64_t ny = (uint64_t)sqrt((double)paths / aspect);
    ny = ny ? ny : 1;
    uint64_t nx = paths / ny ? paths / ny : 1;
    uint64_t cell = i % (nx * ny);
    *x = (float)(((double)(cell % nx) + jx) / (double)nx * cam->width);
    *y = (float)(((double)(cell / nx) + jy) / (double)ny * cam->height);
}

int cdl_importance_build(cdl_importance *imp, const cdl_scene *s, const cdl_camera *cam,
                         const cdl_walk *walk, uint64_t paths, uint32_t tests, float max_radius,
                         cdl_sampler_kind kind, uint64_t seed, cdl_error *err)
{
    memset(imp, 0, sizeof *imp);
    imp->max_r2 = max_radius * max_radius;
    imp->paths = paths;
    uint64_t nchunks = (paths + CHUNK - 1) / CHUNK;
    chunk_out *out = calloc(nchunks ? nchunks : 1, sizeof(chunk_out));
    if (!out)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "importons", 0, "out of memory");
    int fail = 0;
    float inv_paths = 1.0f / (float)paths;
#pragma omp parallel
    {
        cdl_vertex_store vs;
        cdl_vs_init(&vs);
        if (cdl_vs_reserve(&vs, (uint32_t)walk->maxdepth + 2, NULL)) {
#pragma omp atomic write
            fail = 1;
        }
#pragma omp for schedule(dynamic)
        for (int64_t c = 0; c < (int64_t)nchunks; c++) {
            if (fail)
                continue;
            chunk_out *o = &out[c];
            uint64_t rays = 0;
            for (uint64_t i = (uint64_t)c * CHUNK; i < paths && i < (uint64_t)(c + 1) * CHUNK; i++) {
                cdl_sampler smp;
                cdl_sampler_start(&smp, kind, seed ^ 0x1a2b3c4d5e6fULL, i, 0);
                float x, y;
                raster_point(cam, i, paths, &smp, &x, &y);
                cdl_vs_clear(&vs);
                uint32_t nv = cdl_trace_eye_subpath(s, cam, x, y, walk, &smp, &vs, &rays);
                for (uint32_t v = 1; v < nv; v++) {
                    if (cdl_mat_is_delta(s->mats[vs.mat[v]].type))
                        continue;
                    float w = cdl_luminance(vs.beta[v]) * inv_paths;
                    if (!(w > 0.0f) || !isfinite(w))
                        continue;
                    if (o->n == o->cap) {
                        uint32_t cap = o->cap ? 2 * o->cap : 4096;
                        float *p = realloc(o->pts, sizeof(float) * 4 * cap);
                        if (!p) {
#pragma omp atomic write
                            fail = 1;
                            break;
                        }
                        o->pts = p;
                        o->cap = cap;
                    }
                    float *q = o->pts + 4 * (size_t)o->n++;
                    q[0] = vs.p[v].x;
                    q[1] = vs.p[v].y;
                    q[2] = vs.p[v].z;
                    q[3] = w;
                }
            }
        }
        cdl_vs_free(&vs);
    }
    uint64_t total = 0;
    for (uint64_t c = 0; c < nchunks; c++)
        total += out[c].n;
    if (!fail && total > UINT32_MAX / 8)
        fail = 2;
    if (!fail && (imp->pts = malloc(sizeof(float) * 4 * (total ? total : 1))) == NULL)
        fail = 1;
    for (uint64_t c = 0; c < nchunks; c++) {
        if (!fail && out[c].n)
            memcpy(imp->pts + 4 * (size_t)imp->n, out[c].pts, sizeof(float) * 4 * out[c].n);
        imp->n += fail ? 0 : out[c].n;
        free(out[c].pts);
    }
    free(out);
    if (fail) {
        cdl_importance_free(imp);
        return cdl_error_set(err, fail == 2 ? CDL_ERR_INPUT : CDL_ERR_SYSTEM, "importons", 0,
                             fail == 2 ? "too many importons (lower importons)" : "out of memory");
    }
    if (!imp->n) {
        cdl_importance_free(imp);
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                             "no importon landed on a non-specular surface: the camera sees nothing to light");
    }
    if (cdl_kd_build(&imp->kd, imp->pts, 4, imp->n, err)) {
        cdl_importance_free(imp);
        return err->code;
    }
    /* f from test rays: the least importance where the camera looks directly */
    float mn = FLT_MAX;
    cdl_vertex_store vs;
    cdl_vs_init(&vs);
    if (cdl_vs_reserve(&vs, (uint32_t)walk->maxdepth + 2, err)) {
        cdl_importance_free(imp);
        return err->code;
    }
    for (uint32_t t = 0; t < tests; t++) {
        cdl_sampler smp;
        cdl_sampler_start(&smp, kind, seed ^ 0x7e57ULL, t, 0);
        float x, y;
        raster_point(cam, t, tests, &smp, &x, &y);
        cdl_vs_clear(&vs);
        uint64_t rays = 0;
        uint32_t nv = cdl_trace_eye_subpath(s, cam, x, y, walk, &smp, &vs, &rays);
        for (uint32_t v = 1; v < nv; v++)
            if (!cdl_mat_is_delta(s->mats[vs.mat[v]].type)) {
                float I = cdl_importance_at(imp, vs.p[v]);
                if (I > 0.0f) {
                    mn = I < mn ? I : mn;
                    imp->tests++;
                }
                break;
            }
    }
    cdl_vs_free(&vs);
    if (!imp->tests) {
        cdl_importance_free(imp);
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "no test ray from the camera found importance");
    }
    imp->min_test = mn;
    imp->f = 1.0f / mn;
    return 0;
}

void cdl_importance_free(cdl_importance *imp)
{
    cdl_kd_free(&imp->kd);
    free(imp->pts);
    memset(imp, 0, sizeof *imp);
}

float cdl_importance_at(const cdl_importance *imp, cdl_vec3 x)
{
    uint32_t idx[CDL_IMPORTON_K];
    float d2[CDL_IMPORTON_K];
    uint32_t n = cdl_kd_knn(&imp->kd, x, CDL_IMPORTON_K, imp->max_r2, idx, d2);
    if (!n)
        return 0.0f;
    float r2 = n == CDL_IMPORTON_K ? d2[n - 1] : imp->max_r2;
    if (!(r2 > 0.0f))
        return 0.0f;
    float w = 0.0f;
    for (uint32_t i = 0; i < n; i++)
        w += imp->pts[4 * (size_t)idx[i] + 3];
    return w / (CDL_PI * r2);
}
