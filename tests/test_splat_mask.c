/* splat's visibility mask (§8.1, --visibility-mask) on direct light alone:
 *  - under a table (a plate at y = 0.5 over the floor, lit from a panel
 *    above, seen from below its edge), the floor is in full shadow: every
 *    light point is hidden. Without the mask, rays passing the plate's
 *    edge splat into the shadow within their kernel; the plate's underside
 *    (eye samples the camera sees) masks them, so the light leaking under
 *    the edge must fall to a fraction of the unmasked leak, while the
 *    floor in front, which sees the whole light, keeps its irradiance;
 *  - on an open plane no eye sample hides another: the image is the same
 *    as without the mask. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

#define W 64
#define H 48

static void add_quad(cdl_scene *s, const float q[12], uint32_t mat, int32_t emit)
{
    cdl_error err;
    uint32_t first;
    die_on(cdl_scene_add_vertices(s, 4, q, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, mat, emit, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, mat, emit, 0, &err), &err);
}

/* floor 8 x 8 at y = 0 facing up; light 1 x 1 at y = 2 facing down; with
 * `table`, a 2 x 2 plate at y = 0.5 (facing up; its underside is seen) */
static void build(cdl_scene *s, int table)
{
    cdl_error err;
    die_on(cdl_scene_init(s, table ? "table" : "plane", &err), &err);
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(0.5f, 0.5f, 0.5f);
    cdl_material black = cdl_material_default(CDL_MAT_DIFFUSE);
    black.kd = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t mid, bid;
    int32_t emit;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    die_on(cdl_scene_add_material(s, &black, &bid, &err), &err);
    float f[12] = {-4, 0, -4, -4, 0, 4, 4, 0, 4, 4, 0, -4};
    add_quad(s, f, mid, -1);
    if (table) {
        float t[12] = {-1, 0.5f, -1, -1, 0.5f, 1, 1, 0.5f, 1, 1, 0.5f, -1};
        add_quad(s, t, mid, -1);
    }
    float l[12] = {-0.5f, 2, -0.5f, 0.5f, 2, -0.5f, 0.5f, 2, 0.5f, -0.5f, 2, 0.5f};
    die_on(cdl_scene_add_emitter(s, cdl_v3(4.0f, 4.0f, 4.0f), 0, &emit, &err), &err);
    add_quad(s, l, bid, emit);
    die_on(cdl_scene_commit(s, &err), &err);
}

static void setup(cdl_options *opt, cdl_vec3 eye, cdl_vec3 at)
{
    cdl_error err;
    cdl_options_default(opt);
    opt->maxdepth = 1;
    die_on(cdl_camera_init(&opt->camera, eye, at, cdl_v3(0, 1, 0), 40.0f, W, H, &err), &err);
    opt->splat.fractions[0] = 1.0f;
    opt->splat.fractions[1] = opt->splat.fractions[2] = 0.0f;
    opt->photons = 50000;
    /* the report's kernels, without candela's occlusion test: the mask's own effect */
    opt->splat.C = 1.0f;
    opt->splat.occlusion = 0;
}

/* Irradiance at (x, 0, z) from the unoccluded light (Le = 4), by quadrature. */
static double irradiance(double x, double z)
{
    double E = 0.0;
    int n = 64;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double lx = -0.5 + (i + 0.5) / n - x, lz = -0.5 + (j + 0.5) / n - z, r2 = lx * lx + lz * lz + 4.0;
            E += 4.0 * 4.0 / (r2 * r2) / ((double)n * n); /* Le cos cos / r^2 = Le h^2 / r^4, area 1 */
        }
    return E;
}

typedef struct bands {
    double shadow, lit; /* mean radiance of the floor under the plate's edge, and in front of it */
    double want;        /* the closed form of the latter */
} bands;

static bands measure(const cdl_film *f, const cdl_camera *cam)
{
    double ss = 0.0, sl = 0.0, ew = 0.0;
    int ns = 0, nl = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            cdl_vec3 d = cdl_camera_ray(cam, x + 0.5f, y + 0.5f);
            if (!(d.y < 0.0f))
                continue; /* the plate's underside */
            float t = -cam->eye.y / d.y;
            float px = cam->eye.x + t * d.x, pz = cam->eye.z + t * d.z;
            float m = fmaxf(fabsf(px), fabsf(pz));
            double v = film_pixel(f, x, y, 1);
            if (m < 1.0f && m > 0.75f) { /* under the plate, within 0.25 of its edge */
                ss += v;
                ns++;
            } else if (m > 2.4f && m < 3.0f) { /* sees the whole light */
                double want = 0.5 / CDL_PI * irradiance(px, pz);
                ew += want;
                sl += v;
                nl++;
            }
        }
    CHECK(ns > 50 && nl > 50, "the bands hold pixels (%d under the edge, %d in front)", ns, nl);
    return (bands){ns ? ss / ns : 0.0, nl ? sl / nl : 0.0, nl ? ew / nl : 0.0};
}

int main(void)
{
    cdl_scene s;
    cdl_options opt;
    build(&s, 1);
    setup(&opt, cdl_v3(0.0f, 0.3f, 3.2f), cdl_v3(0.0f, 0.1f, 0.0f));
    cdl_film f0, f1;
    render_film("splat", &s, &opt, W, H, 2, &f0);
    opt.splat.visibility_mask = 1;
    render_film("splat", &s, &opt, W, H, 2, &f1);
    bands b0 = measure(&f0, &opt.camera), b1 = measure(&f1, &opt.camera);
    double leak0 = b0.shadow / b0.lit, leak1 = b1.shadow / b1.lit;
    printf("under the plate's edge / lit floor: %.4f without the mask, %.4f with it\n", leak0, leak1);
    CHECK(leak0 > 0.02, "without the mask light leaks under the plate (%.4f of the lit floor)", leak0);
    CHECK(leak1 < 0.3 * leak0, "the mask removes most of it (%.4f, was %.4f)", leak1, leak0);
    /* (both read 4 % low there: kernels wide enough to reach the plate's
     * penumbra; measured 0.957) */
    CHECK(fabs(b0.lit / b0.want - 1.0) < 0.06, "the lit floor in front: %.4f of the closed form", b0.lit / b0.want);
    CHECK(fabs(b1.lit / b0.lit - 1.0) < 0.01, "the mask keeps its light (%.4f of the unmasked)", b1.lit / b0.lit);
    /* the occlusion test (--occlusion, the default): no light through the
     * plate; what the band keeps is the kernel's blur of the shadow's edge
     * from the lit floor beside it, which the floor under the plate sees
     * (measured 0.27 of the lit floor, 0.75 untested, 0.14 with the mask,
     * whose frustum test also stands for the shifted photon's path) */
    cdl_film f2;
    opt.splat.visibility_mask = 0;
    opt.splat.occlusion = 1;
    render_film("splat", &s, &opt, W, H, 2, &f2);
    bands b2 = measure(&f2, &opt.camera);
    printf("with the occlusion test: %.4g of the lit floor\n", b2.shadow / b2.lit);
    CHECK(b2.shadow / b2.lit < 0.5 * leak0, "the occlusion test removes what came through the plate (%.4f, was %.4f)",
          b2.shadow / b2.lit, leak0);
    CHECK(fabs(b2.lit / b0.lit - 1.0) < 0.01, "and keeps the lit floor's light (%.4f of the untested)",
          b2.lit / b0.lit);
    cdl_film_free(&f2);
    cdl_film_free(&f0);
    cdl_film_free(&f1);
    cdl_scene_free(&s);

    /* an open plane, seen from above at an angle */
    build(&s, 0);
    setup(&opt, cdl_v3(0.0f, 1.5f, 2.5f), cdl_v3(0.0f, 0.0f, 0.0f));
    render_film("splat", &s, &opt, W, H, 1, &f0);
    opt.splat.visibility_mask = 1;
    render_film("splat", &s, &opt, W, H, 1, &f1);
    double worst = 0.0, sum = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double a = film_pixel(&f0, x, y, 1), b = film_pixel(&f1, x, y, 1);
            sum += a;
            if (a > 0.0)
                worst = fmax(worst, fabs(b / a - 1.0));
        }
    CHECK(sum > 0.0 && worst < 1e-6, "open plane: the masked image is the unmasked one (worst %.2g)", worst);
    cdl_film_free(&f0);
    cdl_film_free(&f1);
    cdl_scene_free(&s);
    return test_failures ? 1 : 0;
}
