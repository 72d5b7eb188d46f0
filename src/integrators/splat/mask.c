/* splat's visibility mask (Herzog et al. 2007, §8.1, proposed there as
 * future work): before a photon ray splats, the eye samples inside its
 * frustum that may hide others (the occluders, below) are rasterized into
 * a small occlusion buffer in the kernel's plane: lateral offsets from the
 * ray divided by the kernel's radius at their depth (the cone's own
 * perspective, so a blocker near the narrow origin hides only what lies
 * behind it), on at most MASK_G x MASK_G cells, no finer than the
 * samples' median footprint. Each sample covers the surface patch its
 * pixel sees (the masking density: an ellipse, longer on surfaces seen at
 * a grazing angle, so a surface leaves no holes), and a cell keeps the
 * occluder nearest the ray's origin. A feasible sample is then fed only if
 * the front occluder of its cell does not hide it: that occluder lies
 * nearer along the ray and the sample lies behind the occluder's tangent
 * plane (seen from the ray's origin) by more than its own footprint, so a
 * surface never shadows its own neighbours. Only occluders the camera sees
 * count (they must be eye samples), as the report says; the surface the
 * ray leaves is no occluder.
 *
 * The occluders: an eye sample can hide another only if some eye sample
 * lies behind its tangent plane by more than that one's footprint, as seen
 * from some ray origin of the pass in front of it by more than its own
 * (or the same with the sides swapped). In a room the walls, floor and
 * ceiling bound everything and never can; the furniture, thin walls and
 * doors can. prepare finds them once a pass (hiders.c: boxes of 64 and of 4096
 * samples, and of ray origins, bound the search) and puts them under a
 * tree of their own, with the sides they may hide from. A sample that can hide nothing is no occluder at all: it neither
 * hides nor stands in front of an occluder to unveil what lies behind both.
 *
 * Cost (issue 29): a batch of rays at a time, in parallel over the rays,
 * each ray's frustum goes through the occluders' tree (small: a room's
 * furniture), and a ray that meets occluders gets a buffer (8 KiB at most)
 * only if some sample it feeds lies behind one of their planes (else
 * nothing could be hidden: cdl_skd_any_behind, which stops at the first).
 * The splats then go as without masks, part by part, the same
 * traversal and weights, each feasible batch of a ray with a buffer
 * filtered through it (mask_ray.c): samples sum their splats in the same
 * order, and an image without occluders is the unmasked one. A cell holds
 * its front occluder as one 64-bit key, distance bits over the sample's
 * index in the eye-sample tree (z >= 0: the float's bits order as the
 * float), so z-min with the index's tie-break is one unsigned min. Where a
 * ray's occluders lie on at most MASK_PLANES planes (a room's furniture:
 * the Cornell box's every ray, 89-95 % of the generated interiors'), the
 * key holds the plane instead of the index, and the buffer keeps one word
 * a cell (the distance's low 5 bits give way to the plane), a bit a cell
 * for the filled ones and the plane table: the filter then gathers only
 * where a lane's cell is filled, one word, and reads the planes from
 * registers (eight gathers a batch before, the first a cache miss). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <omp.h>
#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "core/grow.h"
#include "integrators/splat/hiders.h"
#include "integrators/splat/mask.h"
#include "integrators/splat/mask_ray.h"

#define NONE UINT32_MAX
#define MASK_OCC (MASK_G * MASK_G / 32) /* words of a buffer's filled-cell bits */
#define RG_PLANES 0x80u                 /* in a ray's side in cells: its buffer has planes */
#define PLANES 8

/* Per thread: the buffers of the rays it took, one after another, per
 * batch slot (the batches alternate between two: one is built while the
 * other's splats are filtered). */
typedef struct mask_worker {
    _Alignas(64) uint32_t *cells[2]; /* the buffers, each g^2 distance bits then g^2 samples (a cache line
                                      * of its own: the threads write theirs all the time) */
    uint64_t *grid;                  /* MASK_G^2 keys: the ray being rasterized */
    uint32_t ncell[2], capcell[2];
    int oom;
    mask_ray x;   /* the ray being built */
    mask_held *held; /* its occluders */
    uint32_t nh, caph;
    /* the held occluders' planes, turned so that a sample one may
     * hide has p . n + pw < c: the largest c per normal (np > PLANES: too
     * many normals to ask) */
    cdl_skd_plane pl[PLANES];
    int np, last; /* last: the plane the last lane had */
    float cmax[16]; /* lanes of offsets on plane last not yet in its c (-inf: none) */
    /* the occluders' distinct planes (MASK_PLANES + 1: too many), as
     * mask_ray's tab, and the one the last lane had */
    float tab[4 * MASK_PLANES];
    int ntab, tlast;
    uint64_t rasterized, tested, buffers, planar;
} mask_worker;

struct splat_mask {
    float rho;          /* the eye samples' median footprint: the smallest cell worth having */
    float *pw;          /* per eye sample (tree order) its footprint */
    uint32_t npw;
    float scale;        /* the largest coordinate of the samples' box */
    /* the occluders under their own tree, and in its order: footprint,
     * patch semi-axes, index in the eye-sample tree, sides */
    cdl_skd occ;
    float *opw, *oax[6];
    uint32_t *oid;
    uint8_t *oside;
    uint32_t nocc;
    mask_worker *w;
    int nw;
    /* per slot, per ray of its batch: its buffer's offset (NONE: none), worker and side in cells */
    uint32_t *roff[2], *rw[2];
    uint8_t *rg[2];
};

int splat_mask_alloc(splat_state *s, cdl_error *err)
{
    if (s->mask)
        return 0;
    splat_mask *m = s->mask = calloc(1, sizeof *m);
    int ok = m != NULL;
    for (int i = 0; ok && i < 2; i++)
        ok = (m->roff[i] = malloc(sizeof *m->roff[i] * SPLAT_MASK_BATCH)) &&
             (m->rw[i] = malloc(sizeof *m->rw[i] * SPLAT_MASK_BATCH)) && (m->rg[i] = malloc(SPLAT_MASK_BATCH));
    if (!ok)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the visibility masks");
    return 0;
}

static void occ_free(splat_mask *m)
{
    cdl_skd_free(&m->occ);
    free(m->opw);
    for (int c = 0; c < 6; c++)
        free(m->oax[c]);
    free(m->oid);
    free(m->oside);
    m->opw = NULL, m->oid = NULL, m->oside = NULL;
    memset(m->oax, 0, sizeof m->oax);
    m->nocc = 0;
}

void splat_mask_free(splat_state *s)
{
    splat_mask *m = s->mask;
    if (!m)
        return;
    for (int i = 0; i < m->nw; i++) {
        free(m->w[i].cells[0]);
        free(m->w[i].cells[1]);
        free(m->w[i].grid);
        free(m->w[i].held);
    }
    free(m->w);
    for (int i = 0; i < 2; i++) {
        free(m->roff[i]);
        free(m->rw[i]);
        free(m->rg[i]);
    }
    free(m->pw);
    occ_free(m);
    free(m);
    s->mask = NULL;
}

size_t splat_mask_bytes(const splat_state *s)
{
    const splat_mask *m = s->mask;
    if (!m)
        return 0;
    size_t b = (size_t)SPLAT_MASK_BATCH * 18 + sizeof(float) * (size_t)m->npw + cdl_skd_bytes(&m->occ) +
               (size_t)m->nocc * (7 * sizeof(float) + sizeof(uint32_t) + 1);
    for (int i = 0; i < m->nw; i++)
        b += (size_t)(m->w[i].capcell[0] + m->w[i].capcell[1]) * sizeof(uint32_t) + (size_t)m->w[i].caph * sizeof(mask_held) +
             (m->w[i].grid ? sizeof(uint64_t) * MASK_G * MASK_G : 0);
    return b;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* The occluders of this pass (see the top) and their tree; 0 or an error
 * code. */
static int occluders(splat_state *s)
{
    splat_mask *m = s->mask;
    const cdl_skd *t = &s->tree;
    occ_free(m);
    const uint32_t n = t->n;
    uint8_t *side = malloc(n ? n : 1);
    const int64_t found = side ? splat_hiders(t, m->pw, s->rays.r, s->rays.n, m->scale, side) : -1;
    if (found < 0) {
        free(side);
        return CDL_ERR_SYSTEM;
    }
    const uint32_t nocc = (uint32_t)found;
    int rc = 0;
    cdl_vec3 *op = malloc(sizeof *op * (nocc ? nocc : 1)), *on = malloc(sizeof *on * (nocc ? nocc : 1));
    uint8_t *ofl = malloc(nocc ? nocc : 1);
    uint32_t *idx = malloc(sizeof *idx * (nocc ? nocc : 1));
    if (!op || !on || !ofl || !idx)
        rc = CDL_ERR_SYSTEM;
    for (uint32_t q = 0, j = 0; !rc && q < n; q++)
        if (side[q]) {
            op[j] = cdl_v3(t->p[0][q], t->p[1][q], t->p[2][q]);
            on[j] = cdl_v3(t->nrm[0][q], t->nrm[1][q], t->nrm[2][q]);
            ofl[j] = t->two[q] != 0.0f ? CDL_SKD_TWO_SIDED : 0;
            idx[j++] = q;
        }
    cdl_skd_params kp = s->kp;
    kp.cull_deg = -1.0f; /* the frustum's samples, any facing */
    cdl_error err;
    if (!rc && nocc && cdl_skd_build(&m->occ, op, on, ofl, nocc, &kp, &err))
        rc = err.code;
    if (!rc && nocc) {
        int ok = (m->opw = malloc(sizeof(float) * (nocc + 16))) && (m->oid = calloc(nocc + 16, sizeof(uint32_t))) &&
                 (m->oside = calloc(nocc + 16, 1));
        for (int c = 0; c < 6; c++)
            ok = ok && (m->oax[c] = malloc(sizeof(float) * (nocc + 16)));
        if (!ok)
            rc = CDL_ERR_SYSTEM;
    }
    if (!rc && nocc) {
        m->nocc = nocc;
        for (uint32_t j = 0; j < nocc; j++) {
            uint32_t q = idx[m->occ.order[j]];
            m->oid[j] = q;
            m->oside[j] = side[q];
            m->opw[j] = m->pw[q];
        }
        for (uint32_t j = nocc; j < nocc + 16; j++)
            m->opw[j] = 0.0f;
    }
    free(op), free(on), free(ofl), free(idx), free(side);
    return rc;
}

int splat_mask_prepare(splat_state *s)
{
    /* cells finer than the samples' spacing only cost clearing and
     * rasterizing: the median footprint of a strided subset bounds them */
    splat_mask *m = s->mask;
    if (m->npw < s->tree.n || !m->pw) {
        /* 16 lanes of padding: the leaf loops read whole batches */
        m->npw = 0;
        free(m->pw);
        if (!(m->pw = calloc((size_t)s->tree.n + 16, sizeof *m->pw)))
            return CDL_ERR_SYSTEM;
        m->npw = s->tree.n;
    }
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->tree.n; q++)
        m->pw[q] = s->eye[q].pw;
    m->scale = 0.0f;
    for (int a = 0; a < 3; a++)
        m->scale = fmaxf(m->scale, fmaxf(fabsf(s->tree.bmin[a]), fabsf(s->tree.bmax[a])));
    int rc = occluders(s);
    if (rc)
        return rc;
    s->st.mask_occ += m->nocc;
    /* a sample stands for the patch a pixel covers: a disc of radius
     * 0.6 pw across its view ray, landed on the surface: an ellipse whose
     * axis along the view is 1 / cos longer, at most 5x: a grazing
     * surface leaves holes beyond that, and longer patches widen every
     * shadow they cast (measured: 20x removed 99.9 % of the leak under a
     * plate seen edge-on, but doubled the Cornell box's direct-light
     * error) */
#pragma omp parallel for schedule(static)
    for (uint32_t j = 0; j < m->nocc; j++) {
        const splat_eye *e = &s->eye[m->oid[j]];
        float r = 0.6f * e->pw, c = fabsf(cdl_dot(e->wo, e->f.n));
        float r2 = r / (c > 0.2f ? c : 0.2f);
        m->oax[0][j] = r2 * e->f.t.x, m->oax[1][j] = r2 * e->f.t.y, m->oax[2][j] = r2 * e->f.t.z;
        m->oax[3][j] = r * e->f.b.x, m->oax[4][j] = r * e->f.b.y, m->oax[5][j] = r * e->f.b.z;
    }
    for (int c = 0; c < 6; c++)
        for (uint32_t j = m->nocc; m->nocc && j < m->nocc + 16; j++)
            m->oax[c][j] = 0.0f;
    uint32_t n = s->tree.n < 4096 ? s->tree.n : 4096, step = n ? s->tree.n / n : 1;
    float *f = malloc(sizeof *f * (n ? n : 1));
    m->rho = 0.0f; /* without memory: the full grid */
    if (!f)
        return 0;
    for (uint32_t i = 0; i < n; i++)
        f[i] = m->pw[(size_t)i * step];
    qsort(f, n, sizeof *f, cmp_float);
    m->rho = n ? f[n / 2] : 0.0f;
    free(f);
    return 0;
}

/* The buffer's side for ray r: MASK_G cells, fewer where the cone's widest
 * cross-section holds fewer median footprints; 0: no cone. */
static int cells_of(const splat_mask *m, const cdl_photon_ray *r)
{
    float hmax = r->h0 + r->dh * r->len;
    if (!(hmax > 0.0f))
        return 0;
    int g = MASK_G;
    if (2.0f * hmax < (float)g * m->rho)
        g = (int)ceilf(2.0f * hmax / m->rho);
    return g < 1 ? 1 : g;
}

static void ray_frame(const splat_state *s, const cdl_photon_ray *r, int g, mask_ray *x)
{
    const splat_mask *m = s->mask;
    cdl_frame f = cdl_frame_from(r->d);
    float big = fmaxf(m->scale, fmaxf(fabsf(r->o.x), fmaxf(fabsf(r->o.y), fabsf(r->o.z))));
    *x = (mask_ray){&m->occ, r, m->opw, (const float *const *)m->oax, {f.t.x, f.t.y, f.t.z}, {f.b.x, f.b.y, f.b.z},
                    /* ~10x the rounding of a plane offset at the coordinates' scale */
                    1e-5f * big, g, INT32_MAX, NULL, NULL, 0, m->oid, m->oside,
                    &s->tree, m->pw, NULL, NULL, NULL, NULL, NULL};
}

_Static_assert((MASK_PLANES & (MASK_PLANES - 1)) == 0 && MASK_PLANES <= 32, "a plane in the low bits of a distance");

/* The plane (n, d) in x's table, added if new; -1: the table is full. d
 * within tol of an entry with the same n is that entry (the samples of one
 * face differ by their rounding). */
static int plane_of(mask_worker *x, const float n[3], float d, float tol)
{
    float *T = x->tab;
    int k = x->tlast;
    if (k < x->ntab && T[k] == n[0] && T[MASK_PLANES + k] == n[1] && T[2 * MASK_PLANES + k] == n[2] &&
        fabsf(T[3 * MASK_PLANES + k] - d) <= tol)
        return k;
    for (k = 0; k < x->ntab; k++)
        if (T[k] == n[0] && T[MASK_PLANES + k] == n[1] && T[2 * MASK_PLANES + k] == n[2] &&
            fabsf(T[3 * MASK_PLANES + k] - d) <= tol)
            return x->tlast = k;
    if (x->ntab == MASK_PLANES) {
        x->ntab = MASK_PLANES + 1;
        return -1;
    }
    T[k] = n[0], T[MASK_PLANES + k] = n[1], T[2 * MASK_PLANES + k] = n[2], T[3 * MASK_PLANES + k] = d;
    x->ntab++;
    return x->tlast = k;
}

/* Each kept lane's plane as an entry of x's table, into pid: its normal
 * turned away from the origin (the side it hides; back: the origin lies
 * behind the plane, cc: p . n with n turned towards the origin), its
 * offset p . n. Lanes with the same normal and side and offsets within
 * tol are one look-up. */
static void plane_ids(mask_worker *x, mask_held *h)
{
    const cdl_skd *t = x->x.t;
    const uint32_t keep = h->mask, back = h->back;
    const float *nx = t->nrm[0] + h->first, *ny = t->nrm[1] + h->first, *nz = t->nrm[2] + h->first;
    const float *px = t->p[0] + h->first, *py = t->p[1] + h->first, *pz = t->p[2] + h->first;
    const float tol = 0.1f * x->x.eps;
#if defined(__AVX512F__)
    const __m512 vnx = _mm512_loadu_ps(nx), vny = _mm512_loadu_ps(ny), vnz = _mm512_loadu_ps(nz);
    const __m512 c = _mm512_fmadd_ps(_mm512_loadu_ps(pz), vnz,
                                     _mm512_fmadd_ps(_mm512_loadu_ps(py), vny, _mm512_mul_ps(_mm512_loadu_ps(px), vnx)));
    const __m512 d = _mm512_mask_sub_ps(c, (__mmask16)~back, _mm512_setzero_ps(), c); /* the offset, turned */
    __m512i ids = _mm512_setzero_si512();
    for (uint32_t m = keep; m && x->ntab <= MASK_PLANES;) {
        const int i = __builtin_ctz(m);
        const float s0 = back >> i & 1u ? 1.0f : -1.0f;
        const float n[3] = {s0 * nx[i], s0 * ny[i], s0 * nz[i]};
        __mmask16 same = _mm512_mask_cmp_ps_mask((__mmask16)(m & (back >> i & 1u ? back : ~back)), vnx,
                                                 _mm512_set1_ps(nx[i]), _CMP_EQ_OQ);
        same = _mm512_mask_cmp_ps_mask(same, vny, _mm512_set1_ps(ny[i]), _CMP_EQ_OQ);
        same = _mm512_mask_cmp_ps_mask(same, vnz, _mm512_set1_ps(nz[i]), _CMP_EQ_OQ);
        same |= (__mmask16)(1u << i); /* a NaN normal: alone */
        float lo = _mm512_mask_reduce_min_ps(same, d), hi = _mm512_mask_reduce_max_ps(same, d);
        if (!(hi - lo <= tol)) { /* not one plane: this lane alone */
            same = (__mmask16)(1u << i);
            float di[16];
            _mm512_storeu_ps(di, d);
            lo = di[i];
        }
        const int k = plane_of(x, n, lo, tol);
        ids = _mm512_mask_mov_epi32(ids, same, _mm512_set1_epi32(k));
        m &= ~(uint32_t)same;
    }
    _mm_storeu_si128((__m128i *)h->pid, _mm512_cvtepi32_epi8(ids));
#else
    float d[16];
    for (int i = 0; i < 16; i++) { /* the offsets, turned */
        const float c = px[i] * nx[i] + py[i] * ny[i] + pz[i] * nz[i];
        d[i] = back >> i & 1u ? c : -c;
    }
    for (uint32_t m = keep; m && x->ntab <= MASK_PLANES;) {
        const int i = __builtin_ctz(m);
        const float s0 = back >> i & 1u ? 1.0f : -1.0f;
        const float n[3] = {s0 * nx[i], s0 * ny[i], s0 * nz[i]};
        uint32_t same = 1u << i;
        float lo = d[i], hi = d[i];
        for (uint32_t r = m & (m - 1); r; r &= r - 1) {
            const int j = __builtin_ctz(r);
            if (nx[j] == nx[i] && ny[j] == ny[i] && nz[j] == nz[i] && (back >> j & 1u) == (back >> i & 1u)) {
                same |= 1u << j;
                lo = d[j] < lo ? d[j] : lo, hi = d[j] > hi ? d[j] : hi;
            }
        }
        if (!(hi - lo <= tol)) /* not one plane: this lane alone */
            same = 1u << i, lo = d[i];
        const int k = plane_of(x, n, lo, tol);
        for (uint32_t r = same; k >= 0 && r; r &= r - 1)
            h->pid[__builtin_ctz(r)] = (uint8_t)k;
        m &= ~same;
    }
#endif
}

/* The offsets collect kept in lanes for the last plane, into its c. */
static void planes_flush(mask_worker *x)
{
#if defined(__AVX512F__)
    const float c = _mm512_reduce_max_ps(_mm512_loadu_ps(x->cmax)) + x->x.eps;
    if (x->last < x->np && c > x->pl[x->last].c)
        x->pl[x->last].c = c;
    _mm512_storeu_ps(x->cmax, _mm512_set1_ps(-INFINITY));
#else
    (void)x;
#endif
}

/* The occluders' tree hands the frustum's batches: the lanes that may
 * hide something for this ray (not on the surface it leaves, on a side
 * its origin may hide from) are held, and their planes noted. */
static void collect(void *ctx, uint32_t first, uint32_t mlen, uint32_t any, const float *z, uint32_t feasible,
                    const float *w, const float *iz)
{
    (void)mlen, (void)feasible, (void)w, (void)iz;
    mask_worker *x = ctx;
    if (!any || x->oom)
        return;
    x->tested += (uint64_t)__builtin_popcount(any);
    const cdl_skd *t = x->x.t;
    const float ox = x->x.r->o.x, oy = x->x.r->o.y, oz = x->x.r->o.z;
    const float *px = t->p[0] + first, *py = t->p[1] + first, *pz = t->p[2] + first;
    const float *nx = t->nrm[0] + first, *ny = t->nrm[1] + first, *nz = t->nrm[2] + first;
    const float *pw = x->x.pw + first;
    const uint8_t *sd = x->x.side + first;
    /* as splat_mask_rasterize_z's (so > 0: the origin behind the plane);
     * cc: the plane's offset turned to the hiding side */
#if defined(__AVX512F__)
    const __m512 vnx = _mm512_loadu_ps(nx), vny = _mm512_loadu_ps(ny), vnz = _mm512_loadu_ps(nz);
    const __m512 vpx = _mm512_loadu_ps(px), vpy = _mm512_loadu_ps(py), vpz = _mm512_loadu_ps(pz);
    const __m512 c = _mm512_fmadd_ps(vpz, vnz, _mm512_fmadd_ps(vpy, vny, _mm512_mul_ps(vpx, vnx)));
    const __m512 so = _mm512_fmadd_ps(_mm512_sub_ps(vpz, _mm512_set1_ps(oz)), vnz,
                                      _mm512_fmadd_ps(_mm512_sub_ps(vpy, _mm512_set1_ps(oy)), vny,
                                                      _mm512_mul_ps(_mm512_sub_ps(vpx, _mm512_set1_ps(ox)), vnx)));
    const __mmask16 pos = _mm512_cmp_ps_mask(so, _mm512_setzero_ps(), _CMP_GT_OQ);
    const __m512 cc = _mm512_mask_sub_ps(c, pos, _mm512_setzero_ps(), c);
    __m512i side = _mm512_cvtepu8_epi32(_mm_loadu_si128((const __m128i *)sd));
    side = _mm512_mask_srli_epi32(side, pos, side, 1);
    uint32_t keep = _mm512_mask_cmp_ps_mask((__mmask16)any, _mm512_abs_ps(so), _mm512_loadu_ps(pw), _CMP_GT_OQ) &
                    _mm512_test_epi32_mask(side, _mm512_set1_epi32(1));
#else
    float so[16], cc[16];
    uint32_t keep = 0;
    for (uint32_t i = 0; i < 16; i++) {
        float c = px[i] * nx[i] + py[i] * ny[i] + pz[i] * nz[i];
        so[i] = (px[i] - ox) * nx[i] + (py[i] - oy) * ny[i] + (pz[i] - oz) * nz[i];
        cc[i] = so[i] > 0.0f ? -c : c;
        keep |= (uint32_t)((fabsf(so[i]) > pw[i]) & ((so[i] > 0.0f ? sd[i] >> 1 : sd[i]) & 1)) << i;
    }
    keep &= any;
#endif
    if (!keep)
        return;
    if (cdl_grow((void **)&x->held, &x->caph, x->nh + 1, sizeof *x->held)) {
        x->oom = 1;
        return;
    }
    mask_held *h = &x->held[x->nh++];
    h->first = first, h->mask = keep;
    memcpy(h->z, z, sizeof h->z);
#if defined(__AVX512F__)
    h->back = pos;
#else
    h->back = 0;
    for (uint32_t i = 0; i < 16; i++)
        h->back |= (uint32_t)(so[i] > 0.0f) << i;
#endif
    /* the planes, turned to the side that hides (the origin's other
     * side): a batch's lanes mostly share one, taken all at once */
#if defined(__AVX512F__)
    if (x->last < x->np && x->np <= PLANES) {
        /* all on the last batch's plane: their offsets' maximum kept in
         * lanes (reduced when the plane changes or the walk ends) */
        const cdl_skd_plane *P = &x->pl[x->last];
        const __m512 zero = _mm512_setzero_ps();
        __mmask16 on = _mm512_mask_cmp_ps_mask((__mmask16)keep, _mm512_mask_sub_ps(vnx, pos, zero, vnx),
                                               _mm512_set1_ps(P->n[0]), _CMP_EQ_OQ);
        on = _mm512_mask_cmp_ps_mask(on, _mm512_mask_sub_ps(vny, pos, zero, vny), _mm512_set1_ps(P->n[1]), _CMP_EQ_OQ);
        on = _mm512_mask_cmp_ps_mask(on, _mm512_mask_sub_ps(vnz, pos, zero, vnz), _mm512_set1_ps(P->n[2]), _CMP_EQ_OQ);
        if (on == (__mmask16)keep) {
            _mm512_storeu_ps(x->cmax, _mm512_mask_max_ps(_mm512_loadu_ps(x->cmax), on, _mm512_loadu_ps(x->cmax), cc));
            return;
        }
    }
#endif
    planes_flush(x);
    for (uint32_t m = keep; m && x->np <= PLANES;) {
        uint32_t i = (uint32_t)__builtin_ctz(m);
        const float n0x = nx[i], n0y = ny[i], n0z = nz[i];
#if defined(__AVX512F__)
        const int back = (int)(pos >> i & 1u);
        const float s0 = back ? -1.0f : 1.0f;
        __mmask16 same = _mm512_mask_cmp_ps_mask((__mmask16)m, vnx, _mm512_set1_ps(n0x), _CMP_EQ_OQ);
        same = _mm512_mask_cmp_ps_mask(same, vny, _mm512_set1_ps(n0y), _CMP_EQ_OQ);
        same = _mm512_mask_cmp_ps_mask(same, vnz, _mm512_set1_ps(n0z), _CMP_EQ_OQ);
        same &= back ? pos : (__mmask16)~pos;
        same |= (__mmask16)(1u << i); /* a NaN normal: alone */
        float c0 = _mm512_mask_reduce_max_ps(same, cc);
#else
        const float s0 = so[i] > 0.0f ? -1.0f : 1.0f;
        uint32_t same = 1u << i;
        float c0 = cc[i];
        for (uint32_t j = 0; j < 16; j++)
            if ((m >> j & 1u) && nx[j] == n0x && ny[j] == n0y && nz[j] == n0z && (so[j] > 0.0f ? -1.0f : 1.0f) == s0) {
                same |= 1u << j;
                c0 = cc[j] > c0 ? cc[j] : c0;
            }
#endif
        m &= ~(uint32_t)same;
        const float n[3] = {s0 * n0x, s0 * n0y, s0 * n0z}, c = c0 + x->x.eps;
        int k = x->last < x->np ? x->last : 0;
        if (!(k < x->np && x->pl[k].n[0] == n[0] && x->pl[k].n[1] == n[1] && x->pl[k].n[2] == n[2]))
            for (k = 0; k < x->np && !(x->pl[k].n[0] == n[0] && x->pl[k].n[1] == n[1] && x->pl[k].n[2] == n[2]); k++)
                ;
        if (k == x->np) {
            if (x->np++ == PLANES)
                break;
            x->pl[k] = (cdl_skd_plane){{n[0], n[1], n[2]}, c};
        } else if (c > x->pl[k].c)
            x->pl[k].c = c;
        x->last = k;
    }
}

/* The slot of the batch ray k belongs to, and its index there. */
static inline uint32_t slot_of(uint32_t k) { return k / SPLAT_MASK_BATCH & 1u; }

/* Ray k on worker wid: its occluders found; a buffer only if some sample
 * it feeds lies behind one's plane (else nothing can be hidden), made and
 * filled. */
static void build_ray(splat_state *s, uint32_t wid, uint32_t k)
{
    splat_mask *m = s->mask;
    mask_worker *x = &m->w[wid];
    const uint32_t sl = slot_of(k), i = k % SPLAT_MASK_BATCH;
    const cdl_photon_ray *r = &s->rays.r[k];
    m->roff[sl][i] = NONE;
    int g = cells_of(m, r);
    if (!g || !m->nocc || x->oom)
        return;
    ray_frame(s, r, g, &x->x);
    x->nh = 0;
    x->np = 0;
    x->last = 0;
    x->ntab = x->tlast = 0;
    for (int i = 0; i < 16; i++)
        x->cmax[i] = -INFINITY;
    cdl_splat_ray sr = splat_ray_of(s, r);
    cdl_skd_count cnt = {0, 0, 0};
    cdl_skd_splat_visit_both(&m->occ, &sr, CDL_SKD_ANY, collect, x, &cnt);
    planes_flush(x);
    if (!x->nh || x->oom ||
        (x->np <= PLANES && !cdl_skd_any_behind(&s->tree, &sr, s->opt.splat.cull ? CDL_SKD_CULL : 0, x->pl, x->np, m->pw, &cnt)))
        return;
    const uint32_t gg = (uint32_t)(g * g);
    for (uint32_t b = 0; b < x->nh && x->ntab <= MASK_PLANES; b++)
        plane_ids(x, &x->held[b]);
    const int planes = x->ntab <= MASK_PLANES;
    const uint32_t words = planes ? MASK_OCC + 4 * MASK_PLANES + gg : 2 * gg;
    if (cdl_grow((void **)&x->cells[sl], &x->capcell[sl], x->ncell[sl] + words, sizeof *x->cells[sl])) {
        x->oom = 1;
        return;
    }
    uint32_t *out = x->cells[sl] + x->ncell[sl];
    if (planes) {
        /* the filled cells' bits, the planes, and per cell its front
         * occluder's distance bits with its plane in the low bits,
         * rasterized in place */
        uint32_t *occ = out, *cz = out + MASK_OCC + 4 * MASK_PLANES;
        memcpy(out + MASK_OCC, x->tab, sizeof x->tab);
        for (uint32_t c = 0; c < gg; c++)
            cz[c] = (uint32_t)INT32_MAX;
        x->x.grid32 = cz;
        for (uint32_t b = 0; b < x->nh; b++)
            x->rasterized += (uint64_t)__builtin_popcount(
                splat_mask_rasterize_planes(&x->x, x->held[b].first, x->held[b].mask, x->held[b].z, x->held[b].pid));
        memset(occ, 0, sizeof *occ * MASK_OCC);
        uint32_t c = 0;
#if defined(__AVX512F__)
        for (; c + 16 <= gg; c += 16)
            occ[c >> 5] |= (uint32_t)_mm512_cmpneq_epi32_mask(_mm512_loadu_si512(cz + c), _mm512_set1_epi32(INT32_MAX))
                           << (c & 31);
#endif
        for (; c < gg; c++)
            occ[c >> 5] |= (uint32_t)(cz[c] != (uint32_t)INT32_MAX) << (c & 31);
    } else {
        uint64_t *grid = x->grid;
        memset(grid, 0xff, sizeof *grid * gg);
        x->x.grid = grid;
        for (uint32_t b = 0; b < x->nh; b++)
            x->rasterized += (uint64_t)__builtin_popcount(
                splat_mask_rasterize_z(&x->x, x->held[b].first, x->held[b].mask, x->held[b].z));
        /* split for the filter: one gather of distances, one of samples
         * where they are near enough */
        uint32_t *zg = out, *ig = zg + gg;
        for (uint32_t c = 0; c < gg; c++) {
            zg[c] = grid[c] == UINT64_MAX ? (uint32_t)INT32_MAX : (uint32_t)(grid[c] >> 32);
            ig[c] = (uint32_t)grid[c];
        }
    }
    m->roff[sl][i] = x->ncell[sl];
    m->rw[sl][i] = wid;
    m->rg[sl][i] = (uint8_t)(g | (planes ? RG_PLANES : 0));
    x->ncell[sl] += words;
    x->buffers++;
    x->planar += planes;
}

int splat_mask_begin(splat_state *s)
{
    splat_mask *m = s->mask;
    int nth = omp_get_max_threads();
    if (nth > m->nw) {
        mask_worker *w = aligned_alloc(64, sizeof *w * (size_t)nth); /* sizeof is a multiple of 64 */
        if (!w)
            return CDL_ERR_SYSTEM;
        if (m->nw)
            memcpy(w, m->w, sizeof *w * (size_t)m->nw);
        free(m->w);
        memset(w + m->nw, 0, sizeof *w * (size_t)(nth - m->nw));
        m->w = w;
        m->nw = nth;
    }
    for (int i = 0; i < m->nw; i++) {
        if (!m->w[i].grid && !(m->w[i].grid = malloc(sizeof(uint64_t) * MASK_G * MASK_G)))
            return CDL_ERR_SYSTEM;
        m->w[i].ncell[0] = m->w[i].ncell[1] = 0;
        m->w[i].oom = 0;
        m->w[i].rasterized = m->w[i].tested = m->w[i].buffers = m->w[i].planar = 0;
    }
    return 0;
}

void splat_mask_build(splat_state *s, uint32_t lo, uint32_t hi)
{
    const int wid = omp_get_thread_num();
    for (uint32_t k = lo; k < hi; k++)
        if (wid < s->mask->nw)
            build_ray(s, (uint32_t)wid, k);
        else /* more threads than at begin (never with one team): no buffer */
            s->mask->roff[slot_of(k)][k % SPLAT_MASK_BATCH] = NONE;
}

void splat_mask_recycle(splat_state *s, uint32_t k)
{
    const int wid = omp_get_thread_num();
    if (wid < s->mask->nw)
        s->mask->w[wid].ncell[slot_of(k)] = 0;
}

int splat_mask_end(splat_state *s)
{
    splat_mask *m = s->mask;
    int rc = 0;
    for (int i = 0; i < m->nw; i++) {
        if (m->w[i].oom)
            rc = CDL_ERR_SYSTEM;
        s->st.rasterized += m->w[i].rasterized;
        s->st.mask_tested += m->w[i].tested;
        s->st.mask_buffers += m->w[i].buffers;
        s->st.mask_planar += m->w[i].planar;
    }
    return rc;
}

int splat_mask_has(const splat_state *s, uint32_t k)
{
    return s->mask->roff[slot_of(k)][k % SPLAT_MASK_BATCH] != NONE;
}

int splat_mask_ray(const splat_state *s, uint32_t k, mask_ray *x)
{
    const splat_mask *m = s->mask;
    const uint32_t sl = slot_of(k), i = k % SPLAT_MASK_BATCH;
    if (m->roff[sl][i] == NONE)
        return 0;
    const uint32_t *b = m->w[m->rw[sl][i]].cells[sl] + m->roff[sl][i];
    ray_frame(s, &s->rays.r[k], m->rg[sl][i] & ~RG_PLANES, x);
    if (m->rg[sl][i] & RG_PLANES) {
        x->occ = b;
        x->tab = (const float *)(b + MASK_OCC);
        x->cz = b + MASK_OCC + 4 * MASK_PLANES;
    } else {
        x->zg = b;
        x->ig = b + (uint32_t)(x->g * x->g);
    }
    return 1;
}

uint32_t splat_mask_occluders(const splat_state *s) { return s->mask ? s->mask->nocc : 0; }
