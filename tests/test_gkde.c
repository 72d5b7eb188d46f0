/* gkde's building blocks: the stratified trial-link sampler (eq. 10) draws
 * each candidate m a_i / W times in expectation, m in total, and the
 * estimate it gives is unbiased; footprint radii follow eq. 7; ball
 * queries restricted to kd subtrees (the parts threads own) find exactly
 * the points brute force finds, each once. */
#include <math.h>
#include <string.h>

#include "core/rng.h"
#include "spatial/pointkd.h"
#include "test_util.h"
#include "transport/gkde_link.h"

static void sampler(void)
{
    cdl_rng r;
    cdl_rng_seed(&r, 3, 1);
    enum { K = 40, TRIALS = 200000 };
    double a[K], f[K], W = 0.0, truth = 0.0;
    for (int i = 0; i < K; i++) {
        /* weights over three orders of magnitude, as 1 / (R^2 cos) are */
        a[i] = exp(7.0 * cdl_rng_float(&r));
        f[i] = cdl_rng_float(&r) * (i % 3 ? 1.0 : 10.0);
        W += a[i];
        truth += f[i];
    }
    for (int mi = 0; mi < 2; mi++) {
        double m = mi ? 10.0 : 7.5; /* whole and fractional draw counts */
        double drawn[K] = {0}, est = 0.0, est2 = 0.0;
        uint32_t bad_total = 0;
        for (int t = 0; t < TRIALS; t++) {
            cdl_strat s;
            cdl_strat_init(&s, m, W, cdl_rng_float(&r));
            uint32_t total = 0;
            double e = 0.0;
            for (int i = 0; i < K; i++) {
                uint32_t k = cdl_strat_next(&s, a[i]);
                total += k;
                drawn[i] += k;
                if (k)
                    e += f[i] * k / (m * a[i] / W); /* weight / expected draws */
            }
            bad_total += total != (uint32_t)floor(m) && total != (uint32_t)ceil(m);
            est += e;
            est2 += e * e;
        }
        CHECK(bad_total == 0, "m = %.1f: every trial draws floor(m) or ceil(m) links (%u did not)", m,
              bad_total);
        double worst = 0.0;
        for (int i = 0; i < K; i++) {
            double expect = m * a[i] / W * TRIALS;
            /* a stratified draw count differs from its mean by less than one */
            double z = fabs(drawn[i] - expect) / sqrt(expect + 1.0);
            worst = z > worst ? z : worst;
        }
        CHECK(worst < 5.0, "m = %.1f: each candidate drawn m a_i / W times on average (worst %.2f sigma)", m,
              worst);
        double mean = est / TRIALS, sd = sqrt((est2 / TRIALS - mean * mean) / TRIALS);
        CHECK(fabs(mean - truth) < 4.0 * sd + 1e-9, "m = %.1f: estimate %.5f vs sum %.5f (sigma %.2g)", m, mean,
              truth, sd);
    }
    cdl_strat s;
    cdl_strat_init(&s, 3.0, 0.0, 0.5);
    CHECK(cdl_strat_next(&s, 1.0) == 0, "no weight: nothing drawn");
}

static void radius(void)
{
    float r1 = cdl_footprint_radius(0.01f, 4.0f, 0.0f, INFINITY);
    float r2 = cdl_footprint_radius(0.01f, 0.25f, r1, INFINITY);
    CHECK(fabsf(r1 - 0.005f) < 1e-7f && fabsf(r2 - 0.025f) < 1e-7f, "eq. 7: R_1 = h / sqrt(p), R_2 = h / sqrt(p) + R_1 (%g, %g)",
          (double)r1, (double)r2);
    CHECK(cdl_footprint_radius(0.01f, 0.0f, r1, INFINITY) == r1, "after a specular bounce the footprint carries on");
    CHECK(cdl_footprint_radius(0.01f, 0.25f, r1, 0.01f) == 0.01f, "capped");
}

typedef struct hit_ctx {
    uint8_t *seen;
    uint32_t dup;
} hit_ctx;

static void mark(void *vc, uint32_t i, float d2)
{
    (void)d2;
    hit_ctx *c = vc;
    c->dup += c->seen[i];
    c->seen[i]++;
}

/* Leaf subtrees of [lo, hi) at `depth` levels plus the node points above
 * them, as gkde splits its eye points. */
static void query_parts(const cdl_kdtree *t, uint32_t lo, uint32_t hi, int depth, cdl_vec3 q, float r2,
                        hit_ctx *c, uint32_t *parts)
{
    if (lo >= hi)
        return;
    if (depth == 0 || hi - lo < 4) {
        cdl_kd_ball_range(t, lo, hi, q, r2, mark, c);
        (*parts)++;
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    cdl_kd_ball_range(t, mid, mid + 1, q, r2, mark, c);
    query_parts(t, lo, mid, depth - 1, q, r2, c, parts);
    query_parts(t, mid + 1, hi, depth - 1, q, r2, c, parts);
}

static void subtrees(void)
{
    cdl_rng r;
    cdl_rng_seed(&r, 9, 2);
    uint32_t n = 5000;
    float *pts = malloc(sizeof(float) * 4 * n);
    for (uint32_t i = 0; i < n; i++) {
        pts[4 * i] = cdl_rng_float(&r);
        pts[4 * i + 1] = i % 2 ? 0.25f : cdl_rng_float(&r); /* half of them coplanar */
        pts[4 * i + 2] = cdl_rng_float(&r);
        pts[4 * i + 3] = 0.0f;
    }
    cdl_kdtree t;
    cdl_error err;
    die_on(cdl_kd_build(&t, pts, 4, n, &err), &err);
    uint8_t *seen = calloc(n, 1);
    uint32_t wrong = 0, dups = 0, found = 0;
    for (int k = 0; k < 300; k++) {
        cdl_vec3 q = cdl_v3(cdl_rng_float(&r), k % 2 ? 0.25f : cdl_rng_float(&r), cdl_rng_float(&r));
        float rad = 0.3f * cdl_rng_float(&r), r2 = rad * rad;
        memset(seen, 0, n);
        hit_ctx c = {seen, 0};
        uint32_t parts = 0;
        query_parts(&t, 0, n, 1 + k % 6, q, r2, &c, &parts);
        dups += c.dup;
        for (uint32_t i = 0; i < n; i++) {
            float dx = pts[4 * i] - q.x, dy = pts[4 * i + 1] - q.y, dz = pts[4 * i + 2] - q.z;
            int in = dx * dx + dy * dy + dz * dz <= r2;
            wrong += (uint32_t)(in != (seen[i] > 0));
            found += (uint32_t)in;
        }
    }
    CHECK(wrong == 0 && dups == 0 && found > 1000,
          "ball queries over kd subtrees and node points = brute force (%u points found, %u wrong, %u twice)",
          found, wrong, dups);
    CHECK(cdl_kd_ball_range(&t, 0, n + 1, cdl_v3(0.5f, 0.5f, 0.5f), 1.0f, mark, &(hit_ctx){seen, 0}) == 0,
          "a range beyond the tree finds nothing");
    cdl_kd_free(&t);
    free(seen);
    free(pts);
}

int main(void)
{
    sampler();
    radius();
    subtrees();
    return test_failures ? 1 : 0;
}
