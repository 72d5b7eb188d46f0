/* The state of the gkde integrator (Bekaert et al. 2003): owned by gkde.c
 * (paths, footprints, calibration, the step's image, the vtable), which
 * calls points.c (points.h: the eye points' kd-tree and stages 3 to 5:
 * candidate counting, trial linking, shadow rays and scores). */
#ifndef CDL_GKDE_STATE_H
#define CDL_GKDE_STATE_H

#include <stdatomic.h>
#include <string.h>

#include "integrators/integrator.h"
#include "spatial/kdparts.h"
#include "transport/gkde_link.h"
#include "transport/subpath.h"

#define GKDE_PATHS_PER_LINK 10000 /* default: one wanted link per this many light paths */

typedef struct gkde_stats {
    double t_eye, t_light, t_count, t_link, t_rays, t_score, t_total;
    double candidates, trials, unoccluded, points; /* summed over steps */
    uint32_t steps;
    size_t peak_bytes;
} gkde_stats;

typedef struct gkde_state {
    const cdl_scene *scene;
    cdl_options opt;
    cdl_walk walk;
    uint32_t n_light, eye_paths, M;
    float h, r_cap;
    int have_h;
    int at_infinity; /* the scene has distant or infinite lights */
    cdl_vertex_store lvs, evs;
    cdl_vertex_store *chunks; /* per row (eye) or per LIGHT_CHUNK paths (light), reused */
    uint32_t **chunk_pix;
    uint32_t nchunks;
    uint32_t *epix;   /* pixel of each eye vertex */
    float *radius;    /* footprint radius of each light vertex */
    uint32_t *lv;     /* light vertices with a footprint */
    float *ball;      /* per entry of lv: its footprint's centre and radius (x, y, z, R), read in order */
    uint32_t nlv;
    float *pts;       /* usable eye vertices in tree order: x, y, z, store index bits */
    uint32_t npts;
    cdl_kdtree kd;
    cdl_kd_part *parts; /* the parts threads own (spatial/kdparts.h) */
    uint32_t nparts;
    /* per part: the candidates of stage 3 as records (light vertex list
     * index, count, points), replayed by stage 4 without a second query */
    struct rec_buf {
        uint32_t *v;
        size_t n, cap;
        int fail;
    } *rec;
    uint32_t nrec;
    /* per point */
    uint32_t *count, *tested, *unocc;
    uint16_t *pdepth; /* eye depth, in tree order (the candidate test reads it) */
    double *wsum, *scale, *cum;
    cdl_vec3 *acc;
    cdl_gkde_eye *eye; /* what links read of each point's eye vertex, built on first use (gkde_eye_of): */
    _Atomic unsigned char *eye_ready; /* 0 not yet, 1 being built, 2 built (most points get no link) */
    /* per pixel: tested and unoccluded links, by eye depth 1, 2, 3+: pv of the
     * steps before fold_at (the plan reads these), pv_new of the steps since.
     * Folding at powers of two makes step i's plan a function of steps
     * [0, 2^floor(log2 i)) alone, so processes that render disjoint steps
     * and sum pv_new at each fold get one process's plans. */
    uint32_t *pv, *pv_new;
    uint32_t fold_at;
    cdl_vec3 *pixsum;
    size_t rec_bytes;
    cdl_gkde_ctx g;
    gkde_stats st;
    atomic_int *cancel; /* the film's, set by each pass */
} gkde_state;

/* links by default: N / 10000 rounded, at least 1 (the report's M = 10
 * at 100000 paths, 5 at the default 50000). */
static inline uint32_t gkde_default_links(uint32_t n_light)
{
    uint32_t m = (n_light + GKDE_PATHS_PER_LINK / 2) / GKDE_PATHS_PER_LINK;
    return m ? m : 1;
}

/* The eye vertex (store index) of point q. */
static inline uint32_t gkde_point_vertex(const gkde_state *s, uint32_t q)
{
    uint32_t e;
    memcpy(&e, &s->pts[4 * (size_t)q + 3], sizeof e);
    return e;
}

/* Point q's eye record, built by the first thread that asks (any other
 * waits for it: the record is the same whoever builds it). */
static inline const cdl_gkde_eye *gkde_eye_of(const gkde_state *s, uint32_t q)
{
    _Atomic unsigned char *f = &s->eye_ready[q];
    if (atomic_load_explicit(f, memory_order_acquire) == 2)
        return &s->eye[q];
    unsigned char free_ = 0;
    if (atomic_compare_exchange_strong_explicit(f, &free_, 1, memory_order_acq_rel, memory_order_acquire)) {
        cdl_gkde_eye_init(&s->g, gkde_point_vertex(s, q), &s->eye[q]);
        atomic_store_explicit(f, 2, memory_order_release);
    } else {
        while (atomic_load_explicit(f, memory_order_acquire) != 2)
            ;
    }
    return &s->eye[q];
}

/* The P_vis tally of eye vertex y: its pixel's (tested, unoccluded) pair
 * for its depth 1, 2 or 3+. */
static inline uint32_t gkde_pv_bucket(const gkde_state *s, uint32_t y)
{
    uint32_t d = s->evs.depth[y];
    return 6 * s->epix[y] + 2 * (d >= 3 ? 2 : d - 1);
}

#endif
