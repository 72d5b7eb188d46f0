/* Photon tracing (pm) against closed forms: the flux stored on a square
 * under a point light is I times its solid angle, under a spot light the
 * cone's power, inside a closed diffuse sphere of albedo a around a point
 * light the primary photons carry 4 pi I and all of them 4 pi I / (1 - a),
 * a distant light puts E A on a square and a constant sky 2 pi L A,
 * and the irradiance estimate there is I / ((1 - a) R^2); the maps are
 * bit-identical on 1, 2 and 3 threads; importance-driven deposition
 * (Keller & Wald 2000) keeps the flux (eps bound) or drops it (discard);
 * each map's flux does not depend on the caustic ratio q; budgets that
 * cannot be met are errors, quickly.
 * CDL_TEST_SCALE=k (the sanitizer run) traces k times fewer photons and
 * widens the noise tolerances by sqrt(k). */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "spatial/photon_map.h"
#include "transport/importance.h"
#include "transport/photons.h"
#include "test_pm_common.h"

/* ---- photon tracing ---- */

/* A Lambertian rectangle y = 0, x in [x0, x1], z in [z0, z1], facing up. */
static void add_floor(cdl_scene *s, float x0, float x1, float z0, float z1, float rho)
{
    cdl_error err;
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(rho, rho, rho);
    uint32_t mid, first;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    float p[12] = {x0, 0, z0, x1, 0, z0, x1, 0, z1, x0, 0, z1};
    die_on(cdl_scene_add_vertices(s, 4, p, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 1, mid, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 3, first + 2, mid, -1, 0, &err), &err);
}

/* Solid angle of the rectangle [x0,x1] x [z0,z1] on y = 0 seen from
 * (px, h, pz) above it: four rectangles with a corner at the foot point. */
static double corner_sa(double a, double b, double h)
{
    return atan(a * b / (h * sqrt(a * a + b * b + h * h)));
}
static double rect_sa(double x0, double x1, double z0, double z1, double px, double h, double pz)
{
    return corner_sa(x1 - px, z1 - pz, h) + corner_sa(px - x0, z1 - pz, h) + corner_sa(x1 - px, pz - z0, h) +
           corner_sa(px - x0, pz - z0, h);
}

typedef struct map_sums {
    double primary[3], all[3], sq; /* flux; sum of squared green flux */
    uint32_t nprimary, ncaustic_flag;
} map_sums;

static map_sums sums(const cdl_photon_map *m)
{
    map_sums r;
    memset(&r, 0, sizeof r);
    for (uint32_t i = 0; i < m->n; i++) {
        const cdl_photon *ph = &m->ph[i];
        for (int c = 0; c < 3; c++) {
            r.all[c] += ph->power[c];
            if (cdl_photon_flags(ph) & CDL_PH_PRIMARY)
                r.primary[c] += ph->power[c];
        }
        r.sq += (double)ph->power[1] * ph->power[1];
        r.nprimary += (cdl_photon_flags(ph) & CDL_PH_PRIMARY) != 0;
        r.ncaustic_flag += (cdl_photon_flags(ph) & CDL_PH_CAUSTIC) != 0;
    }
    return r;
}

static cdl_photon_params params(uint32_t target)
{
    cdl_photon_params pp;
    memset(&pp, 0, sizeof pp);
    pp.target = target;
    pp.q = 1.0f;
    pp.max_paths = (uint64_t)target * 1000u;
    return pp;
}

static int trace(const cdl_scene *s, const cdl_walk *w, const cdl_photon_params *pp, uint64_t seed, uint32_t pass,
                 cdl_photon_map *g, cdl_photon_map *c, cdl_photon_stats *st, cdl_error *err)
{
    return cdl_photons_trace(s, w, pp, CDL_SAMPLER_SOBOL, seed, pass, g, c, st, err);
}

/* Relative sd of a k-NN estimate from Poisson photons of equal flux:
 * sqrt(c / k) with c = E[w^2] / E[w]^2 of the kernel over the disc (box 1,
 * cone 3/2, epanechnikov 4/3), times n sum p^2 / (sum p)^2 for photons of
 * unequal flux. */
static double knn_sd(cdl_kernel kern, uint32_t k, uint32_t n, const map_sums *m)
{
    double c = kern == CDL_KERNEL_CONE ? 1.5 : kern == CDL_KERNEL_EPANECHNIKOV ? 4.0 / 3.0 : 1.0;
    double spread = (double)n * m->sq / (m->all[1] * m->all[1]);
    return sqrt(c * spread / (double)k);
}

/* A closed form at a random surface point: fills x, n, returns E (green). */
typedef double (*point_fn)(const void *ctx, cdl_vec3 *x, cdl_vec3 *n);

/* The irradiance estimate at M random points: its rms relative error must
 * be the k-NN noise (within 25 %; `bias` widens it for curvature), its
 * mean within 4 sd / sqrt(min(M, 500)) of the closed form's (the discs of
 * more points overlap: their errors are correlated; measured with 3000
 * points and six seeds: sd of the mean 0.37 %, not 0.22 %), no point
 * beyond 7 sd (the k-NN estimate's upper tail is long: 5.5 sd seen). */
static void knn_check(const cdl_photon_map *map, const cdl_pm_query *q, const char *what, int M, point_fn fn,
                      const void *ctx, double bias)
{
    map_sums m = sums(map);
    double sd = knn_sd(q->kernel, q->k, map->n, &m);
    double s2 = 0.0, st = 0.0, sr = 0.0, worst = 0.0;
    for (int i = 0; i < M; i++) {
        cdl_vec3 x, nrm;
        double Er = fn(ctx, &x, &nrm);
        double E = cdl_pmap_irradiance(map, q, x, nrm).y;
        s2 += (E / Er - 1.0) * (E / Er - 1.0);
        st += E;
        sr += Er;
        worst = fmax(worst, fabs(E / Er - 1.0));
    }
    double rms = sqrt(s2 / M), lim_mean = 4.0 * sd / sqrt(fmin((double)M, 500.0)) * tol_scale;
    CHECK(rms < 1.25 * sd * bias && fabs(st / sr - 1.0) < lim_mean && worst < 7.0 * sd * bias,
          "%s: %s k-NN irradiance (k %u) at %d points: rms error %.2f%% (k-NN noise %.2f%%), mean ratio %.5f "
          "(limit 1 +- %.2f%%), worst %.1f%% (limit %.1f%%)",
          what, kernel_name[q->kernel], q->k, M, 100 * rms, 100 * sd, st / sr, 100 * lim_mean, 100 * worst,
          700 * sd * bias);
}

typedef struct rect_ctx {
    cdl_vec3 lp;
    double I;
    double box[4]; /* x0, x1, z0, z1 of the query points */
} rect_ctx;

static double rect_E(const void *ctx, cdl_vec3 *x, cdl_vec3 *n)
{
    const rect_ctx *c = ctx;
    *x = cdl_v3((float)(c->box[0] + (c->box[1] - c->box[0]) * rnd()), 0.0f,
                (float)(c->box[2] + (c->box[3] - c->box[2]) * rnd()));
    *n = cdl_v3(0.0f, 1.0f, 0.0f);
    cdl_vec3 l = cdl_sub(c->lp, *x);
    double r2 = cdl_dot(l, l);
    return c->I * l.y / (r2 * sqrt(r2));
}

/* Photons from lights at infinity start on a disk covering the scene's
 * bounding sphere: a distant light of radiance (1, 2, 3) straight down on a
 * square of area A puts E A on it; a constant sky of radiance L on a
 * two-sided square 2 pi L A (pi L A on each side). The share of paths that
 * hit is A over the disk's area: binomial noise. */
static void lights_at_infinity(void)
{
    for (int sky = 0; sky < 2; sky++) {
        cdl_scene s;
        cdl_error err;
        die_on(cdl_scene_init(&s, sky ? "sky" : "distant", &err), &err);
        add_floor(&s, -1, 1, -1, 1, 0.5f);
        cdl_vec3 L = cdl_v3(1, 2, 3);
        if (sky)
            die_on(cdl_scene_add_infinite_light(&s, L, &err), &err);
        else
            die_on(cdl_scene_add_distant_light(&s, cdl_v3(0, -1, 0), L, &err), &err);
        die_on(cdl_scene_commit(&s, &err), &err);
        cdl_walk walk = {1, 3, 0};
        uint32_t target = 100000 / count_div;
        cdl_photon_params pp = params(target);
        cdl_photon_map g, c;
        cdl_pmap_init(&g);
        cdl_pmap_init(&c);
        cdl_photon_stats st;
        die_on(trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err), &err);
        double A = 4.0, R = sqrt(2.0), frac = (double)st.paths ? (double)g.n / (double)st.paths : 0.0;
        double expect = sky ? 2.0 * PI_D * A : A, hit = (sky ? 0.5 : 1.0) * A / (PI_D * R * R); /* the mean of |cos| over the sphere is 1/2 */
        map_sums m = sums(&g);
        double lim = fmax(4.0 * sqrt((1.0 - hit) / (double)target), 1e-3), worst = 0.0;
        for (int c3 = 0; c3 < 3; c3++)
            worst = fmax(worst, fabs(m.primary[c3] / (expect * (c3 + 1)) - 1.0));
        CHECK(worst < lim && fabs(frac / hit - 1.0) < 0.05,
              "%s: primary flux / %s off by %.3f%% (limit %.3f%%), %.3f of the paths hit (expected %.3f)",
              sky ? "constant sky over a two-sided square" : "distant light on a square",
              sky ? "2 pi L A" : "E A", 100 * worst, 100 * lim, frac, hit);
        cdl_pmap_free(&g);
        cdl_pmap_free(&c);
        cdl_scene_free(&s);
    }
}

static void point_light_square(void)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "square", &err), &err);
    const float I = 10.0f, h = 1.0f, X0 = -1.0f, X1 = 1.5f, Z0 = -1.0f, Z1 = 1.0f;
    const cdl_vec3 lp = cdl_v3(0.2f, h, -0.3f);
    add_floor(&s, X0, X1, Z0, Z1, 0.5f);
    die_on(cdl_scene_add_point_light(&s, lp, cdl_v3(I, 2 * I, 3 * I), &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    cdl_walk walk = {8, 3, 0};
    uint32_t target = 200000 / count_div;
    cdl_photon_params pp = params(target);
    cdl_photon_map g, c;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    cdl_photon_stats st;
    double t0 = now();
    die_on(trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err), &err);
    double t1 = now();
    double omega = rect_sa(X0, X1, Z0, Z1, lp.x, h, lp.z), frac = omega / (4.0 * PI_D);
    map_sums m = sums(&g);
    /* binomial: the share of paths that hit is frac, about target / frac paths */
    double sigma = sqrt((1.0 - frac) / (double)target);
    double lim = fmax(4.0 * sigma, 1e-3);
    double worst = 0.0;
    for (int c3 = 0; c3 < 3; c3++)
        worst = fmax(worst, fabs(m.primary[c3] / (I * (c3 + 1) * omega) - 1.0));
    CHECK(worst < lim,
          "point light over a rectangle: primary flux / (I Omega = %.4f I) off by %.4f%% (limit 4 binomial sigma "
          "= %.3f%%; %u photons from %llu paths in %.2f s)",
          omega, 100 * worst, 100 * lim, g.n, (unsigned long long)st.paths, t1 - t0);
    CHECK(g.n == target && m.nprimary == g.n && c.n == 0 && m.all[1] == m.primary[1],
          "an open rectangle: exactly %u photons (target %u), all primary (%u), no caustic photons (%u)", g.n, target,
          m.nprimary, c.n);
    CHECK(st.candidates == g.n && st.paths == st.paths_global && fabs((double)st.paths * frac / g.n - 1.0) < lim,
          "stats: %llu candidates, %llu paths (%llu global), hit share %.5f (Omega / 4 pi = %.5f)",
          (unsigned long long)st.candidates, (unsigned long long)st.paths, (unsigned long long)st.paths_global,
          (double)g.n / (double)st.paths, frac);
    /* every photon lies on the rectangle, arrived from the light, on the upper side */
    double worst_dir = 0.0, worst_pos = 0.0;
    int bad_n = 0, bad_light = 0;
    for (uint32_t i = 0; i < g.n; i++) {
        const cdl_photon *ph = &g.ph[i];
        cdl_vec3 p = cdl_v3(ph->p[0], ph->p[1], ph->p[2]);
        worst_pos = fmax(worst_pos, fabs(p.y));
        if (p.x < X0 - 1e-4f || p.x > X1 + 1e-4f || p.z < Z0 - 1e-4f || p.z > Z1 + 1e-4f)
            worst_pos = 1.0;
        worst_dir = fmax(worst_dir, angle_deg(cdl_photon_wi(ph), cdl_normalize(cdl_sub(lp, p))));
        bad_n += cdl_photon_n(ph).y < 0.999f;
        bad_light += cdl_photon_light(ph) != 0;
    }
    CHECK(worst_pos < 1e-4 && worst_dir < 0.01 && !bad_n && !bad_light,
          "photons on the rectangle (|y| <= %.2g), wi towards the light within %.4f deg, %d normals not up, %d "
          "with another light id",
          worst_pos, worst_dir, bad_n, bad_light);

    /* irradiance estimate against I cos / r^2: photons from QMC paths lie
     * like Poisson points, so the k-NN noise is the textbook one */
    uint32_t k = 100;
    cdl_pm_query q = {k, 0.1f * 0.1f, CDL_KERNEL_CONE, 0, malloc(sizeof(uint32_t) * k), malloc(sizeof(float) * k), {0}, 0, NULL, 0, 1.0f};
    rect_ctx rc = {lp, 2.0 * I, {X0 + 0.3, X1 - 0.3, Z0 + 0.3, Z1 - 0.3}};
    rng_state = 99;
    knn_check(&g, &q, "point light over a rectangle", 1000, rect_E, &rc, 1.0);
    free(q.idx);
    free(q.d2);

    /* deterministic: same (seed, pass) on 1, 2 and 3 threads; another pass differs */
    pp = params(60000 / count_div);
    die_on(trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err), &err);
    cdl_photon_map g2, c2;
    cdl_pmap_init(&g2);
    cdl_pmap_init(&c2);
    int nthreads = omp_get_max_threads(), same = 1;
    for (int t = 1; t <= 3; t++) {
        omp_set_num_threads(t);
        cdl_photon_stats st2;
        die_on(trace(&s, &walk, &pp, 1, 0, &g2, &c2, &st2, &err), &err);
        same &= g2.n == g.n && !memcmp(g2.ph, g.ph, sizeof(cdl_photon) * g.n) && st2.paths == st.paths;
    }
    omp_set_num_threads(nthreads);
    CHECK(same, "point light: bit-identical map of %u photons with 1, 2 and 3 threads", g.n);
    cdl_photon_stats st3;
    die_on(trace(&s, &walk, &pp, 1, 1, &g2, &c2, &st3, &err), &err);
    CHECK(g2.n == g.n && memcmp(g2.ph, g.ph, sizeof(cdl_photon) * g.n) != 0,
          "pass 1 gives another map of the same size (%u)", g2.n);

    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
    cdl_pmap_free(&g2);
    cdl_pmap_free(&c2);
    cdl_scene_free(&s);
}

/* A spot light straight down with cone 30 deg and falloff 10 deg over a
 * plane that catches the whole cone: the stored flux is the emitted power
 * 2 pi I (1 - cos_f + (cos_f - cos_t) / 5) (pbrt's quartic falloff). */
static void spot_light(void)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "spot", &err), &err);
    const float I = 5.0f;
    add_floor(&s, -3.0f, 3.0f, -3.0f, 3.0f, 0.5f);
    die_on(cdl_scene_add_spot_light(&s, cdl_v3(0.1f, 1.0f, 0.0f), cdl_v3(0.0f, -1.0f, 0.0f), cdl_v3(I, I, I), 30.0f,
                                    10.0f, &err),
           &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    cdl_walk walk = {8, 3, 0};
    uint32_t target = 200000 / count_div;
    cdl_photon_params pp = params(target);
    cdl_photon_map g, c;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    cdl_photon_stats st;
    die_on(trace(&s, &walk, &pp, 3, 0, &g, &c, &st, &err), &err);
    double ct = cos(30.0 * PI_D / 180.0), cf = cos(20.0 * PI_D / 180.0);
    double P = 2.0 * PI_D * I * (1.0 - cf + (cf - ct) / 5.0);
    map_sums m = sums(&g);
    /* every path hits: only the falloff weights vary. The paths of one pass
     * are independent samples (the Sobol sampler stratifies over passes),
     * so the sd is that of the mean weight: 0.18 % at 200000 photons */
    double sd = sqrt(fmax(0.0, m.sq - m.all[1] * m.all[1] / g.n)) / m.all[1];
    CHECK(st.paths == target && fabs(m.primary[1] / P - 1.0) < 4.0 * sd,
          "spot light: %llu paths for %u photons, flux / power %.5f (limit 1 +- %.2f%% = 4 sd)",
          (unsigned long long)st.paths, target, m.primary[1] / P, 400 * sd);
    double worst_cone = 0.0;
    for (uint32_t i = 0; i < g.n; i++) {
        cdl_vec3 wi = cdl_photon_wi(&g.ph[i]);
        worst_cone = fmax(worst_cone, angle_deg(wi, cdl_v3(0.0f, 1.0f, 0.0f)));
    }
    CHECK(worst_cone < 30.01, "spot light: photons within the 30 deg cone (widest %.4f deg)", worst_cone);
    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
    cdl_scene_free(&s);
}

/* Sphere of radius 1 around the origin, diffuse albedo a, no emission. */
static void build_sphere(cdl_scene *s, int nth, int nph, float albedo, double *area)
{
    cdl_error err;
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(albedo, albedo, albedo);
    uint32_t mid, first;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    int nv = (nth + 1) * (nph + 1);
    float *p = malloc(sizeof(float) * 3 * (size_t)nv);
    for (int i = 0; i <= nth; i++)
        for (int j = 0; j <= nph; j++) {
            float th = CDL_PI * (float)i / (float)nth, ph = 2.0f * CDL_PI * (float)j / (float)nph;
            float *q = p + 3 * (i * (nph + 1) + j);
            q[0] = sinf(th) * cosf(ph);
            q[1] = cosf(th);
            q[2] = sinf(th) * sinf(ph);
        }
    die_on(cdl_scene_add_vertices(s, (uint32_t)nv, p, NULL, NULL, &first, &err), &err);
    *area = 0.0;
    for (int i = 0; i < nth; i++)
        for (int j = 0; j < nph; j++) {
            uint32_t a = (uint32_t)(i * (nph + 1) + j), b = a + 1;
            uint32_t c = a + (uint32_t)(nph + 1), d = c + 1;
            die_on(cdl_scene_add_triangle(s, first + a, first + c, first + b, mid, -1, 0, &err), &err);
            die_on(cdl_scene_add_triangle(s, first + b, first + c, first + d, mid, -1, 0, &err), &err);
            uint32_t t[2][3] = {{a, c, b}, {b, c, d}};
            for (int k = 0; k < 2; k++) {
                cdl_vec3 A = cdl_v3(p[3 * t[k][0]], p[3 * t[k][0] + 1], p[3 * t[k][0] + 2]);
                cdl_vec3 B = cdl_v3(p[3 * t[k][1]], p[3 * t[k][1] + 1], p[3 * t[k][1] + 2]);
                cdl_vec3 C = cdl_v3(p[3 * t[k][2]], p[3 * t[k][2] + 1], p[3 * t[k][2] + 2]);
                *area += 0.5 * cdl_length(cdl_cross(cdl_sub(B, A), cdl_sub(C, A)));
            }
        }
    free(p);
}

typedef struct sphere_ctx {
    const cdl_scene *s;
    double E;
} sphere_ctx;

/* A random point of the mesh (triangle uniformly, then uniform in it:
 * near-uniform in area), its inward normal. */
static double sphere_E(const void *ctx, cdl_vec3 *x, cdl_vec3 *n)
{
    const sphere_ctx *c = ctx;
    const cdl_scene *s = c->s;
    uint32_t t = (uint32_t)(rnd() * s->ntris) % s->ntris;
    const uint32_t *ix = s->idx + 3 * t;
    double u = rnd(), v = rnd();
    if (u + v > 1.0)
        u = 1.0 - u, v = 1.0 - v;
    cdl_vec3 A = cdl_v3(s->pos[3 * ix[0]], s->pos[3 * ix[0] + 1], s->pos[3 * ix[0] + 2]);
    cdl_vec3 B = cdl_v3(s->pos[3 * ix[1]], s->pos[3 * ix[1] + 1], s->pos[3 * ix[1] + 2]);
    cdl_vec3 C = cdl_v3(s->pos[3 * ix[2]], s->pos[3 * ix[2] + 1], s->pos[3 * ix[2] + 2]);
    *x = cdl_add(A, cdl_add(cdl_scale(cdl_sub(B, A), (float)u), cdl_scale(cdl_sub(C, A), (float)v)));
    *n = s->face_n[t];
    if (cdl_dot(*n, *x) > 0.0f)
        *n = cdl_neg(*n);
    return c->E;
}

/* A point light at the centre of a closed diffuse sphere of albedo a:
 * photons of bounce d carry 4 pi I a^(d-1) in all; the irradiance is the
 * same everywhere, I / ((1 - a) R^2) (the polyhedron's area for 4 pi R^2). */
static void furnace(void)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "furnace", &err), &err);
    const float a = 0.5f, I = 2.0f;
    double area;
    build_sphere(&s, 64, 128, a, &area);
    die_on(cdl_scene_add_point_light(&s, cdl_v3(0.01f, 0.02f, -0.015f), cdl_v3(I, I, I), &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    cdl_walk walk = {64, 3, 0};
    uint32_t target = 300000 / count_div;
    cdl_photon_params pp = params(target);
    cdl_photon_map g, c;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    cdl_photon_stats st;
    double t0 = now();
    die_on(trace(&s, &walk, &pp, 5, 0, &g, &c, &st, &err), &err);
    double t1 = now();
    map_sums m = sums(&g);
    double P = 4.0 * PI_D * I, Pall = P / (1.0 - a);
    /* every path hits: the primary flux is exact up to rounding; the rest
     * carries the noise of the path lengths (Russian roulette): sd about
     * sqrt(sum of squared photon fluxes) */
    double sd = sqrt(m.sq) / Pall;
    double lim = fmax(5.0 * sd, 2e-3) * tol_scale;
    CHECK(fabs(m.primary[1] / P - 1.0) < 1e-4 && m.nprimary == st.paths,
          "furnace: %u primary photons (one per path, %llu paths) carry %.6f of 4 pi I", m.nprimary,
          (unsigned long long)st.paths, m.primary[1] / P);
    CHECK(fabs(m.all[1] / Pall - 1.0) < lim,
          "furnace: all photons carry %.5f of 4 pi I / (1 - a) (limit %.2f%% = 5 sd; %u photons in %.2f s)",
          m.all[1] / Pall, 100 * lim, g.n, t1 - t0);
    CHECK(m.all[0] == m.all[1] && m.all[2] == m.all[1] && m.primary[0] == m.primary[1] &&
              m.primary[2] == m.primary[1],
          "furnace: white light, grey walls: the three channels carry the same flux");
    CHECK(g.n >= target && g.n < target + (uint32_t)walk.maxdepth + 2,
          "furnace: %u photons for a target of %u (the last path's photons on top)", g.n, target);
    /* irradiance at random points of the wall, normal inwards */
    uint32_t k = 200;
    cdl_pm_query q = {k, 0.2f * 0.2f, CDL_KERNEL_EPANECHNIKOV, 0, malloc(sizeof(uint32_t) * k),
                      malloc(sizeof(float) * k), {0}, 0, NULL, 0, 1.0f};
    sphere_ctx sc = {&s, Pall / area};
    rng_state = 4242;
    knn_check(&g, &q, "furnace", 1000, sphere_E, &sc, 1.0);
    /* seen from outside, nothing arrived */
    double outside = 0.0;
    for (int i = 0; i < 50; i++) {
        cdl_vec3 x, n;
        sphere_E(&sc, &x, &n);
        outside += cdl_pmap_irradiance(&g, &q, x, cdl_neg(n)).y;
    }
    CHECK(outside == 0.0, "furnace: irradiance on the outside of the wall %g", outside);
    free(q.idx);
    free(q.d2);
    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
    cdl_scene_free(&s);
}

/* Floor, a mirror sphere on it, a diffuse ceiling, a point and a spot
 * light: both maps, several light ids, both caustic-selection modes. */
static void build_room(cdl_scene *s)
{
    cdl_error err;
    die_on(cdl_scene_init(s, "room", &err), &err);
    add_floor(s, -2.0f, 2.0f, -2.0f, 2.0f, 0.7f);
    cdl_material ceil_m = cdl_material_default(CDL_MAT_DIFFUSE);
    uint32_t cm, first, mm;
    die_on(cdl_scene_add_material(s, &ceil_m, &cm, &err), &err);
    float p[12] = {-2, 2, -2, 2, 2, -2, 2, 2, 2, -2, 2, 2};
    die_on(cdl_scene_add_vertices(s, 4, p, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, cm, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, cm, -1, 0, &err), &err);
    cdl_material mirror = cdl_material_default(CDL_MAT_MIRROR);
    mirror.ks = cdl_v3(0.9f, 0.9f, 0.9f);
    die_on(cdl_scene_add_material(s, &mirror, &mm, &err), &err);
    die_on(cdl_scene_add_sphere(s, cdl_v3(0.3f, 0.5f, 0.2f), 0.5f, mm, -1, 0, &err), &err);
    die_on(cdl_scene_add_point_light(s, cdl_v3(-0.5f, 1.5f, 0.0f), cdl_v3(3.0f, 3.0f, 3.0f), &err), &err);
    die_on(cdl_scene_add_spot_light(s, cdl_v3(1.0f, 1.8f, -1.0f), cdl_v3(-0.5f, -1.0f, 0.5f), cdl_v3(8.0f, 6.0f, 4.0f),
                                    40.0f, 5.0f, &err),
           &err);
    die_on(cdl_scene_commit(s, &err), &err);
}

static void room_determinism(void)
{
    cdl_scene s;
    cdl_error err;
    build_room(&s);
    cdl_walk walk = {16, 3, 0};
    uint32_t target = 40000 / count_div;
    int nthreads = omp_get_max_threads();
    double gflux[3], cflux[3], gsd2[3], csd2[3]; /* green flux of both maps, relative variance */
    for (int mode = 0; mode < 3; mode++) {
        cdl_photon_params pp = params(target);
        pp.q = mode == 0 ? 1.0f : 0.25f;
        pp.caustic_random = mode == 2;
        cdl_photon_map g[3], c[3];
        cdl_photon_stats st[3];
        for (int t = 0; t < 3; t++) {
            cdl_pmap_init(&g[t]);
            cdl_pmap_init(&c[t]);
            omp_set_num_threads(t + 1);
            die_on(trace(&s, &walk, &pp, 7, 2, &g[t], &c[t], &st[t], &err), &err);
        }
        omp_set_num_threads(nthreads);
        int same = 1;
        for (int t = 1; t < 3; t++)
            same &= g[t].n == g[0].n && c[t].n == c[0].n && !memcmp(g[t].ph, g[0].ph, sizeof(cdl_photon) * g[0].n) &&
                    !memcmp(c[t].ph, c[0].ph, sizeof(cdl_photon) * c[0].n) && st[t].paths == st[0].paths &&
                    st[t].candidates == st[0].candidates;
        const char *name[] = {"q = 1", "q = 0.25 prefix", "q = 0.25 random"};
        map_sums mg = sums(&g[0]), mc = sums(&c[0]);
        gflux[mode] = mg.all[1];
        cflux[mode] = mc.all[1];
        gsd2[mode] = mg.sq / (mg.all[1] * mg.all[1]);
        csd2[mode] = mc.sq / (mc.all[1] * mc.all[1]);
        uint32_t lights[2] = {0, 0};
        for (uint32_t i = 0; i < g[0].n; i++)
            lights[cdl_photon_light(&g[0].ph[i]) & 1]++;
        CHECK(same && g[0].n >= target && c[0].n > 0,
              "room, %s: %u global + %u caustic photons from %llu paths (%llu for the global map), identical on "
              "1, 2 and 3 threads",
              name[mode], g[0].n, c[0].n, (unsigned long long)st[0].paths, (unsigned long long)st[0].paths_global);
        CHECK(mc.ncaustic_flag == c[0].n && mg.ncaustic_flag == 0 && lights[0] > 0 && lights[1] > 0,
              "room, %s: caustic flags only in the caustic map (%u of %u), photons of both lights (%u, %u)", name[mode],
              mc.ncaustic_flag, c[0].n, lights[0], lights[1]);
        if (mode == 1) {
            /* prefix: floor(q N) paths fill the global map, all N the caustic map */
            CHECK(st[0].paths == (uint64_t)floor((double)st[0].paths_global / 0.25),
                  "prefix selection: %llu paths in all = floor(%llu / q)", (unsigned long long)st[0].paths,
                  (unsigned long long)st[0].paths_global);
        }
        for (int t = 0; t < 3; t++) {
            cdl_pmap_free(&g[t]);
            cdl_pmap_free(&c[t]);
        }
    }
    /* the flux of each map does not depend on q: prefix selection keeps the
     * very paths of q = 1 for the global map (same seed: the same flux);
     * random selection stores a photon with probability q and flux / q; the
     * caustic map fills from 4 times the paths (noise: 4 sd, the sd of a
     * sum of photon fluxes about sqrt(sum of squares)) */
    double lg = 4.0 * sqrt(gsd2[0] + gsd2[2]), lc1 = 4.0 * sqrt(csd2[0] + csd2[1]), lc2 = 4.0 * sqrt(csd2[0] + csd2[2]);
    CHECK(fabs(gflux[1] / gflux[0] - 1.0) < 1e-5 && fabs(gflux[2] / gflux[0] - 1.0) < lg,
          "global flux q = 0.25 / q = 1: prefix %.6f (the same paths), random %.4f (limit 1 +- %.1f%%)",
          gflux[1] / gflux[0], gflux[2] / gflux[0], 100 * lg);
    CHECK(fabs(cflux[1] / cflux[0] - 1.0) < lc1 && fabs(cflux[2] / cflux[0] - 1.0) < lc2,
          "caustic flux q = 0.25 / q = 1: prefix %.4f (limit 1 +- %.1f%%), random %.4f (limit 1 +- %.1f%%)",
          cflux[1] / cflux[0], 100 * lc1, cflux[2] / cflux[0], 100 * lc2);
    cdl_scene_free(&s);
}

/* Importance-driven deposition (Keller & Wald 2000 §2.1): a camera sees
 * the left part of a plane under a point light. With the bound eps the
 * flux stays (unbiased) while the unseen part keeps about eps of its
 * photons; with discard the unseen flux is gone. */
static void importance(void)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "importance", &err), &err);
    const float I = 4.0f, h = 1.0f;
    add_floor(&s, -2.0f, 2.0f, -2.0f, 2.0f, 0.5f);
    die_on(cdl_scene_add_point_light(&s, cdl_v3(0.0f, h, 0.0f), cdl_v3(I, I, I), &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);
    cdl_camera cam;
    die_on(cdl_camera_init(&cam, cdl_v3(-1.0f, 3.0f, 0.0f), cdl_v3(-1.0f, 0.0f, 0.0f), cdl_v3(0.0f, 0.0f, -1.0f), 30.0f,
                           64, 64, &err),
           &err);
    cdl_walk walk = {8, 3, 0};
    cdl_importance imp;
    die_on(cdl_importance_build(&imp, &s, &cam, &walk, 32768, 1024, 0.1f, CDL_SAMPLER_SOBOL, 1, &err), &err);
    const double omega = rect_sa(-2, 2, -2, 2, 0, h, 0), P = I * omega;
    uint32_t target = 40000 / count_div;
    const float eps = 0.05f;
    double share[3], flux[3], sdv[3];
    cdl_photon_map g, c, g0;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    cdl_pmap_init(&g0);
    int far_kept_discard = 0, channels_differ = 0;
    for (int mode = 0; mode < 3; mode++) {
        cdl_photon_params pp = params(target);
        pp.imp = mode ? &imp : NULL;
        pp.eps = eps;
        pp.discard = mode == 2;
        cdl_photon_stats st;
        die_on(trace(&s, &walk, &pp, 11, 0, &g, &c, &st, &err), &err);
        uint32_t nfar = 0;
        for (uint32_t i = 0; i < g.n; i++)
            nfar += g.ph[i].p[0] > 0.5f;
        share[mode] = (double)nfar / (double)st.paths; /* far photons per path */
        map_sums m = sums(&g);
        flux[mode] = m.primary[1];
        if (m.primary[0] != m.primary[1] || m.primary[2] != m.primary[1])
            channels_differ = 1;
        sdv[mode] = sqrt(m.sq);
        if (mode == 2)
            far_kept_discard = (int)nfar;
        if (mode == 0) {
            /* eps = 1: p is 1 everywhere, the very same map as without importance */
            cdl_photon_params p1 = pp;
            p1.imp = &imp;
            p1.eps = 1.0f;
            cdl_photon_stats st1;
            cdl_photon_map c1;
            cdl_pmap_init(&c1);
            die_on(trace(&s, &walk, &p1, 11, 0, &g0, &c1, &st1, &err), &err);
            CHECK(g0.n == g.n && !memcmp(g0.ph, g.ph, sizeof(cdl_photon) * g.n),
                  "importance with eps = 1 stores the same map as without (%u photons)", g0.n);
            cdl_pmap_free(&c1);
        }
    }
    CHECK(imp.n > 0 && imp.f > 0.0f, "importons: %u from %llu paths, f = %.4g", imp.n, (unsigned long long)imp.paths,
          imp.f);
    double r = share[1] / share[0];
    CHECK(r > 0.6 * eps && r < 1.6 * eps,
          "unseen part (x > 0.5): photons per path with importance / without = %.4f (eps = %.2f)", r, eps);
    /* binomial noise without importance; with it the photons' own spread */
    double frac = omega / (4.0 * PI_D), lim0 = 4.0 * sqrt((1.0 - frac) / target);
    double lim = fmax(5.0 * sdv[1] / P, lim0);
    CHECK(fabs(flux[0] / P - 1.0) < lim0 && fabs(flux[1] / P - 1.0) < lim,
          "flux without importance %.5f (limit 1 +- %.2f%% = 4 binomial sd), with (eps bound) %.5f of I Omega "
          "(limit 1 +- %.2f%% = 5 sd)",
          flux[0] / P, 100 * lim0, flux[1] / P, 100 * lim);
    CHECK(!channels_differ, "importance: white light, grey floor: the three channels carry the same flux");
    CHECK(far_kept_discard == 0 && flux[2] / P < 0.9,
          "discard: %d photons kept in the unseen part, flux %.4f of I Omega (biased low)", far_kept_discard,
          flux[2] / P);
    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
    cdl_pmap_free(&g0);
    cdl_importance_free(&imp);
    cdl_scene_free(&s);
}

/* ---- budgets that cannot be met ---- */

static void expect_error(const char *what, int rc, const cdl_error *err, const char *needle, double secs,
                         const cdl_photon_map *g)
{
    char buf[2048] = "";
    if (rc)
        cdl_error_format(err, buf, sizeof buf);
    CHECK(rc != 0 && strstr(buf, needle) && secs < 10.0 && g->n == 0,
          "%s: code %d in %.2f s, maps emptied (%u photons), message: %s", what, rc, secs, g->n, buf);
}

static void budgets(void)
{
    cdl_error err;
    cdl_walk walk = {8, 3, 0};
    cdl_photon_map g, c;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    cdl_photon_stats st;

    /* a spot light pointing up, away from the only surface */
    {
        cdl_scene s;
        die_on(cdl_scene_init(&s, "spot-away", &err), &err);
        add_floor(&s, -1, 1, -1, 1, 0.5f);
        die_on(cdl_scene_add_spot_light(&s, cdl_v3(0, 1, 0), cdl_v3(0, 1, 0), cdl_v3(1, 1, 1), 30.0f, 0.0f, &err),
               &err);
        die_on(cdl_scene_commit(&s, &err), &err);
        cdl_photon_params pp = params(1000);
        double t0 = now();
        int rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("light facing away from everything", rc, &err, "cannot be met", now() - t0, &g);
        /* the same with a large budget: must still give up early */
        pp = params(1000000);
        t0 = now();
        rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("light facing away, 10^6 photons", rc, &err, "cannot be met", now() - t0, &g);
        cdl_scene_free(&s);
    }
    /* a tiny square the light mostly misses (share 3e-5): the projection gives up */
    {
        cdl_scene s;
        die_on(cdl_scene_init(&s, "tiny", &err), &err);
        add_floor(&s, -0.01f, 0.01f, -0.01f, 0.01f, 0.5f);
        die_on(cdl_scene_add_point_light(&s, cdl_v3(0, 1, 0), cdl_v3(1, 1, 1), &err), &err);
        die_on(cdl_scene_commit(&s, &err), &err);
        cdl_photon_params pp = params(10000);
        pp.max_paths = 200000;
        double t0 = now();
        int rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("tiny square, 10^4 photons within 2e5 paths", rc, &err, "cannot be met", now() - t0, &g);
        /* the hard limit below 2^16 paths */
        pp = params(100);
        pp.max_paths = 5000;
        t0 = now();
        rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("tiny square, 100 photons within 5000 paths", rc, &err, "cannot be met", now() - t0, &g);
        /* a budget that can be met is met: about 3.2e-5 stored per path */
        pp = params(20);
        pp.max_paths = 10000000;
        rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        CHECK(rc == 0 && g.n == 20, "tiny square, 20 photons within 10^7 paths: code %d, %u photons from %llu paths",
              rc, g.n, (unsigned long long)st.paths);
        cdl_scene_free(&s);
    }
    /* only a mirror: no photon can be stored */
    {
        cdl_scene s;
        die_on(cdl_scene_init(&s, "mirror", &err), &err);
        cdl_material mirror = cdl_material_default(CDL_MAT_MIRROR);
        uint32_t mm;
        die_on(cdl_scene_add_material(&s, &mirror, &mm, &err), &err);
        die_on(cdl_scene_add_sphere(&s, cdl_v3(0, 0, 0), 1.0f, mm, -1, 0, &err), &err);
        die_on(cdl_scene_add_point_light(&s, cdl_v3(0, 2, 0), cdl_v3(1, 1, 1), &err), &err);
        die_on(cdl_scene_commit(&s, &err), &err);
        cdl_photon_params pp = params(1000);
        double t0 = now();
        int rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("only a mirror", rc, &err, "cannot be met", now() - t0, &g);
        cdl_scene_free(&s);
    }
    /* a zero target is refused */
    {
        cdl_scene s;
        die_on(cdl_scene_init(&s, "zero", &err), &err);
        add_floor(&s, -1, 1, -1, 1, 0.5f);
        die_on(cdl_scene_add_point_light(&s, cdl_v3(0, 1, 0), cdl_v3(1, 1, 1), &err), &err);
        die_on(cdl_scene_commit(&s, &err), &err);
        cdl_photon_params pp = params(0);
        pp.max_paths = 1000;
        double t0 = now();
        int rc = trace(&s, &walk, &pp, 1, 0, &g, &c, &st, &err);
        expect_error("zero photons", rc, &err, "at least 1", now() - t0, &g);
        cdl_scene_free(&s);
    }
    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
}

int main(void)
{
    test_scale_init();
    double t2 = now();
    point_light_square();
    lights_at_infinity();
    spot_light();
    furnace();
    double t3 = now();
    room_determinism();
    double t3b = now();
    importance();
    double t4 = now();
    budgets();
    double t5 = now();
    printf("times: tracing %.2f s, room %.2f s, importance %.2f s, budgets %.2f s\n", t3 - t2, t3b - t3,
           t4 - t3b, t5 - t4);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
