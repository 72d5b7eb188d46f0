/* splat's radiance cache (Herzog et al. 2007, §6.3, §6.3.1) against a
 * smooth closed form, direct light only:
 *  - a plane under a small light: the cached image follows the analytic
 *    irradiance within a stated error in the middle, about as well as the
 *    uncached splatting it interpolates;
 *  - every pixel gathers at least N_c records, and records are a small
 *    share of the eye samples;
 *  - a blocker's sharp shadow: the irradiance gradient of the splats puts
 *    more records along the shadow's edge than the geometric spacing does,
 *    and the image there is closer to the closed form. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

#define W 64
#define H 64
#define LH 0.4f  /* half the light's side */
#define LY 1.0f  /* the light's height */
#define BH 0.15f /* half the blocker's side, at height BY */
#define BY 0.15f
#define EPS 0.2f /* the cache error */

static void quad(cdl_scene *s, const float *v, uint32_t mat, int32_t emit, cdl_error *err)
{
    uint32_t first;
    die_on(cdl_scene_add_vertices(s, 4, v, NULL, NULL, &first, err), err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, mat, emit, 0, err), err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, mat, emit, 0, err), err);
}

/* A 4 x 4 floor at y = 0 facing up, a small light at y = LY facing down,
 * and (blocker) a black square at y = BY between them. */
static void build(cdl_scene *s, int blocker)
{
    cdl_error err;
    die_on(cdl_scene_init(s, "cache", &err), &err);
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE), black = m;
    m.kd = cdl_v3(0.5f, 0.5f, 0.5f);
    black.kd = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t mid, bid;
    int32_t emit;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    die_on(cdl_scene_add_material(s, &black, &bid, &err), &err);
    float f[12] = {-2, 0, -2, -2, 0, 2, 2, 0, 2, 2, 0, -2};
    quad(s, f, mid, -1, &err);
    die_on(cdl_scene_add_emitter(s, cdl_v3(5.0f, 5.0f, 5.0f), 0, &emit, &err), &err);
    float l[12] = {-LH, LY, -LH, LH, LY, -LH, LH, LY, LH, -LH, LY, LH};
    quad(s, l, bid, emit, &err);
    if (blocker) {
        float b[12] = {-BH + 0.2f, BY, -BH, BH + 0.2f, BY, -BH, BH + 0.2f, BY, BH, -BH + 0.2f, BY, BH};
        quad(s, b, bid, -1, &err);
    }
    die_on(cdl_scene_commit(s, &err), &err);
}

/* Reflected radiance kd / pi E at (x, 0, z), E by quadrature over the
 * light (blocked rays left out). */
static double radiance(double x, double z, int blocker)
{
    double E = 0.0;
    int n = 24;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double lx = -LH + 2.0 * LH * (i + 0.5) / n, lz = -LH + 2.0 * LH * (j + 0.5) / n;
            if (blocker) { /* where the segment to the light crosses y = BY */
                double t = BY / LY, bx = x + t * (lx - x), bz = z + t * (lz - z);
                if (fabs(bx - 0.2) < BH && fabs(bz) < BH)
                    continue;
            }
            double dx = lx - x, dz = lz - z, r2 = dx * dx + dz * dz + LY * LY;
            E += 5.0 * LY * LY / (r2 * r2) * (4.0 * LH * LH / ((double)n * n));
        }
    return 0.5 / CDL_PI * E;
}

static void setup(cdl_options *opt)
{
    cdl_error err;
    cdl_options_default(opt);
    opt->maxdepth = 1;
    /* under the light, looking down at the middle of the floor */
    die_on(cdl_camera_init(&opt->camera, cdl_v3(0.0f, 0.9f, 0.001f), cdl_v3(0, 0, 0), cdl_v3(0, 0, -1), 90.0f, W, H,
                           &err),
           &err);
    opt->splat.fractions[0] = 1.0f;
    opt->splat.fractions[1] = opt->splat.fractions[2] = 0.0f;
    opt->photons = 100000;
    opt->splat.C = 0.5f;
}

/* The floor point a pixel sees; 0 if it sees the blocker. */
static int floor_at(const cdl_camera *cam, int x, int y, int blocker, double *px, double *pz)
{
    cdl_vec3 d = cdl_camera_ray(cam, x + 0.5f, y + 0.5f);
    float tb = (BY - cam->eye.y) / d.y, bx = cam->eye.x + tb * d.x, bz = cam->eye.z + tb * d.z;
    if (blocker && fabsf(bx - 0.2f) < BH && fabsf(bz) < BH)
        return 0;
    float t = -cam->eye.y / d.y;
    *px = cam->eye.x + t * d.x;
    *pz = cam->eye.z + t * d.z;
    return 1;
}

typedef struct err_stats {
    double rel, mean, edge; /* mean |relative error| in the middle, mean ratio, |relative error| near the shadow's edge */
} err_stats;

static err_stats errors(const cdl_film *f, const cdl_camera *cam, int blocker)
{
    double sum = 0.0, st = 0.0, sr = 0.0, se = 0.0;
    int n = 0, ne = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double px, pz;
            if (!floor_at(cam, x, y, blocker, &px, &pz) || fabs(px) > 0.7 || fabs(pz) > 0.7)
                continue;
            double want = radiance(px, pz, blocker), got = film_pixel(f, x, y, 1);
            /* the shadow's edge: the closed form changes by a third within 2 pixels */
            double wx = radiance(px + 0.05, pz, blocker), wz = radiance(px, pz + 0.05, blocker);
            if (blocker && (fabs(wx - want) > want / 3 || fabs(wz - want) > want / 3)) {
                se += fabs(got - want) / (want + 0.05);
                ne++;
            }
            sum += fabs(got - want) / want;
            st += want;
            sr += got;
            n++;
        }
    return (err_stats){sum / n, sr / st, ne ? se / ne : 0.0};
}

static double records(const cdl_film *f, int a, double *min_gathered)
{
    double r = 0.0, mg = INFINITY;
    for (int p = 0; p < W * H; p++) {
        r += f->aovs[a].sum[3 * p];
        mg = fmin(mg, f->aovs[a].sum[3 * p + 1]);
    }
    *min_gathered = mg;
    return r;
}

static void render_with(const cdl_scene *s, const cdl_options *opt, cdl_film *f, int *aov)
{
    cdl_error err;
    cdl_integrator it;
    die_on(cdl_integrator_create("splat", &it, &err), &err);
    die_on(it.vt->prepare(it.self, s, opt, &err), &err);
    die_on(cdl_film_init(f, W, H, &err), &err);
    *aov = cdl_film_add_aov(f, "records", 3, &err);
    die_on(*aov < 0, &err);
    for (uint32_t p = 0; p < 4; p++)
        die_on(it.vt->render_pass(it.self, f, p, &err), &err);
    cdl_integrator_destroy(&it);
}

int main(void)
{
    cdl_scene s, sb;
    build(&s, 0);
    build(&sb, 1);
    cdl_options opt;
    setup(&opt);
    int scale = getenv("CDL_TEST_SCALE") ? atoi(getenv("CDL_TEST_SCALE")) : 1;
    (void)scale;
    cdl_film plain, cached, geo, grad;
    int a0, a1, a2, a3;
    render_with(&s, &opt, &plain, &a0);
    opt.splat.cache = EPS;
    render_with(&s, &opt, &cached, &a1);
    err_stats ep = errors(&plain, &opt.camera, 0), ec = errors(&cached, &opt.camera, 0);
    CHECK(ec.rel < 0.03 && ec.rel < ep.rel + 0.01 && fabs(ec.mean - 1.0) < 0.02,
          "a smooth field: the cache's mean relative error %.4f (without it %.4f), mean ratio %.4f", ec.rel, ep.rel,
          ec.mean);
    double mg, nrec = records(&cached, a1, &mg) / 4.0;
    CHECK(mg >= (double)opt.splat.cache_min && nrec > 10 && nrec < W * H / 3.0,
          "every pixel gathers >= %u records (fewest %.0f); %.0f records for %d pixels", opt.splat.cache_min, mg, nrec,
          W * H);
    /* the shadow of a blocker: spacing from the splats' gradient against
     * the geometric spacing alone */
    opt.splat.cache_geometric = 1;
    render_with(&sb, &opt, &geo, &a2);
    opt.splat.cache_geometric = 0;
    render_with(&sb, &opt, &grad, &a3);
    cdl_film bplain;
    int a4;
    opt.splat.cache = 0.0f;
    render_with(&sb, &opt, &bplain, &a4);
    err_stats ebp = errors(&bplain, &opt.camera, 1);
    double mg2, mg3, r_geo = records(&geo, a2, &mg2), r_grad = records(&grad, a3, &mg3);
    err_stats eg = errors(&geo, &opt.camera, 1), ed = errors(&grad, &opt.camera, 1);
    CHECK(r_grad > 1.2 * r_geo, "a shadow's edge: the irradiance gradient places %.0f records, the geometric spacing "
          "%.0f", r_grad / 4.0, r_geo / 4.0);
    CHECK(ed.edge < eg.edge, "at the shadow's edge the error is %.3f with the gradient, %.3f without (uncached "
          "splatting %.3f)", ed.edge, eg.edge, ebp.edge);
    cdl_film_free(&plain);
    cdl_film_free(&cached);
    cdl_film_free(&geo);
    cdl_film_free(&grad);
    cdl_film_free(&bplain);
    cdl_scene_free(&s);
    cdl_scene_free(&sb);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
