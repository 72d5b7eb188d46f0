/* The visibility mask's occluders (see mask.c): an eye sample can hide
 * another only if some eye sample lies behind its tangent plane by more
 * than that one's footprint, as seen from some ray origin of the pass in
 * front of it by more than its own (or the same with the sides swapped).
 * In a room the walls, floor and ceiling bound everything and never can;
 * the furniture, thin walls and doors can. The extremes of p . n (+ pw)
 * over the samples and over the origins answer that for a normal: a
 * branch and bound over boxes of 64 and of 4096 points, cached per normal
 * (a planar surface's samples share theirs). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrators/splat/hiders.h"

/* Points (eye samples in tree order, or ray origins in Morton order) with
 * a margin each (a footprint, or none) under boxes of 64 and of 64 of
 * those, for the search of points behind a plane. */
#define SBOX 64
typedef struct sbox {
    float lo[3], hi[3], pmin;
} sbox;

typedef struct pset {
    const float *x[3], *pw; /* pw NULL: no margin */
    uint32_t n, nf, nc;
    sbox *fine, *coarse;
} pset;

static sbox sbox_empty(void) { return (sbox){{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}, INFINITY}; }

static void sbox_add(sbox *b, const sbox *c)
{
    for (int a = 0; a < 3; a++)
        b->lo[a] = fminf(b->lo[a], c->lo[a]), b->hi[a] = fmaxf(b->hi[a], c->hi[a]);
    b->pmin = fminf(b->pmin, c->pmin);
}

static int pset_init(pset *ps)
{
    ps->nf = (ps->n + SBOX - 1) / SBOX, ps->nc = (ps->nf + SBOX - 1) / SBOX;
    ps->fine = malloc(sizeof *ps->fine * (ps->nf ? ps->nf : 1));
    ps->coarse = malloc(sizeof *ps->coarse * (ps->nc ? ps->nc : 1));
    if (!ps->fine || !ps->coarse)
        return -1;
#pragma omp parallel for schedule(static)
    for (uint32_t f = 0; f < ps->nf; f++) {
        sbox b = sbox_empty();
        for (uint32_t y = f * SBOX; y < ps->n && y < (f + 1) * SBOX; y++) {
            for (int a = 0; a < 3; a++)
                b.lo[a] = fminf(b.lo[a], ps->x[a][y]), b.hi[a] = fmaxf(b.hi[a], ps->x[a][y]);
            b.pmin = fminf(b.pmin, ps->pw ? ps->pw[y] : 0.0f);
        }
        ps->fine[f] = b;
    }
    for (uint32_t G = 0; G < ps->nc; G++) {
        ps->coarse[G] = sbox_empty();
        for (uint32_t f = G * SBOX; f < ps->nf && f < (G + 1) * SBOX; f++)
            sbox_add(&ps->coarse[G], &ps->fine[f]);
    }
    return 0;
}

static void pset_free(pset *ps)
{
    free(ps->fine);
    free(ps->coarse);
}

/* The least p . n + pw over the box (a lower bound of its points'). */
static inline float sbox_low(const sbox *b, const float n[3])
{
    float v = b->pmin;
    for (int a = 0; a < 3; a++)
        v += n[a] * (n[a] > 0.0f ? b->lo[a] : b->hi[a]);
    return v;
}

/* The least p . n + pw of box f's points. */
static float fine_min(const pset *ps, uint32_t f, const float n[3])
{
    const uint32_t lo = f * SBOX, hi = (f + 1) * SBOX < ps->n ? (f + 1) * SBOX : ps->n;
    float v = INFINITY;
#pragma omp simd reduction(min : v)
    for (uint32_t y = lo; y < hi; y++)
        v = fminf(v, ps->x[0][y] * n[0] + ps->x[1][y] * n[1] + ps->x[2][y] * n[2] + (ps->pw ? ps->pw[y] : 0.0f));
    return v;
}

/* The least p . n + pw of all points (branch and bound over the boxes,
 * the most promising group first). */
static float pset_min(const pset *ps, const float n[3])
{
    float best = INFINITY;
    uint32_t G0 = 0;
    float l0 = INFINITY;
    for (uint32_t G = 0; G < ps->nc; G++) {
        float l = sbox_low(&ps->coarse[G], n);
        if (l < l0)
            l0 = l, G0 = G;
    }
    for (uint32_t i = 0; i < ps->nc; i++) {
        uint32_t G = i == 0 ? G0 : i == G0 ? 0 : i;
        if (!(sbox_low(&ps->coarse[G], n) < best))
            continue;
        for (uint32_t f = G * SBOX; f < ps->nf && f < (G + 1) * SBOX; f++)
            if (sbox_low(&ps->fine[f], n) < best)
                best = fminf(best, fine_min(ps, f, n));
    }
    return best;
}

/* Per thread, the least p . n + pw of the samples and origins for the last
 * normals met (a planar surface's samples share theirs), +-n each. */
#define NCACHE 64
typedef struct ncache {
    float n[3], v[4];
} ncache;

static const float *extremes(ncache *c, const pset *eye, const pset *org, const float n[3])
{
    uint32_t b[3];
    memcpy(b, n, sizeof b);
    ncache *e = &c[(b[0] * 73856093u ^ b[1] * 19349663u ^ b[2] * 83492791u) % NCACHE];
    if (memcmp(e->n, n, sizeof e->n)) {
        const float m[3] = {-n[0], -n[1], -n[2]};
        memcpy(e->n, n, sizeof e->n);
        e->v[0] = pset_min(eye, n), e->v[1] = pset_min(eye, m);
        e->v[2] = pset_min(org, n), e->v[3] = pset_min(org, m);
    }
    return e->v;
}

int64_t splat_hiders(const cdl_skd *t, const float *pw, const cdl_photon_ray *rays, uint32_t nrays, float scale,
                     uint8_t *side)
{
    const uint32_t n = t->n, no = nrays;
    pset eye = {{t->p[0], t->p[1], t->p[2]}, pw, n, 0, 0, NULL, NULL}, org;
    float *ox = malloc(sizeof(float) * 3 * (no ? no : 1));
    org = (pset){{ox, ox + no, ox + 2 * (size_t)no}, NULL, no, 0, 0, NULL, NULL};
    if (ox)
        for (uint32_t k = 0; k < no; k++)
            ox[k] = rays[k].o.x, ox[no + k] = rays[k].o.y, ox[2 * (size_t)no + k] = rays[k].o.z;
    if (!ox || pset_init(&eye) || pset_init(&org)) {
        pset_free(&eye), pset_free(&org), free(ox);
        return -1;
    }
    /* rounding of plane offsets at the coordinates' scale: more occluders,
     * never fewer */
    const float eps = 1e-5f * scale;
    int64_t found = 0;
#pragma omp parallel reduction(+ : found)
    {
        ncache cache[NCACHE];
        for (int i = 0; i < NCACHE; i++)
            cache[i].n[0] = cache[i].n[1] = cache[i].n[2] = NAN; /* matches no normal bit for bit */
#pragma omp for schedule(dynamic, 256)
        for (uint32_t q = 0; q < n; q++) {
            const float nv[3] = {t->nrm[0][q], t->nrm[1][q], t->nrm[2][q]};
            const float c = t->p[0][q] * nv[0] + t->p[1][q] * nv[1] + t->p[2][q] * nv[2], pq = pw[q];
            const float *v = extremes(cache, &eye, &org, nv);
            /* in front: an origin with o . n > c + pq and a sample with
             * p . n + pw < c; behind: the same with n turned */
            uint8_t sd = 0;
            if (v[3] < eps - c - pq && v[0] < c + eps)
                sd |= 1u;
            if (v[2] < c - pq + eps && v[1] < eps - c)
                sd |= 2u;
            side[q] = sd;
            found += sd != 0;
        }
    }
    pset_free(&eye);
    pset_free(&org);
    free(ox);
    return found;
}
