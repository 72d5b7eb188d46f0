/* The point kd-tree against brute force: k nearest neighbours (with and
 * without a radius limit) and ball queries on uniform, clustered and
 * degenerate (coplanar, duplicated) point sets. */
#include <string.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "spatial/pointkd.h"
#include "test_util.h"

typedef struct ball_ctx {
    uint8_t *seen;
    uint32_t dup;
} ball_ctx;

static void mark(void *vc, uint32_t i, float d2)
{
    (void)d2;
    ball_ctx *c = vc;
    if (c->seen[i])
        c->dup++;
    c->seen[i] = 1;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

static void run(const char *name, int kind, uint32_t n)
{
    cdl_rng r;
    cdl_rng_seed(&r, 7, (uint64_t)kind);
    float *pts = malloc(sizeof(float) * 4 * n); /* stride 4: like a store with padding */
    for (uint32_t i = 0; i < n; i++) {
        float *p = pts + 4 * i;
        p[0] = cdl_rng_float(&r);
        p[1] = cdl_rng_float(&r);
        p[2] = kind == 2 ? 0.5f : cdl_rng_float(&r); /* coplanar */
        if (kind == 1) {                               /* clusters */
            float s = 0.02f;
            int c = (int)(cdl_rng_float(&r) * 8.0f);
            p[0] = 0.1f * (float)c + s * p[0];
            p[1] = 0.3f + s * p[1];
            p[2] = 0.7f - 0.05f * (float)c + s * p[2];
        }
        if (kind == 3 && i % 3 == 1) /* duplicates */
            memcpy(p, pts + 4 * (i - 1), 3 * sizeof(float));
        if (kind == 4 && i < 150) { /* a shell: many nearly equal distances from its centre */
            cdl_vec3 d = cdl_sample_uniform_sphere(p[0], p[1]);
            float rad = 0.05f + 1e-6f * (p[2] - 0.5f);
            p[0] = 0.5f + rad * d.x, p[1] = 0.5f + rad * d.y, p[2] = 0.5f + rad * d.z;
        }
        p[3] = 0.0f;
    }
    cdl_kdtree t;
    cdl_error err;
    die_on(cdl_kd_build(&t, pts, 4, n, &err), &err);
    float *all = malloc(sizeof(float) * n);
    uint8_t *seen = calloc(n, 1);
    uint32_t out[64], gout[256];
    float d2[64], gd2[256], guess = 0.0f;
    int knn_bad = 0, ball_bad = 0, order_bad = 0, guess_bad = 0;
    for (int qi = 0; qi < 300; qi++) {
        cdl_vec3 q = cdl_v3(cdl_rng_float(&r) * 1.2f - 0.1f, cdl_rng_float(&r), cdl_rng_float(&r));
        if (kind == 4 && qi % 2)
            q = cdl_v3(0.5f, 0.5f, 0.5f);
        uint32_t k = 1 + (uint32_t)(cdl_rng_float(&r) * 63.0f);
        float max_d2 = qi % 2 ? 0.01f : INFINITY;
        for (uint32_t i = 0; i < n; i++) {
            const float *p = pts + 4 * i;
            float dx = p[0] - q.x, dy = p[1] - q.y, dz = p[2] - q.z;
            all[i] = dx * dx + dy * dy + dz * dz;
        }
        uint32_t got = cdl_kd_knn(&t, q, k, max_d2, out, d2);
        /* brute force: the k-th smallest distance within the limit */
        float *sorted = malloc(sizeof(float) * n);
        memcpy(sorted, all, sizeof(float) * n);
        qsort(sorted, n, sizeof(float), cmp_float);
        uint32_t want = 0;
        while (want < k && want < n && sorted[want] <= max_d2)
            want++;
        if (got != want)
            knn_bad++;
        for (uint32_t j = 0; j < got && j < want; j++) {
            if (d2[j] != sorted[j] || all[out[j]] != d2[j])
                knn_bad++;
            if (j && d2[j] < d2[j - 1])
                order_bad++;
        }
        /* the guessed ball and the k-th distance by histogram: right
         * whatever the guess: carried over from the last
         * query, none, far too small, or so large the buffer overflows */
        float g = qi % 5 == 0 ? 1e-8f : qi % 7 == 0 ? 10.0f : qi % 11 == 0 ? 0.0f : guess;
        guess = g;
        uint32_t cap = k + 1 + (uint32_t)(qi % 3) * k;
        float kth;
        uint32_t gn = cdl_kd_knn_guess(&t, q, k, max_d2, &guess, cap, gout, gd2, &kth);
        /* with k points in reach: kth is the k-th distance, and the points
         * include every one nearer; else exactly those within max_d2 */
        if (want == k ? kth != sorted[k - 1] || gn < k : kth != -1.0f || gn != want)
            guess_bad++;
        uint32_t nearer = 0;
        for (uint32_t j = 0; j < gn; j++) {
            if (all[gout[j]] != gd2[j] || gd2[j] > max_d2)
                guess_bad++;
            nearer += want < k || gd2[j] < kth;
        }
        uint32_t expect_nearer = 0;
        for (uint32_t j = 0; j < want; j++)
            expect_nearer += want < k || sorted[j] < kth;
        if (nearer != expect_nearer)
            guess_bad++;
        for (uint32_t j = 1; j < gn; j++) /* no point twice */
            for (uint32_t i = 0; i < j; i++)
                if (gout[i] == gout[j])
                    guess_bad++;
        free(sorted);
        /* ball query: exactly the points within r */
        float r2 = 0.002f + 0.02f * cdl_rng_float(&r);
        memset(seen, 0, n);
        ball_ctx bc = {seen, 0};
        uint32_t cnt = cdl_kd_ball(&t, q, r2, mark, &bc);
        uint32_t expect = 0;
        for (uint32_t i = 0; i < n; i++) {
            int in = all[i] <= r2;
            expect += (uint32_t)in;
            if (in != seen[i])
                ball_bad++;
        }
        if (cnt != expect || bc.dup)
            ball_bad++;
    }
    CHECK(knn_bad == 0 && order_bad == 0, "%s (%u points): k-NN matches brute force in 300 queries (%d mismatches, %d out of order)",
          name, n, knn_bad, order_bad);
    CHECK(guess_bad == 0, "%s: k-NN by a guessed ball and selection matches brute force (%d mismatches)", name,
          guess_bad);
    CHECK(ball_bad == 0, "%s: ball queries find exactly the points within r, each once (%d mismatches)", name, ball_bad);
    free(all);
    free(seen);
    free(pts);
    cdl_kd_free(&t);
}

int main(void)
{
    run("uniform", 0, 5000);
    run("clustered", 1, 5000);
    run("coplanar", 2, 3000);
    run("duplicates", 3, 3000);
    run("shell", 4, 3000);
    run("tiny", 0, 3);
    cdl_kdtree t;
    cdl_error err;
    float bad[6] = {0, 0, 0, NAN, 1, 1};
    CHECK(cdl_kd_build(&t, bad, 3, 2, &err) != 0, "a NaN point is refused: %s", err.msg);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
