/* splat's occlusion test (occlusion, on by default): a photon ray feeds
 * an eye sample only if nothing lies between the sample and the point of
 * the ray it stands for. Algorithm 2's kernel reaches through walls: a ray
 * in one room lands within h of the floor, walls and ceiling of the next
 * room under a shared wall, and light leaks through door gaps and thin
 * walls. The test is exact: from the sample (lifted off its surface by a
 * ray offset) to c, the ray's point nearest to it (its hit point for
 * samples beyond it), a segment must be free. Most splats need no shadow
 * ray: each pass gives every eye sample its clearance (scene/clearance.c),
 * the radius of the half-ball in front of its surface that holds no
 * geometry, and a c inside it is seen. Only splats near an occluder trace
 * a ray.
 * Samples that receive light from both sides (rough glass) are not tested.
 * This is candela's; the report's §8.1 mask (visibility_mask) only
 * approximates visibility by the eye samples the camera sees. */
#include <math.h>
#include <stdlib.h>

#include "integrators/splat/occlusion.h"
#include "scene/clearance.h"

struct splat_occl {
    float *rho; /* per eye sample (tree order): its clearance; INFINITY: not tested */
    float *up;  /* per eye sample: free distance along its normal (the lift's bound) */
    uint32_t cap;
};

void splat_occl_free(splat_state *s)
{
    if (s->occl) {
        free(s->occl->rho);
        free(s->occl->up);
    }
    free(s->occl);
    s->occl = NULL;
}

size_t splat_occl_bytes(const splat_state *s)
{
    return s->occl ? 2 * (size_t)s->occl->cap * sizeof(float) : 0;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

int splat_occl_prepare(splat_state *s, cdl_error *err)
{
    if (!s->occl && !(s->occl = calloc(1, sizeof *s->occl)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the occlusion test");
    struct splat_occl *o = s->occl;
    if (o->cap < s->neye + 16) {
        float *r = realloc(o->rho, sizeof(float) * (s->neye + 16));
        if (r)
            o->rho = r;
        float *u = r ? realloc(o->up, sizeof(float) * (s->neye + 16)) : NULL;
        if (!u)
            return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the occlusion test");
        o->up = u;
        o->cap = s->neye + 16;
    }
    /* clearances out to the reach of most kernels past their hits (the
     * 95th percentile of 1024 rays' widest radius): a wider one's splats
     * beyond it trace rays */
    float hs[1024];
    uint32_t nh = 0;
    for (uint32_t k = 0; k < s->rays.n && nh < 1024; k += s->rays.n / 1024 + 1) {
        const cdl_photon_ray *r = &s->rays.r[k];
        hs[nh++] = r->h0 + r->dh * r->len;
    }
    qsort(hs, nh, sizeof *hs, cmp_float);
    float reach = nh ? hs[nh * 95 / 100] : 0.0f;
    reach *= 1.0f + (s->opt.splat.cap > 0.0f ? s->opt.splat.cap : 1.0f);
    const cdl_skd *t = &s->tree;
#pragma omp parallel for schedule(dynamic, 256)
    for (uint32_t q = 0; q < s->neye; q++) {
        if (t->two[q] > 0.0f) {
            o->rho[q] = INFINITY;
            continue;
        }
        cdl_vec3 x = cdl_v3(t->p[0][q], t->p[1][q], t->p[2][q]), n = cdl_v3(t->nrm[0][q], t->nrm[1][q], t->nrm[2][q]);
        o->rho[q] = cdl_clearance(s->scene, x, n, reach);
        /* the lift's bound: half way to what lies above the sample, from
         * where the camera's ray found it */
        cdl_hit h;
        float m = cdl_maxf(fabsf(x.x), cdl_maxf(fabsf(x.y), fabsf(x.z)));
        cdl_vec3 a = cdl_madd(x, s->eye[q].wo, 2.0f * (s->scene->eps + m * 1e-5f));
        o->up[q] = cdl_intersect(s->scene, a, n, reach, &h) ? 0.5f * h.t : reach;
    }
    return 0;
}

/* The segment of splat (r, q) to test, from the sample lifted off its
 * surface to c, the ray's point that stands for it: 0 when the sample's
 * clearance settles it (seen), else 1 with the segment in *o, *d, *len. */
static int segment(const splat_state *s, const cdl_photon_ray *r, uint32_t q, float iz, cdl_vec3 *o, cdl_vec3 *d,
                   float *len)
{
    float rho = s->occl->rho[q];
    if (rho == INFINITY)
        return 0;
    const cdl_skd *t = &s->tree;
    cdl_vec3 x = cdl_v3(t->p[0][q], t->p[1][q], t->p[2][q]);
    /* c kept off the surfaces at the ray's ends by two ray offsets: on a
     * wall of zero thickness the hit point is on both of its sides */
    float m = cdl_maxf(fabsf(x.x), cdl_maxf(fabsf(x.y), fabsf(x.z)));
    float e = 2.0f * (s->scene->eps + m * 1e-5f), z = iz > 0.0f ? 1.0f / iz : 0.0f;
    z = z < r->len - e ? z : r->len - e;
    cdl_vec3 c = cdl_madd(r->o, r->d, z > e ? z : cdl_minf(e, 0.5f * r->len));
    cdl_vec3 v = cdl_sub(c, x);
    if (cdl_dot(v, v) < rho * rho)
        return 0;
    /* back along the camera's path to the sample: its side of the surface
     * even where a sheet of zero thickness meets a wall; then lifted along
     * its normal by a quarter of the kernel's radius at c (less where
     * something lies nearer above), as pm lifts its queries: a segment
     * that grazes the surface is blocked by any step on it (a rug's edge,
     * a skirting board), which left those splats out and read dark near
     * every such step, a bias that falls only with the kernels */
    *o = cdl_madd(x, s->eye[q].wo, e);
    float lift = cdl_minf(0.25f * (r->h0 + r->dh * z), s->occl->up[q]);
    if (lift > 0.0f)
        *o = cdl_madd(*o, cdl_v3(t->nrm[0][q], t->nrm[1][q], t->nrm[2][q]), lift);
    cdl_vec3 ac = cdl_sub(c, *o);
    *len = cdl_length(ac);
    if (!(*len > 0.0f))
        return 0;
    *d = cdl_scale(ac, 1.0f / *len);
    return 1;
}

int splat_occl_seen(const splat_state *s, const cdl_photon_ray *r, uint32_t q, float iz, uint64_t *rays)
{
    cdl_vec3 o, d;
    float len;
    if (!segment(s, r, q, iz, &o, &d, &len))
        return 1;
    (*rays)++;
    return !cdl_occluded(s->scene, o, d, len);
}

/* The lanes that need a ray go to Embree as one packet of 16: they start
 * in one leaf of the tree and end near one photon ray, so they are
 * coherent. */
uint32_t splat_occl_filter(const splat_state *s, const cdl_photon_ray *r, uint32_t first, uint32_t mask,
                           const float *iz, uint64_t *rays)
{
    /* Embree reads the packet and its valid mask with aligned 64-byte loads */
    struct RTCRay16 p;
    _Alignas(64) int valid[16];
    uint32_t need = 0;
    for (uint32_t i = 0; i < 16; i++) {
        cdl_vec3 o, d;
        float len;
        valid[i] = 0;
        if (!(mask >> i & 1u) || !segment(s, r, first + i, iz[i], &o, &d, &len))
            continue;
        valid[i] = -1;
        need |= 1u << i;
        p.org_x[i] = o.x;
        p.org_y[i] = o.y;
        p.org_z[i] = o.z;
        p.dir_x[i] = d.x;
        p.dir_y[i] = d.y;
        p.dir_z[i] = d.z;
        p.tnear[i] = 0.0f;
        p.tfar[i] = len;
        p.time[i] = 0.0f;
        p.mask[i] = 0xFFFFFFFFu;
        p.id[i] = i;
        p.flags[i] = 0;
    }
    if (!need)
        return mask;
    int nn = __builtin_popcount(need);
    *rays += (uint64_t)nn;
    uint32_t keep = mask;
    if (nn < 4) { /* a sparse packet costs more than its rays alone */
        for (uint32_t m = need; m; m &= m - 1) {
            uint32_t i = (uint32_t)__builtin_ctz(m);
            if (cdl_occluded(s->scene, cdl_v3(p.org_x[i], p.org_y[i], p.org_z[i]),
                             cdl_v3(p.dir_x[i], p.dir_y[i], p.dir_z[i]), p.tfar[i]))
                keep &= ~(1u << i);
        }
        return keep;
    }
    cdl_shadow_ctx sc;
    rtcInitIntersectContext(&sc.ctx);
    sc.ctx.flags = s->scene->ninsts ? RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT : RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    sc.skip_sphere = UINT32_MAX;
    rtcOccluded16(valid, s->scene->rtc, &sc.ctx, &p);
    for (uint32_t i = 0; i < 16; i++)
        if ((need >> i & 1u) && p.tfar[i] < 0.0f)
            keep &= ~(1u << i);
    return keep;
}
