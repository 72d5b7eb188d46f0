#include "transport/light_pool.h"

#include <stdlib.h>
#include <string.h>

int cdl_light_pool_init(cdl_light_pool *lp, uint32_t k, uint32_t interleave, int maxdepth,
                        cdl_error *err)
{
    memset(lp, 0, sizeof *lp);
    cdl_vs_init(&lp->vs);
    lp->k = k;
    lp->n_interleave = interleave ? interleave : 1;
    lp->sets = lp->n_interleave * lp->n_interleave;
    lp->stride = (uint32_t)maxdepth + 2;
    if ((uint64_t)k * lp->stride > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_USAGE, "light_paths", 0, "too many light path vertices");
    lp->len = calloc(k ? k : 1, sizeof(uint32_t));
    if (!lp->len)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    return cdl_vs_reserve(&lp->vs, k * lp->stride, err);
}

void cdl_light_pool_free(cdl_light_pool *lp)
{
    cdl_vs_free(&lp->vs);
    free(lp->len);
    lp->len = NULL;
}

void cdl_light_pool_trace(cdl_light_pool *lp, const cdl_scene *s, const cdl_walk *walk,
                          cdl_sampler_kind kind, uint64_t seed, uint32_t pass, uint64_t *rays)
{
    uint64_t total = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : total)
    for (uint32_t i = 0; i < lp->k; i++) {
        /* a view of the shared arrays that appends at this path's slot */
        cdl_vertex_store view = lp->vs;
        view.n = i * lp->stride;
        cdl_sampler smp;
        cdl_sampler_start(&smp, kind, seed ^ 0x5bd1e995u, (uint64_t)i, pass);
        uint64_t r = 0;
        lp->len[i] = cdl_trace_light_subpath(s, walk, &smp, &view, &r);
        total += r;
    }
    *rays += total;
}
