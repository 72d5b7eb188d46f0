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
    uint32_t dup, ranges, in_ranges;
} hit_ctx;

static void mark(void *vc, uint32_t i, float d2)
{
    (void)d2;
    hit_ctx *c = vc;
    c->dup += c->seen[i];
    c->seen[i]++;
}

static void mark_range(void *vc, uint32_t a, uint32_t b)
{
    hit_ctx *c = vc;
    for (uint32_t i = a; i < b; i++)
        mark(vc, i, 0.0f);
    c->ranges++;
    c->in_ranges += b - a;
}

/* cdl_kd_ball_cells over the parts of a tree in tree order (the two
 * halves and the root point, each with the box of its points) against
 * brute force; ranges must lie in the ball and carry most points of big
 * balls. */
static void cells(void)
{
    cdl_rng r;
    cdl_rng_seed(&r, 11, 3);
    uint32_t n = 6000;
    float *pts = malloc(sizeof(float) * 4 * n), *sorted = malloc(sizeof(float) * 4 * n);
    for (uint32_t i = 0; i < n; i++) {
        pts[4 * i] = cdl_rng_float(&r);
        pts[4 * i + 1] = i % 3 ? 0.5f : cdl_rng_float(&r); /* most on a plane */
        pts[4 * i + 2] = i % 5 ? cdl_rng_float(&r) : 0.125f;
        pts[4 * i + 3] = 0.0f;
    }
    cdl_kdtree t;
    cdl_error err;
    die_on(cdl_kd_build(&t, pts, 4, n, &err), &err);
    for (uint32_t q = 0; q < n; q++)
        memcpy(&sorted[4 * q], &pts[4 * t.idx[q]], 4 * sizeof(float));
    t.pts = sorted;
    cdl_kd_make_identity(&t);
    uint32_t mid = n / 2, part[3][2] = {{0, mid}, {mid, mid + 1}, {mid + 1, n}};
    float lo[3][3], hi[3][3];
    for (int p = 0; p < 3; p++)
        for (int a = 0; a < 3; a++) {
            lo[p][a] = INFINITY;
            hi[p][a] = -INFINITY;
            for (uint32_t i = part[p][0]; i < part[p][1]; i++) {
                lo[p][a] = fminf(lo[p][a], sorted[4 * i + a]);
                hi[p][a] = fmaxf(hi[p][a], sorted[4 * i + a]);
            }
        }
    uint8_t *seen = calloc(n, 1);
    uint32_t wrong = 0, dups = 0, found = 0, outside = 0, ranges = 0, in_ranges = 0, counted = 0;
    for (int k = 0; k < 400; k++) {
        cdl_vec3 q = cdl_v3(cdl_rng_float(&r), k % 2 ? 0.5f : cdl_rng_float(&r), cdl_rng_float(&r));
        float rad = (k % 4 ? 0.4f : 0.05f) * cdl_rng_float(&r), r2 = rad * rad;
        memset(seen, 0, n);
        hit_ctx c = {seen, 0, 0, 0};
        for (int p = 0; p < 3; p++)
            counted += cdl_kd_ball_cells(&t, part[p][0], part[p][1], lo[p], hi[p], q, r2, mark, mark_range, &c);
        ranges += c.ranges;
        in_ranges += c.in_ranges;
        dups += c.dup;
        for (uint32_t i = 0; i < n; i++) {
            float dx = sorted[4 * i] - q.x, dy = sorted[4 * i + 1] - q.y, dz = sorted[4 * i + 2] - q.z;
            int in = dx * dx + dy * dy + dz * dz <= r2;
            wrong += (uint32_t)(in != (seen[i] > 0));
            found += (uint32_t)in;
            outside += (uint32_t)(!in && seen[i]);
        }
    }
    CHECK(wrong == 0 && dups == 0 && outside == 0 && counted == found && found > 100000,
          "cell ball queries = brute force (%u points found, %u wrong, %u twice, %u outside, %u counted)", found,
          wrong, dups, outside, counted);
    CHECK(in_ranges * 2 > found && ranges * 8 < in_ranges,
          "big balls report whole cells (%u of %u points in %u ranges)", in_ranges, found, ranges);
    float blo[3] = {0, 0, 0}, bhi[3] = {1, 1, 1};
    CHECK(cdl_kd_ball_cells(&t, 0, n + 1, blo, bhi, cdl_v3(0.5f, 0.5f, 0.5f), 1.0f, mark, mark_range,
                            &(hit_ctx){seen, 0, 0, 0}) == 0,
          "a range beyond the tree finds nothing");
    cdl_kd_free(&t);
    free(seen);
    free(pts);
    free(sorted);
}

int main(void)
{
    sampler();
    radius();
    cells();
    return test_failures ? 1 : 0;
}
