/* splat against closed forms (direct light only):
 *  - a small isolated quad under a large light keeps its irradiance out to
 *    its edges (photon rays that miss it still pass its edge samples),
 *    where the photon map seen directly loses about half: the boundary
 *    bias the report removes; its centre matches the closed form;
 *  - a quad's underside, which no photon reaches, stays black;
 *  - on a Lambertian surface the three radiance maps (direct, histogram,
 *    SH) give the same image;
 *  - the bandwidth picture (--aov bandwidth) in a closed room. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"

#define W 48
#define H 48
#define QH 0.25f /* half the small quad's side */

static void build(cdl_scene *s)
{
    cdl_error err;
    die_on(cdl_scene_init(s, "quad", &err), &err);
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(0.5f, 0.5f, 0.5f);
    cdl_material black = cdl_material_default(CDL_MAT_DIFFUSE);
    black.kd = cdl_v3(0.0f, 0.0f, 0.0f);
    uint32_t mid, bid, first;
    int32_t emit;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    die_on(cdl_scene_add_material(s, &black, &bid, &err), &err);
    /* the small quad at y = 0, facing up */
    float q[12] = {-QH, 0, -QH, QH, 0, -QH, QH, 0, QH, -QH, 0, QH};
    die_on(cdl_scene_add_vertices(s, 4, q, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 1, mid, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 3, first + 2, mid, -1, 0, &err), &err);
    /* a 4 x 4 light at y = 2 facing down */
    float l[12] = {-2, 2, -2, 2, 2, -2, 2, 2, 2, -2, 2, 2};
    die_on(cdl_scene_add_emitter(s, cdl_v3(1.0f, 1.0f, 1.0f), 0, &emit, &err), &err);
    die_on(cdl_scene_add_vertices(s, 4, l, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, bid, emit, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, bid, emit, 0, &err), &err);
    die_on(cdl_scene_commit(s, &err), &err);
}

/* Irradiance at (x, 0, z) from the light (Le = 1), by quadrature. */
static double irradiance(double x, double z)
{
    double E = 0.0;
    int n = 200;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double lx = -2.0 + 4.0 * (i + 0.5) / n - x, lz = -2.0 + 4.0 * (j + 0.5) / n - z, r2 = lx * lx + lz * lz + 4.0;
            E += 4.0 / (r2 * r2) * (16.0 / ((double)n * n)); /* cos cos / r^2 = h^2 / r^4 */
        }
    return E;
}

typedef struct ring {
    double centre, edge;
} ring;

/* Means over the quad's pixels: the middle half, and the outer band of the
 * pixels whose centre lies within `band` of an edge. */
static ring measure(const cdl_film *f, const cdl_camera *cam, float band)
{
    double sc = 0.0, se = 0.0;
    int nc = 0, ne = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            cdl_vec3 d = cdl_camera_ray(cam, x + 0.5f, y + 0.5f);
            float t = -cam->eye.y / d.y;
            float px = cam->eye.x + t * d.x, pz = cam->eye.z + t * d.z;
            float m = fmaxf(fabsf(px), fabsf(pz));
            if (m > QH)
                continue;
            double v = film_pixel(f, x, y, 1);
            if (m < 0.5f * QH) {
                sc += v;
                nc++;
            } else if (m > QH - band) {
                se += v;
                ne++;
            }
        }
    return (ring){sc / nc, se / ne};
}

static void setup(cdl_options *opt, int from_below)
{
    cdl_error err;
    cdl_options_default(opt);
    opt->maxdepth = 1;
    die_on(cdl_camera_init(&opt->camera, cdl_v3(0.0f, from_below ? -1.2f : 1.2f, 0.001f), cdl_v3(0, 0, 0),
                           cdl_v3(0, 0, -1), 28.0f, W, H, &err),
           &err);
    opt->splat.fractions[0] = 1.0f;
    opt->splat.fractions[1] = opt->splat.fractions[2] = 0.0f;
    opt->photons = 100000; /* pm's is set where it renders */
    opt->pm.gather = 0;
    opt->pm.direct_photons = 1;
    opt->pm.k = 200;
}

/* A closed room [-1, 1]^3 (walls facing in) with a light panel under the
 * ceiling: light bounces many times. */
static void build_room(cdl_scene *s)
{
    cdl_error err;
    die_on(cdl_scene_init(s, "room", &err), &err);
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(0.7f, 0.7f, 0.7f);
    uint32_t mid, first;
    int32_t emit;
    die_on(cdl_scene_add_material(s, &m, &mid, &err), &err);
    /* 8 corners; each face listed counter-clockwise seen from inside */
    float c[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1, -1, -1, 1, 1, -1, 1, 1, 1, 1, -1, 1, 1};
    die_on(cdl_scene_add_vertices(s, 8, c, NULL, NULL, &first, &err), &err);
    static const int f[6][4] = {{0, 1, 2, 3}, {5, 4, 7, 6}, {4, 0, 3, 7}, {1, 5, 6, 2}, {4, 5, 1, 0}, {3, 2, 6, 7}};
    for (int k = 0; k < 6; k++) {
        die_on(cdl_scene_add_triangle(s, first + f[k][0], first + f[k][1], first + f[k][2], mid, -1, 0, &err), &err);
        die_on(cdl_scene_add_triangle(s, first + f[k][0], first + f[k][2], first + f[k][3], mid, -1, 0, &err), &err);
    }
    float l[12] = {-0.3f, 0.99f, -0.3f, 0.3f, 0.99f, -0.3f, 0.3f, 0.99f, 0.3f, -0.3f, 0.99f, 0.3f};
    die_on(cdl_scene_add_emitter(s, cdl_v3(5.0f, 5.0f, 5.0f), 0, &emit, &err), &err);
    die_on(cdl_scene_add_vertices(s, 4, l, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, mid, emit, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, mid, emit, 0, &err), &err);
    die_on(cdl_scene_commit(s, &err), &err);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* --aov bandwidth (Figure 4.4) on the McGuire-like scene: every pixel's
 * mean bandwidth lies within the clamp's range (a ratio of at most 1/R^2
 * between any two), and rays of depth 3 get wider kernels than those of
 * depth 2 (their path densities are lower), as the report shows. */
static void bandwidth_picture(void)
{
    cdl_scene room;
    build_room(&room);
    const cdl_scene *s = &room;
    cdl_options opt;
    setup(&opt, 0);
    cdl_error e0;
    die_on(cdl_camera_init(&opt.camera, cdl_v3(0.0f, 0.0f, 0.95f), cdl_v3(0, 0, 0), cdl_v3(0, 1, 0), 80.0f, W, H, &e0),
           &e0);
    opt.maxdepth = 8;
    opt.splat.fractions[0] = 0.3f;
    opt.splat.fractions[1] = 0.7f;
    cdl_error err;
    cdl_integrator it;
    cdl_film f;
    die_on(cdl_integrator_create("splat", &it, &err), &err);
    die_on(it.vt->prepare(it.self, s, &opt, &err), &err);
    die_on(cdl_film_init(&f, W, H, &err), &err);
    int a = cdl_film_add_aov(&f, "bandwidth", 3, &err);
    die_on(a < 0, &err);
    die_on(it.vt->render_pass(it.self, &f, 0, &err), &err);
    double lo = INFINITY, hi = 0.0, *d2 = malloc(sizeof(double) * W * H), *d3 = malloc(sizeof(double) * W * H);
    int n2 = 0, n3 = 0;
    for (int p = 0; p < W * H; p++) {
        const double *v = &f.aovs[a].sum[3 * p];
        for (int c = 0; c < 3; c++)
            if (v[c] > 0.0) {
                lo = fmin(lo, v[c]);
                hi = fmax(hi, v[c]);
            }
        if (v[0] > 0.0)
            d2[n2++] = v[0];
        if (v[1] > 0.0)
            d3[n3++] = v[1];
    }
    qsort(d2, (size_t)n2, sizeof *d2, cmp_double);
    qsort(d3, (size_t)n3, sizeof *d3, cmp_double);
    double R = opt.splat.R;
    CHECK(n2 > 100 && hi / lo <= 1.0001 / (R * R), "bandwidth picture: %d pixels, bandwidths %.3g .. %.3g (ratio %.1f, "
          "at most 1/R^2 = %.0f)", n2, lo, hi, hi / lo, 1.0 / (R * R));
    CHECK(n3 > 100 && d3[n3 / 2] > d2[n2 / 2], "rays of depth 3 get wider kernels than depth 2 (medians %.3g, %.3g)",
          d3[n3 / 2], d2[n2 / 2]);
    free(d2);
    free(d3);
    cdl_film_free(&f);
    cdl_integrator_destroy(&it);
    cdl_scene_free(&room);
}

int main(void)
{
    cdl_scene s;
    build(&s);
    cdl_options opt;
    setup(&opt, 0);
    double want = 0.5 / CDL_PI * irradiance(0.0, 0.0);
    cdl_film fs, fp, fh, fsh;
    render_film("splat", &s, &opt, W, H, 8, &fs);
    opt.photons = 10000; /* the photon map's radius near the band's width: 200 of 10000 photons on the quad */
    render_film("pm", &s, &opt, W, H, 8, &fp);
    opt.photons = 100000;
    float band = 0.04f;
    ring rs = measure(&fs, &opt.camera, band), rp = measure(&fp, &opt.camera, band);
    CHECK(fabs(rs.centre / want - 1.0) < 0.03, "splat: quad centre %.4f, closed form %.4f", rs.centre, want);
    double edge_want = 0.5 / CDL_PI * irradiance(QH - 0.5 * band, 0.0) / (0.5 / CDL_PI * irradiance(0.0, 0.0));
    CHECK(fabs(rs.edge / rs.centre / edge_want - 1.0) < 0.06,
          "splat: the quad's edge band reads %.3f of its centre (closed form %.3f): no boundary bias",
          rs.edge / rs.centre, edge_want);
    CHECK(rp.edge / rp.centre < 0.85 * edge_want,
          "pm (the photon map seen directly): edge band %.3f of its centre: boundary bias (%.3f expected)",
          rp.edge / rp.centre, edge_want);
    opt.splat.mode = CDL_SPLAT_HISTOGRAM;
    render_film("splat", &s, &opt, W, H, 2, &fh);
    opt.splat.mode = CDL_SPLAT_SH;
    render_film("splat", &s, &opt, W, H, 2, &fsh);
    opt.splat.mode = CDL_SPLAT_DIRECT;
    cdl_film fd;
    render_film("splat", &s, &opt, W, H, 2, &fd);
    double worst_h = 0.0, worst_s = 0.0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            double d = film_pixel(&fd, x, y, 1);
            if (!(d > 0.01 * want))
                continue;
            worst_h = fmax(worst_h, fabs(film_pixel(&fh, x, y, 1) / d - 1.0));
            worst_s = fmax(worst_s, fabs(film_pixel(&fsh, x, y, 1) / d - 1.0));
        }
    CHECK(worst_h < 1e-4 && worst_s < 1e-4,
          "Lambertian: histogram and SH maps give the direct mode's pixels (worst %.2g, %.2g)", worst_h, worst_s);
    /* from below: the underside, which no photon reaches */
    setup(&opt, 1);
    cdl_film fb;
    render_film("splat", &s, &opt, W, H, 2, &fb);
    ring rb = measure(&fb, &opt.camera, band);
    CHECK(rb.centre == 0.0 && rb.edge == 0.0, "the underside stays black (%g, %g)", rb.centre, rb.edge);
    bandwidth_picture();
    cdl_film_free(&fs);
    cdl_film_free(&fp);
    cdl_film_free(&fh);
    cdl_film_free(&fsh);
    cdl_film_free(&fd);
    cdl_film_free(&fb);
    cdl_scene_free(&s);
    return test_failures ? 1 : 0;
}
