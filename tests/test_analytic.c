/* Analytic scenes (DESIGN.md, Verification):
 *  - white furnace: inside a closed sphere of albedo a emitting L_e the
 *    radiance is L_e / (1 - a) everywhere;
 *  - a Lambertian plane under a point light: L = rho/pi * I cos(theta) / r^2.
 * Usage: test_analytic [INTEGRATOR] (default path). */
#include <math.h>
#include <string.h>

#include "test_util.h"

/* CDL_TEST_SCALE=k (the sanitizer run) renders k times fewer samples and
 * widens the noise tolerances by sqrt(k): the numbers are still checked,
 * the statistics just carry the noise that fewer samples leave. */
static double tol_scale = 1.0;
static uint32_t spp_div = 1;

/* Point-light methods (ir, rigi) trace K light paths per pass: a few suffice
 * here, and their passes cost more, so they get fewer of them. */
static uint32_t method_setup(const char *integ, cdl_options *opt, uint32_t spp)
{
    spp = spp / spp_div > 16 ? spp / spp_div : 16;
    if (!strcmp(integ, "rigi") || !strcmp(integ, "ir")) {
        opt->light_paths = 8;
        return spp / 16 > 16 ? spp / 16 : 16;
    }
    return spp;
}

/* Sphere of radius 1, triangles wound so their CCW normal points inwards:
 * the emitting front face looks at the camera inside. */
static void build_sphere(cdl_scene *s, int nth, int nph, float albedo, float le)
{
    cdl_error err;
    die_on(cdl_scene_init(s, "furnace", &err), &err);
    cdl_material m;
    memset(&m, 0, sizeof m);
    m.type = CDL_MAT_DIFFUSE;
    m.kd = cdl_v3(albedo, albedo, albedo);
    m.kd_tex = -1;
    uint32_t mid, first;
    int32_t emit;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    die_on(cdl_scene_add_emitter(s, cdl_v3(le, le, le), 0, &emit, &err), &err);
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
    free(p);
    for (int i = 0; i < nth; i++)
        for (int j = 0; j < nph; j++) {
            uint32_t a = first + (uint32_t)(i * (nph + 1) + j), b = a + 1;
            uint32_t c = a + (uint32_t)(nph + 1), d = c + 1;
            /* (a, b, c) would face outwards */
            die_on(cdl_scene_add_triangle(s, a, c, b, mid, emit, 0, &err), &err);
            die_on(cdl_scene_add_triangle(s, b, c, d, mid, emit, 0, &err), &err);
        }
    die_on(cdl_scene_commit(s, &err), &err);
}

static void furnace(const char *integ)
{
    cdl_scene s;
    build_sphere(&s, 24, 48, 0.8f, 1.0f);
    /* the inward winding must be right, or nothing emits towards us */
    cdl_vec3 n = s.face_n[s.ntris / 2];
    const float *v = s.pos + 3 * s.idx[3 * (s.ntris / 2)];
    CHECK(n.x * v[0] + n.y * v[1] + n.z * v[2] < 0.0f, "furnace sphere faces inwards");
    cdl_options opt;
    cdl_options_default(&opt);
    opt.maxdepth = 1024;
    cdl_error err;
    int W = 2, H = 2;
    die_on(cdl_camera_init(&opt.camera, cdl_v3(0.1f, -0.2f, 0.05f), cdl_v3(0.3f, 0.1f, -1.0f),
                           cdl_v3(0.0f, 1.0f, 0.0f), 90.0f, W, H, &err),
           &err);
    cdl_film f;
    /* bdpt connects every eye vertex to every light vertex: with paths of
     * 5 bounces on average (tails to hundreds) its sample costs 10x path's,
     * and at a quarter of the samples its worst pixel is still off by only
     * 0.16 % (limit 1 %) */
    uint32_t spp = method_setup(integ, &opt, strcmp(integ, "bdpt") ? 250000 : 62500);
    render_film(integ, &s, &opt, W, H, spp, &f);
    double mean = 0.0, worst = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                double v = film_pixel(&f, x, y, c);
                mean += v;
                worst = fmax(worst, fabs(v / 5.0 - 1.0));
            }
    mean /= 3.0 * W * H;
    CHECK(fabs(mean / 5.0 - 1.0) < 0.005 * tol_scale, "%s furnace: image mean %.4f, expected 5 (within %.1f%%)",
          integ, mean, 0.5 * tol_scale);
    CHECK(worst < 0.01 * tol_scale, "%s furnace: worst pixel off by %.2f%% (limit %.0f%%)", integ, 100.0 * worst,
          tol_scale);
    CHECK(f.nonfinite == 0, "%s furnace: %llu non-finite samples", integ, (unsigned long long)f.nonfinite);
    cdl_film_free(&f);
    cdl_scene_free(&s);
}

/* A Lambertian square y = 0, |x|, |z| <= 10, facing up, of albedo rho. */
static void add_ground(cdl_scene *s, float rho)
{
    cdl_error err;
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(rho, rho, rho);
    uint32_t mid, first;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    float p[12] = {-10, 0, -10, 10, 0, -10, 10, 0, 10, -10, 0, 10};
    die_on(cdl_scene_add_vertices(s, 4, p, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 1, mid, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 3, first + 2, mid, -1, 0, &err), &err);
}

static void plane(const char *integ)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "plane", &err), &err);
    const float rho = 0.5f, I = 10.0f, h = 1.0f;
    add_ground(&s, rho);
    cdl_vec3 lp = cdl_v3(0.3f, h, -0.2f);
    die_on(cdl_scene_add_point_light(&s, lp, cdl_v3(I, I, I), &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);

    cdl_options opt;
    cdl_options_default(&opt);
    opt.maxdepth = 4; /* an open plane: nothing to bounce off */
    int W = 24, H = 16;
    die_on(cdl_camera_init(&opt.camera, cdl_v3(0.2f, 4.0f, 0.5f), cdl_v3(0.0f, 0.0f, 0.0f),
                           cdl_v3(0.0f, 0.0f, -1.0f), 60.0f, W, H, &err),
           &err);
    cdl_film f;
    /* pixel jitter noise: worst pixel ~0.4 % */
    render_film(integ, &s, &opt, W, H, method_setup(integ, &opt, 8192), &f);
    double worst = 0.0, mean_t = 0.0, mean_r = 0.0;
    enum { SUB = 32 };
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            /* closed form averaged over the pixel on a SUB x SUB grid */
            double ref = 0.0;
            for (int j = 0; j < SUB; j++)
                for (int i = 0; i < SUB; i++) {
                    cdl_vec3 d = cdl_camera_ray(&opt.camera, (float)x + (i + 0.5f) / SUB,
                                                (float)y + (j + 0.5f) / SUB);
                    if (d.y >= 0.0f)
                        continue;
                    float t = -opt.camera.eye.y / d.y;
                    cdl_vec3 q = cdl_madd(opt.camera.eye, d, t);
                    if (fabsf(q.x) > 10.0f || fabsf(q.z) > 10.0f)
                        continue;
                    cdl_vec3 l = cdl_sub(lp, q);
                    double r2 = cdl_dot(l, l), cos_t = l.y / sqrt(r2);
                    ref += rho / 3.14159265358979323846 * I * cos_t / r2;
                }
            ref /= SUB * SUB;
            double v = film_pixel(&f, x, y, 1);
            mean_t += v;
            mean_r += ref;
            worst = fmax(worst, fabs(v - ref) / ref);
        }
    CHECK(worst < 0.01 * tol_scale, "%s plane under point light: worst pixel %.3f%% off the closed form (limit %.0f%%)",
          integ, 100.0 * worst, tol_scale);
    CHECK(fabs(mean_t / mean_r - 1.0) < 0.002 * tol_scale, "%s plane: image mean ratio %.5f", integ, mean_t / mean_r);
    cdl_film_free(&f);
    cdl_scene_free(&s);
}

/* A Lambertian plane under a sphere light of radiance Le: while the sphere
 * is wholly above the plane's horizon, E = pi Le (r/d)^2 cos(theta) with d
 * and theta those of the centre (the sphere looks like a point source of
 * intensity Le pi r^2). Exercises solid-angle sampling of spheres. */
static void sphere_light(const char *integ)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "sphere-light", &err), &err);
    const float rho = 0.5f, Le = 10.0f, r = 0.3f;
    add_ground(&s, rho);
    cdl_material black = cdl_material_default(CDL_MAT_DIFFUSE);
    black.kd = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t bid;
    int32_t emit;
    die_on(cdl_scene_add_material(&s, &black, &bid, &err), &err);
    die_on(cdl_scene_add_emitter(&s, cdl_v3(Le, Le, Le), 0, &emit, &err), &err);
    cdl_vec3 c = cdl_v3(0.5f, 1.2f, -0.1f);
    die_on(cdl_scene_add_sphere(&s, c, r, bid, emit, 0, &err), &err);
    die_on(cdl_scene_commit(&s, &err), &err);

    cdl_options opt;
    cdl_options_default(&opt);
    opt.maxdepth = 1;
    int W = 24, H = 16;
    die_on(cdl_camera_init(&opt.camera, cdl_v3(-0.3f, 4.0f, 0.4f), cdl_v3(0.0f, 0.0f, 0.0f),
                           cdl_v3(0.0f, 0.0f, -1.0f), 50.0f, W, H, &err),
           &err);
    /* two renders with different seeds measure the estimator's own noise:
     * bdpt's light tracing gains nothing from the Sobol sampler, so its
     * pixels are noisier than path's at equal samples */
    cdl_film f, f2;
    uint32_t spp = method_setup(integ, &opt, getenv("CDL_SPP") ? (uint32_t)atoi(getenv("CDL_SPP")) : 4096);
    render_film(integ, &s, &opt, W, H, spp, &f);
    opt.seed = 77;
    render_film(integ, &s, &opt, W, H, spp, &f2);
    double worst = 0.0, mean_t = 0.0, mean_r = 0.0, noise2 = 0.0;
    enum { SUB = 16 };
    int npix = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double ref = 0.0;
            int hidden = 0;
            for (int j = 0; j < SUB; j++)
                for (int i = 0; i < SUB; i++) {
                    cdl_vec3 d = cdl_camera_ray(&opt.camera, (float)x + (i + 0.5f) / SUB,
                                                (float)y + (j + 0.5f) / SUB);
                    /* pixels that see the sphere itself are left out */
                    cdl_vec3 oc = cdl_sub(opt.camera.eye, c);
                    float rm = 1.1f * r; /* margin: jittered rays may clip the rim */
                    float bq = cdl_dot(oc, d), cq = cdl_dot(oc, oc) - rm * rm;
                    if (bq * bq - cq > 0.0f)
                        hidden = 1;
                    float t = -opt.camera.eye.y / d.y;
                    cdl_vec3 q = cdl_madd(opt.camera.eye, d, t);
                    cdl_vec3 l = cdl_sub(c, q);
                    double d2 = cdl_dot(l, l), cos_t = l.y / sqrt(d2);
                    ref += rho / 3.14159265358979323846 * (3.14159265358979323846 * Le * r * r / d2 * cos_t);
                }
            if (hidden)
                continue;
            ref /= SUB * SUB;
            double v1 = film_pixel(&f, x, y, 0), v2 = film_pixel(&f2, x, y, 0);
            double v = 0.5 * (v1 + v2);
            noise2 += (v1 - v2) * (v1 - v2) / (4.0 * ref * ref); /* variance of v, relative */
            mean_t += v;
            mean_r += ref;
            npix++;
worst = fmax(worst, fabs(v - ref) / ref);
        }
    /* 8 sigma: light-tracing splats make the noise heavy-tailed */
    double sigma = sqrt(noise2 / (npix ? npix : 1)), limit = fmax(0.01 * tol_scale, 8.0 * sigma);
    CHECK(worst < limit,
          "%s plane under a sphere light: worst of %d pixels %.3f%% off the closed form "
          "(limit max(1%%, 8 sigma = %.3f%%))", integ, npix, 100.0 * worst, 800.0 * sigma);
    CHECK(fabs(mean_t / mean_r - 1.0) < 0.002 * tol_scale, "%s sphere light: image mean ratio %.5f (limit %.1f%%)", integ,
          mean_t / mean_r, 0.2 * tol_scale);
    cdl_film_free(&f);
    cdl_film_free(&f2);
    cdl_scene_free(&s);
}

int main(int argc, char **argv)
{
    const char *integ = argc > 1 ? argv[1] : "path";
    if (getenv("CDL_TEST_SCALE") && atoi(getenv("CDL_TEST_SCALE")) > 1) {
        spp_div = (uint32_t)atoi(getenv("CDL_TEST_SCALE"));
        tol_scale = sqrt((double)spp_div);
    }
    furnace(integ);
    plane(integ);
    /* rigi lights through its point lights, uniform over the sphere's
     * area: far too noisy for a per-pixel check at test budgets */
    if (strcmp(integ, "rigi") != 0)
        sphere_light(integ);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
