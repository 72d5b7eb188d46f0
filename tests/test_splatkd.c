/* The eye-sample kd-tree of photon ray splatting (spatial/splatkd.c): the
 * frustum traversal (Algorithm 1), with and without culling nodes, whole
 * or part by part, finds exactly the feasible samples brute force finds,
 * with the same weights; the layout keeps its promises (8-byte nodes,
 * small leaves, culling nodes on coherent normals); the visibility mask's
 * one traversal (both visit) feeds exactly what the part-by-part visits
 * feed, and its frustum lanes hold every feasible one; parallel photon rays
 * onto a plane give the exact irradiance; a sample never receives light
 * from the side it does not show. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "spatial/splatkd.h"
#include "test_util.h"

static cdl_vec3 rand_dir(cdl_rng *r)
{
    float z = 1.0f - 2.0f * cdl_rng_float(r), phi = 2.0f * (float)CDL_PI * cdl_rng_float(r);
    float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return cdl_v3(s * cosf(phi), s * sinf(phi), z);
}

/* Samples on three walls of a unit box, a floor and a sphere; some two-sided. */
static uint32_t make_samples(cdl_rng *r, uint32_t n, cdl_vec3 *p, cdl_vec3 *nr, uint8_t *fl)
{
    for (uint32_t i = 0; i < n; i++) {
        float u = cdl_rng_float(r), v = cdl_rng_float(r);
        fl[i] = 0;
        switch (i % 5) {
        case 0: p[i] = cdl_v3(u, 0.0f, v), nr[i] = cdl_v3(0, 1, 0); break;
        case 1: p[i] = cdl_v3(0.0f, u, v), nr[i] = cdl_v3(1, 0, 0); break;
        case 2: p[i] = cdl_v3(u, v, 0.0f), nr[i] = cdl_v3(0, 0, 1); break;
        case 3: {
            cdl_vec3 d = rand_dir(r);
            p[i] = cdl_add(cdl_v3(0.5f, 0.4f, 0.5f), cdl_scale(d, 0.2f));
            nr[i] = d;
            break;
        }
        default: /* a thin two-sided panel */
            p[i] = cdl_v3(0.7f, 0.2f + 0.3f * u, 0.2f + 0.3f * v), nr[i] = cdl_v3(-1, 0, 0);
            fl[i] = CDL_SKD_TWO_SIDED;
            break;
        }
    }
    return n;
}

static int cmp_hit(const void *a, const void *b)
{
    const cdl_splat_hit *x = a, *y = b;
    return (x->s > y->s) - (x->s < y->s);
}

/* A range visitor appending its hits (iz checked against the 16-lane
 * visit's in the comparison with brute force). */
static void append_range(void *ctx, uint32_t first, uint32_t n, const uint16_t *mask, const float *w, const float *iz)
{
    cdl_splat_hits *out = ctx;
    if (n > CDL_SKD_CHUNK || (n % 16 && mask[n / 16] >> (n % 16))) /* lanes past the range */
        out->fail = 1;
    for (uint32_t i = 0; i < n; i++)
        if (mask[i / 16] >> (i % 16) & 1u) {
            if (!(w[i] > 0.0f)) /* a feasible lane weighing 0 */
                out->fail = 1;
            if (out->n == out->cap) {
                out->cap = out->cap ? 2 * out->cap : 1024;
                out->h = realloc(out->h, sizeof *out->h * out->cap);
            }
            out->h[out->n++] = (cdl_splat_hit){first + i, w[i], iz[i]};
        }
}

static void traversal(void)
{
    cdl_rng r;
    cdl_rng_seed(&r, 5, 7);
    uint32_t n = 20000;
    cdl_vec3 *p = malloc(sizeof *p * n), *nr = malloc(sizeof *nr * n);
    uint8_t *fl = malloc(n);
    make_samples(&r, n, p, nr, fl);
    cdl_skd t;
    cdl_skd_params prm;
    cdl_skd_params_default(&prm, sqrtf(3.0f));
    cdl_error err;
    die_on(cdl_skd_build(&t, p, nr, fl, n, &prm, &err), &err);
    CHECK(sizeof(cdl_skd_node) == 8, "8-byte nodes");
    uint32_t big = 0, covered = 0;
    for (uint32_t i = 0; i < t.nnodes; i++)
        if ((t.nodes[i].b & 15) == 3) {
            big += t.nodes[i].a > prm.leaf_size;
            covered += t.nodes[i].a;
        }
    CHECK(big == 0 && covered == n && t.culls > 0 && t.empties > 0,
          "%u leaves hold all %u samples, none over %u; %u culling and %u empty nodes, depth %u", t.leaves, covered,
          prm.leaf_size, t.culls, t.empties, t.depth);
    uint32_t parts_cover = 0;
    for (uint32_t k = 0; k < t.nparts; k++)
        parts_cover += t.parts[k].hi - t.parts[k].lo;
    CHECK(parts_cover == n && t.nparts > 8, "%u parts cover the samples once", t.nparts);
    cdl_splat_hits a = {0}, b = {0}, c = {0}, e = {0}, f = {0};
    uint32_t wrong = 0, total = 0, wdiff = 0;
    uint32_t izdiff = 0;
    uint64_t ranges_tested = 0, tested_cull = 0, tested_plain = 0, tested_slabs = 0, nodes_cull = 0, nodes_slabs = 0;
    for (int k = 0; k < 600; k++) {
        cdl_splat_ray ray;
        ray.o = cdl_v3(1.2f * cdl_rng_float(&r) - 0.1f, 1.2f * cdl_rng_float(&r) - 0.1f, 1.2f * cdl_rng_float(&r) - 0.1f);
        ray.d = rand_dir(&r);
        ray.on = k % 3 ? cdl_v3(0, 0, 0) : rand_dir(&r);
        ray.len = 1.5f * cdl_rng_float(&r);
        ray.h0 = 0.1f * cdl_rng_float(&r);
        ray.dh = k % 2 ? 0.0f : 0.2f * cdl_rng_float(&r);
        ray.cap = k % 3 == 1 ? 0.0f : 4.0f;
        ray.zmin = k % 3 ? 0.0f : 1e-3f;
        a.n = b.n = c.n = e.n = f.n = 0;
        cdl_skd_splat_brute(&t, UINT32_MAX, &ray, &a);
        uint64_t t0 = b.tested, n0 = b.nodes;
        cdl_skd_splat(&t, UINT32_MAX, &ray, CDL_SKD_CULL, &b);
        tested_cull += b.tested - t0;
        nodes_cull += b.nodes - n0;
        t0 = c.tested;
        for (uint32_t q = 0; q < t.nparts; q++) {
            if (k % 2) { /* part by part, a range a visit */
                cdl_skd_count pc = {0, 0, 0};
                cdl_skd_splat_visit_range(&t, q, &ray, k % 4 == 1 ? CDL_SKD_CULL : 0, append_range, &c, &pc);
                c.tested += pc.tested;
            } else {
                cdl_skd_splat(&t, q, &ray, k % 4 == 0 ? CDL_SKD_CULL : 0, &c);
            }
        }
        tested_plain += c.tested - t0;
        t0 = e.tested, n0 = e.nodes;
        cdl_skd_splat(&t, UINT32_MAX, &ray, CDL_SKD_CULL | CDL_SKD_SLABS, &e);
        tested_slabs += e.tested - t0;
        nodes_slabs += e.nodes - n0;
        cdl_skd_count cnt = {0, 0, 0};
        cdl_skd_splat_visit_range(&t, UINT32_MAX, &ray, CDL_SKD_CULL, append_range, &f, &cnt);
        ranges_tested += cnt.tested;
        cdl_splat_hits *all[5] = {&a, &b, &c, &e, &f};
        for (int o = 0; o < 5; o++)
            if (all[o]->n)
                qsort(all[o]->h, all[o]->n, sizeof *all[o]->h, cmp_hit);
        total += a.n;
        /* the leaf test runs 16 lanes with its own rounding: a sample on the
         * kernel's rim (weight ~ 0) may fall either side, and weights agree
         * to float rounding of the peak weight */
        float wmax = 0.0f;
        for (uint32_t i = 0; i < a.n; i++)
            wmax = fmaxf(wmax, a.h[i].w);
        const cdl_splat_hits *other[4] = {&b, &c, &e, &f};
        for (int o = 0; o < 4; o++) {
            const cdl_splat_hits *x = other[o];
            uint32_t i = 0, j = 0;
            while (i < a.n || j < x->n) {
                if (j >= x->n || (i < a.n && a.h[i].s < x->h[j].s)) {
                    wrong += a.h[i].w > 1e-3f * wmax;
                    i++;
                } else if (i >= a.n || x->h[j].s < a.h[i].s) {
                    wrong += x->h[j].w > 1e-3f * wmax;
                    j++;
                } else {
                    wdiff += fabsf(a.h[i].w - x->h[j].w) > 1e-4f * wmax;
                    /* z itself to rounding (1 / z amplifies z's error near 0) */
                    float za = a.h[i].iz > 0.0f ? 1.0f / a.h[i].iz : 0.0f;
                    float zb = x->h[j].iz > 0.0f ? 1.0f / x->h[j].iz : 0.0f;
                    izdiff += fabsf(za - zb) > 1e-5f * za + 1e-6f;
                    i++, j++;
                }
            }
        }
    }
    CHECK(wrong == 0 && wdiff == 0 && izdiff == 0 && total > 20000,
          "frustum traversal (bounding spheres, whole tree and part by part, 16 lanes or a range a visit; "
          "Algorithm 1's slabs) = brute force over 600 rays (%u feasible samples; %u found by one only, %u weights "
          "differ by more than 1e-4 of the ray's largest, %u distances z by more than 1e-5 z + 1e-6)",
          total, wrong, wdiff, izdiff);
    CHECK(ranges_tested == tested_cull && !f.fail && !c.fail,
          "the range visit tests the samples the 16-lane visit tests (%llu, %llu), its masks within the chunks",
          (unsigned long long)ranges_tested, (unsigned long long)tested_cull);
    CHECK(tested_cull < 20ull * total, "the traversal tests few samples per feasible one (%.2f)",
          (double)tested_cull / total);
    /* the wide tree tests whole small subtrees (branch-free 16-lane tests)
     * instead of descending: a few more samples, far fewer nodes */
    CHECK(tested_cull < 2 * tested_slabs && 4 * nodes_cull < nodes_slabs,
          "the wide bounding-sphere traversal tests %.2f samples per feasible one (Algorithm 1's slabs %.2f) and "
          "visits %.1f nodes per ray (slabs %.1f)",
          (double)tested_cull / total, (double)tested_slabs / total, nodes_cull / 600.0, nodes_slabs / 600.0);
    (void)tested_plain;
    free(a.h);
    free(b.h);
    free(c.h);
    free(e.h);
    free(f.h);
    cdl_skd_free(&t);
    free(p);
    free(nr);
    free(fl);
}

/* What a visit fed: sample, weight and 1 / z, bit for bit. */
typedef struct fed {
    uint32_t *s, n, cap, last, order_ok, outside, any;
    float *w, *iz;
} fed;

static void fed_add(fed *f, uint32_t q, float w, float iz)
{
    if (f->n == f->cap) {
        f->cap = f->cap ? 2 * f->cap : 1024;
        f->s = realloc(f->s, sizeof *f->s * f->cap);
        f->w = realloc(f->w, sizeof *f->w * f->cap);
        f->iz = realloc(f->iz, sizeof *f->iz * f->cap);
    }
    f->s[f->n] = q, f->w[f->n] = w, f->iz[f->n] = iz;
    f->n++;
}

static void fed_part(void *ctx, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *iz)
{
    (void)m;
    for (; mask; mask &= mask - 1) {
        int i = __builtin_ctz(mask);
        fed_add(ctx, first + (uint32_t)i, w[i], iz[i]);
    }
}

static void fed_both(void *ctx, uint32_t first, uint32_t m, uint32_t any, const float *z, uint32_t feasible,
                     const float *w, const float *iz)
{
    (void)m, (void)z;
    fed *f = ctx;
    f->order_ok &= first >= f->last;
    f->last = first;
    f->outside += (uint32_t)__builtin_popcount(feasible & ~any);
    f->any += (uint32_t)__builtin_popcount(any);
    fed_part(ctx, first, m, feasible, w, iz);
}

static void sort_fed(fed *f)
{
    for (uint32_t i = 1; i < f->n; i++) /* insertion sort: a few hundred, mostly in order */
        for (uint32_t j = i; j > 0 && f->s[j - 1] > f->s[j]; j--) {
            uint32_t s = f->s[j];
            float w = f->w[j], iz = f->iz[j];
            f->s[j] = f->s[j - 1], f->w[j] = f->w[j - 1], f->iz[j] = f->iz[j - 1];
            f->s[j - 1] = s, f->w[j - 1] = w, f->iz[j - 1] = iz;
        }
}

/* The both visit against the visits part by part, with and without
 * culling nodes and with the slabs. */
static void both_visit(void)
{
    cdl_rng r;
    cdl_rng_seed(&r, 11, 3);
    uint32_t n = 20000;
    cdl_vec3 *p = malloc(sizeof *p * n), *nr = malloc(sizeof *nr * n);
    uint8_t *fl = malloc(n);
    make_samples(&r, n, p, nr, fl);
    cdl_skd t;
    cdl_skd_params prm;
    cdl_skd_params_default(&prm, sqrtf(3.0f));
    cdl_error err;
    die_on(cdl_skd_build(&t, p, nr, fl, n, &prm, &err), &err);
    fed a = {0}, b = {0};
    uint32_t differ = 0, total = 0, outside = 0, order = 1, culled_any = 0;
    uint64_t anys = 0;
    const int flags[3] = {0, CDL_SKD_CULL, CDL_SKD_CULL | CDL_SKD_SLABS};
    for (int k = 0; k < 600; k++) {
        cdl_splat_ray ray;
        ray.o = cdl_v3(1.2f * cdl_rng_float(&r) - 0.1f, 1.2f * cdl_rng_float(&r) - 0.1f, 1.2f * cdl_rng_float(&r) - 0.1f);
        ray.d = rand_dir(&r);
        ray.on = k % 3 ? cdl_v3(0, 0, 0) : rand_dir(&r);
        ray.len = 1.5f * cdl_rng_float(&r);
        ray.h0 = 0.1f * cdl_rng_float(&r);
        ray.dh = k % 2 ? 0.0f : 0.2f * cdl_rng_float(&r);
        ray.cap = k % 3 == 1 ? 0.0f : 4.0f;
        ray.zmin = k % 3 ? 0.0f : 1e-3f;
        ray.otol = k % 5 ? 0.0f : 1e-3f;
        int f = flags[k % 3];
        cdl_skd_count cnt = {0, 0, 0};
        a.n = b.n = 0;
        b.last = 0, b.order_ok = 1, b.outside = 0, b.any = 0;
        for (uint32_t q = 0; q < t.nparts; q++)
            cdl_skd_splat_visit(&t, q, &ray, f, fed_part, &a, &cnt);
        cdl_skd_splat_visit_both(&t, &ray, f, fed_both, &b, &cnt);
        /* the parts come in order, so both lists are in tree order (not so
         * the slabs part by part: front to back) */
        if (f & CDL_SKD_SLABS)
            sort_fed(&a);
        differ += a.n != b.n;
        for (uint32_t i = 0; i < a.n && i < b.n; i++)
            differ += a.s[i] != b.s[i] || memcmp(&a.w[i], &b.w[i], 4) || memcmp(&a.iz[i], &b.iz[i], 4);
        total += a.n;
        outside += b.outside;
        order &= b.order_ok;
        anys += b.any;
        culled_any += (f & CDL_SKD_CULL) && b.any > b.n;
    }
    CHECK(differ == 0 && total > 20000 && order,
          "the both visit feeds what the part-by-part visits feed over 600 rays, bit for bit, in tree order "
          "(%u feasible samples, %u differ)",
          total, differ);
    CHECK(outside == 0 && anys > (uint64_t)total && culled_any > 0,
          "its frustum lanes (%.2f per feasible sample) hold every feasible one (%u outside)",
          (double)anys / total, outside);
    free(a.s), free(a.w), free(a.iz), free(b.s), free(b.w), free(b.iz);
    cdl_skd_free(&t);
    free(p);
    free(nr);
    free(fl);
}

/* Expected irradiance of parallel rays at angle theta onto a plane, as a
 * fraction of the exact phi / g^2 cos(theta): rays ending before a sample
 * reach it through the hemispherical cap of Algorithm 2, whose kernel is
 * renormalized over the cap's cross-section: exact at normal incidence,
 * low at oblique ones, 1/2 + cos(theta) 8/(3 pi) int_0^1 (1 - s^2)^(3/2) /
 * (1 - s^2 sin^2(theta))^2 ds. */
static double cap_factor(double theta)
{
    double sum = 0.0, sn = sin(theta);
    int n = 100000;
    for (int i = 0; i < n; i++) {
        double s = (i + 0.5) / n, q = 1.0 - s * s * sn * sn;
        sum += pow(1.0 - s * s, 1.5) / (q * q);
    }
    return 0.5 + cos(theta) * 8.0 / (3.0 * CDL_PI) * sum / n;
}

/* Parallel rays of flux phi each, one per cell of a jittered grid of
 * spacing g across the beam, onto the plane y = 0 at angle theta: the
 * irradiance phi / g^2 cos(theta) (times the cap's factor) away from the
 * edges, and nothing for a plane facing away. */
static void irradiance(float theta, float cap)
{
    cdl_rng r;
    cdl_rng_seed(&r, 8, 1);
    uint32_t n = 400;
    cdl_vec3 p[400], nr[400];
    for (uint32_t i = 0; i < n; i++) {
        p[i] = cdl_v3(0.4f + 0.2f * cdl_rng_float(&r), 0.0f, 0.4f + 0.2f * cdl_rng_float(&r));
        nr[i] = cdl_v3(0, 1, 0);
    }
    cdl_skd t;
    cdl_skd_params prm;
    cdl_skd_params_default(&prm, 1.0f);
    cdl_error err;
    die_on(cdl_skd_build(&t, p, nr, NULL, n, &prm, &err), &err);
    double *E = calloc(n, sizeof *E), *B = calloc(n, sizeof *B);
    float g = 0.004f, h = 0.05f;
    cdl_vec3 d = cdl_v3(sinf(theta), -cosf(theta), 0.0f);
    cdl_splat_hits hits = {0};
    for (int backside = 0; backside < 2; backside++) {
        for (int i = -150; i <= 150; i++)
            for (int j = -150; j <= 150; j++) {
                float a = ((float)i + cdl_rng_float(&r) - 0.5f) * g, b = ((float)j + cdl_rng_float(&r) - 0.5f) * g;
                cdl_vec3 hit = cdl_v3(0.5f + a / cosf(theta), 0.0f, 0.5f + b);
                cdl_splat_ray ray = {cdl_sub(hit, cdl_scale(d, 2.0f)), d, cdl_v3(0, 0, 0), 2.0f, h, 0.0f, cap, 0.0f, 0.0f};
                if (backside) { /* from below: the samples show their top */
                    ray.d = cdl_neg(d);
                    ray.o = cdl_add(hit, cdl_scale(d, 2.0f));
                }
                hits.n = 0;
                cdl_skd_splat(&t, UINT32_MAX, &ray, 1, &hits);
                for (uint32_t k = 0; k < hits.n; k++)
                    (backside ? B : E)[hits.h[k].s] += hits.h[k].w;
            }
    }
    double factor = cap > 0.0f ? 1.0 : cap_factor(theta);
    double want = 1.0 / ((double)g * g) * cos(theta) * factor, mean = 0.0, worst = 0.0, back = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        mean += E[i] / n;
        worst = fmax(worst, fabs(E[i] / want - 1.0));
        back += B[i];
    }
    CHECK(fabs(mean / want - 1.0) < 0.01 && worst < 0.05,
          "parallel rays at %.2f rad, %s cap: irradiance %.5g per unit flux, expected %.5g (factor %.4f; mean "
          "ratio %.4f, worst sample off by %.3f)",
          (double)theta, cap > 0.0f ? "tangent-plane" : "hemisphere", mean, want, factor, mean / want, worst);
    CHECK(back == 0.0, "rays from the side a sample does not show give it nothing (%g)", back);
    free(E);
    free(B);
    free(hits.h);
    cdl_skd_free(&t);
}

/* A ray leaving the back of a thin two-sided sheet feeds no sample on its
 * front (they face the ray and lie on the origin's tangent plane), but a
 * sample of a wall meeting the sheet in a concave corner is fed however
 * close to the sheet it lies. */
static void sheet(void)
{
    cdl_vec3 d = cdl_normalize(cdl_v3(0.3f, 0.0f, -1.0f));
    cdl_splat_ray ray = {cdl_v3(0, 0, 0), d, cdl_v3(0, 0, -1), 1.0f, 0.2f, 0.0f, 4.0f, 1e-5f, 0.0f};
    float z, front = cdl_splat_weight(&ray, cdl_v3(0.05f, 0.0f, 0.0f), cdl_v3(0, 0, 1), 0, &z);
    float wall = cdl_splat_weight(&ray, cdl_v3(0.05f, 0.0f, -1e-6f), cdl_v3(-1, 0, 0), 0, &z);
    ray.zmin = 0.0f;
    float leak = cdl_splat_weight(&ray, cdl_v3(0.05f, 0.0f, 0.0f), cdl_v3(0, 0, 1), 0, &z);
    CHECK(front == 0.0f && wall > 0.0f && leak > 0.0f,
          "sheet: the front of the sheet a ray leaves gets %g (%g with zmin 0), a corner's wall %g", (double)front,
          (double)leak, (double)wall);
}

int main(void)
{
    sheet();
    traversal();
    both_visit();
    irradiance(0.0f, 0.0f);
    irradiance(0.6f, 0.0f);
    irradiance(0.6f, 4.0f);
    irradiance(1.2f, 4.0f);
    return test_failures ? 1 : 0;
}
