/* Environment maps against closed forms:
 *  - the map's sampling (each layout): the returned pdf equals
 *    cdl_envmap_pdf, the pdf integrates to 1 over the sphere, and
 *    E[L / pdf] is the map's flux;
 *  - Mitsuba's layout interpolates bilinearly between texels at
 *    u = (x + 1/2) / w, v = y / (h - 1), across the seam at u = 0 too;
 *  - a rotated frame turns the map with it;
 *  - rendered by an integrator (argument, default path): a Lambertian plane
 *    of albedo rho under two hemispheres of radiance L1 (light +z) and L2
 *    has radiance rho (L1 + L2) / 2 when it faces the boundary and rho L1
 *    when it faces +z; a diffuse sphere of albedo a under a constant
 *    environment of radiance 1 has radiance a, the background 1. */
#include <math.h>
#include <string.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "film/image.h"
#include "scene/envmap.h"
#include "io/loader.h"
#include "test_util.h"

static double tol_scale = 1.0;
static uint32_t spp_div = 1;

/* The integrator behind a test name ("bdpt-shared": bdpt with shared paths). */
static const char *method(const char *integ)
{
    return !strcmp(integ, "bdpt-shared") ? "bdpt" : integ;
}

/* Passes for integ (pm's cost more: a photon map each) and its options. */
static uint32_t passes(const char *integ, cdl_options *opt, uint32_t spp)
{
    if (!strcmp(integ, "pm")) {
        opt->photons = 5000;
        spp /= 16;
    }
    if (!strcmp(integ, "rigi") || !strcmp(integ, "ir")) {
        opt->light_paths = 16;
        spp /= 4;
    }
    if (!strcmp(integ, "gkde")) { /* a step traces its light paths and links every eye vertex */
        opt->gkde.light_paths = 2000;
        spp /= 4;
    }
    if (!strcmp(integ, "splat")) { /* a pass traces and splats its photon rays */
        opt->photons = 5000;
        spp /= 4;
    }
    if (!strcmp(integ, "bdpt-shared")) { /* shared light paths in 2 x 2 sets */
        opt->light_paths = 64;
        opt->interleave = 2;
    }
    return spp / spp_div > 16 ? spp / spp_div : 16;
}

/* Two hemispheres in the light frame: rows above the equator L1, below L2,
 * with a bright spot so that importance sampling has something to find.
 * In Mitsuba's layout the rows are nodes from pole to pole: 33 of them put
 * row 16 on the equator, and the upper hemisphere (rows 0 to 16) is all L1. */
static cdl_envmap *two_hemispheres_in(int layout, float L1, float L2, int spot, const cdl_vec3 frame[3])
{
    int w = 64, h = layout == CDL_ENVMAP_MITSUBA ? 33 : 32, upper = layout == CDL_ENVMAP_MITSUBA ? 17 : 16;
    float *rgb = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                rgb[3 * (y * w + x) + c] = y < upper ? L1 : L2;
    if (spot)
        for (int c = 0; c < 3; c++)
            rgb[3 * (5 * w + 9) + c] = 400.0f;
    cdl_envmap *m = malloc(sizeof *m);
    cdl_error err;
    die_on(cdl_envmap_init(m, w, h, rgb, frame, layout, &err), &err);
    return m;
}

static cdl_envmap *two_hemispheres(float L1, float L2, int spot, const cdl_vec3 frame[3])
{
    return two_hemispheres_in(CDL_ENVMAP_EQUIRECT, L1, L2, spot, frame);
}

static const cdl_vec3 zup[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

/* A square equal-area map (pbrt-v4): L1 where the texel centre has z > 0,
 * else L2, and one bright texel. */
static cdl_envmap *equal_area_map(float L1, float L2, int spot)
{
    int n = 32;
    float *rgb = malloc(sizeof(float) * 3 * (size_t)n * (size_t)n);
    for (int y = 0; y < n; y++)
        for (int x = 0; x < n; x++) {
            cdl_vec3 d = cdl_equal_area_square_to_sphere((x + 0.5f) / n, (y + 0.5f) / n);
            for (int c = 0; c < 3; c++)
                rgb[3 * (y * n + x) + c] = d.z > 0.0f ? L1 : L2;
        }
    if (spot)
        for (int c = 0; c < 3; c++)
            rgb[3 * (7 * n + 20) + c] = 400.0f;
    cdl_envmap *m = malloc(sizeof *m);
    cdl_error err;
    die_on(cdl_envmap_init(m, n, n, rgb, zup, 1, &err), &err);
    return m;
}

/* The mapping: square -> sphere -> square is the identity, and uniform
 * points of the square are uniform on the sphere (E[z] = 0, E[z^2] = 1/3). */
static void equal_area_mapping(void)
{
    cdl_rng rng;
    cdl_rng_seed(&rng, 3, 0);
    double worst = 0.0, ez = 0.0, ez2 = 0.0, worst_len = 0.0;
    enum { N = 200000 };
    for (int i = 0; i < N; i++) {
        float u = cdl_rng_float(&rng), v = cdl_rng_float(&rng), u2, v2;
        cdl_vec3 d = cdl_equal_area_square_to_sphere(u, v);
        cdl_equal_area_sphere_to_square(d, &u2, &v2);
        worst = fmax(worst, fmax(fabs(u2 - u), fabs(v2 - v)));
        worst_len = fmax(worst_len, fabs(cdl_length(d) - 1.0));
        ez += d.z;
        ez2 += d.z * d.z;
    }
    ez /= N;
    ez2 /= N;
    CHECK(worst < 1e-4 && worst_len < 1e-5, "equal-area: square -> sphere -> square within %.2g, |d| - 1 within %.2g",
          worst, worst_len);
    CHECK(fabs(ez) < 0.01 && fabs(ez2 - 1.0 / 3.0) < 0.01, "equal-area: uniform on the sphere: E[z] %.4f, E[z^2] %.4f",
          ez, ez2);
}

/* The integral of the map's radiance (red) over the sphere by the midpoint
 * rule on a fine (theta, phi) grid. */
static double flux_by_quadrature(const cdl_envmap *m)
{
    enum { NT = 2048, NP = 4096 };
    double sum = 0.0;
    for (int i = 0; i < NT; i++) {
        double th = CDL_PI * (i + 0.5) / NT, row = 0.0;
        for (int j = 0; j < NP; j++) {
            double ph = 2.0 * CDL_PI * (j + 0.5) / NP;
            cdl_vec3 d = cdl_v3((float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th));
            row += cdl_envmap_eval(m, d).x;
        }
        sum += row * sin(th);
    }
    return sum * (CDL_PI / NT) * (2.0 * CDL_PI / NP);
}

static void sampling(int layout)
{
    cdl_envmap *m = layout == CDL_ENVMAP_EQUAL_AREA ? equal_area_map(1.0f, 0.25f, 1)
                                                    : two_hemispheres_in(layout, 1.0f, 0.25f, 1, zup);
    const char *kind = layout == CDL_ENVMAP_EQUAL_AREA ? "equal-area"
                       : layout == CDL_ENVMAP_MITSUBA  ? "Mitsuba's bilinear"
                                                       : "equirectangular";
    cdl_rng rng;
    cdl_rng_seed(&rng, 7, 0);
    enum { N = 400000 };
    double est = 0.0, pdf_int = 0.0, worst = 0.0;
    int uncovered = 0;
    for (int i = 0; i < N; i++) {
        cdl_vec3 w;
        float pdf;
        cdl_vec3 L = cdl_envmap_sample(m, cdl_rng_float(&rng), cdl_rng_float(&rng), &w, &pdf);
        if (pdf > 0.0f) {
            est += L.x / pdf;
            worst = fmax(worst, fabs(cdl_envmap_pdf(m, w) / pdf - 1.0));
        }
        cdl_vec3 d = cdl_sample_uniform_sphere(cdl_rng_float(&rng), cdl_rng_float(&rng));
        float p = cdl_envmap_pdf(m, d);
        pdf_int += p * 4.0 * CDL_PI;
        uncovered += !(p > 0.0f) && cdl_envmap_eval(m, d).x > 0.0f;
    }
    est /= N;
    pdf_int /= N;
    CHECK(worst < 1e-3, "%s: pdf of the sampled direction equals the sample's pdf (worst %.2g)", kind, worst);
    CHECK(fabs(pdf_int - 1.0) < 0.02, "%s: pdf integrates to %.4f over the sphere (1 within 2 %%)", kind, pdf_int);
    CHECK(uncovered == 0, "%s: the pdf is positive wherever the radiance is (%d directions not)", kind, uncovered);
    CHECK(fabs(est / m->flux.x - 1.0) < 0.005, "%s: E[L/pdf] %.5f vs flux %.5f (within 0.5 %%)", kind, est,
          (double)m->flux.x);
    if (layout == CDL_ENVMAP_EQUAL_AREA) { /* every texel 4 pi / n^2 */
        double f = 0.0;
        for (int i = 0; i < m->w * m->h; i++)
            f += m->rgb[3 * i] * 4.0 * CDL_PI / (m->w * m->h);
        CHECK(fabs(m->flux.x / f - 1.0) < 1e-4, "equal-area: flux %.5f vs %.5f", (double)m->flux.x, f);
        cdl_envmap_free(m);
        free(m);
        return;
    }
    if (layout == CDL_ENVMAP_MITSUBA) { /* the interpolated radiance's integral */
        double f = flux_by_quadrature(m);
        CHECK(fabs(m->flux.x / f - 1.0) < 1e-3, "Mitsuba's bilinear: flux %.5f vs %.5f by quadrature",
              (double)m->flux.x, f);
        cdl_envmap_free(m);
        free(m);
        return;
    }
    /* flux of the two hemispheres plus the spot texel's solid angle */
    double th0 = CDL_PI * 5 / 32, th1 = CDL_PI * 6 / 32;
    double exact = 2.0 * CDL_PI * (1.0 + 0.25) + (400.0 - 1.0) * 2.0 * CDL_PI / 64 * (cos(th0) - cos(th1));
    CHECK(fabs(m->flux.x / exact - 1.0) < 1e-4, "envmap: flux %.5f vs %.5f", (double)m->flux.x, exact);
    cdl_envmap_free(m);
    free(m);
    /* light frame with z along world y: world +y sees L1, -y L2 */
    const cdl_vec3 yup[3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    m = two_hemispheres(1.0f, 0.25f, 0, yup);
    cdl_vec3 a = cdl_envmap_eval(m, cdl_v3(0.1f, 0.99f, 0.0f)), b = cdl_envmap_eval(m, cdl_v3(0.0f, -0.99f, 0.1f));
    CHECK(a.x == 1.0f && b.x == 0.25f, "envmap: rotated frame: up %g, down %g", (double)a.x, (double)b.x);
    cdl_envmap_free(m);
    free(m);
}

/* The direction of (u, v) in the z-up light frame. */
static cdl_vec3 uv_dir(double u, double v)
{
    double ph = 2.0 * CDL_PI * u, th = CDL_PI * v;
    return cdl_v3((float)(sin(th) * cos(ph)), (float)(sin(th) * sin(ph)), (float)cos(th));
}

/* Mitsuba's layout: texel (x, y) is seen at u = (x + 1/2) / w,
 * v = y / (h - 1), halfway between texels is their mean, across the seam at
 * u = 0 too (the last column's neighbour is the first), and a constant map
 * has the flux 4 pi L. */
static void mitsuba_layout(void)
{
    int w = 6, h = 5;
    float *rgb = malloc(sizeof(float) * 3 * (size_t)(w * h));
    for (int i = 0; i < w * h; i++) /* the poles' rows constant: each is one direction */
        for (int c = 0; c < 3; c++)
            rgb[3 * i + c] = (i < w ? 3.0f : i >= w * (h - 1) ? 5.0f : (float)(1 + (i * 7) % 11)) + 0.5f * (float)c;
    cdl_envmap m;
    cdl_error err;
    die_on(cdl_envmap_init(&m, w, h, rgb, zup, CDL_ENVMAP_MITSUBA, &err), &err);
    int nodes = 0, mids = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *t = rgb + 3 * (y * w + x), *r = rgb + 3 * (y * w + (x + 1) % w);
            cdl_vec3 L = cdl_envmap_eval(&m, uv_dir((x + 0.5) / w, (double)y / (h - 1)));
            nodes += fabsf(L.x - t[0]) < 1e-4f && fabsf(L.z - t[2]) < 1e-4f;
            if (y == 0 || y == h - 1) /* at a pole every u is the same direction */
                continue;
            /* halfway to the right neighbour (for x = w - 1 across u = 0) */
            L = cdl_envmap_eval(&m, uv_dir((x + 1.0) / w, (double)y / (h - 1)));
            mids += fabsf(L.x - 0.5f * (t[0] + r[0])) < 1e-4f;
        }
    CHECK(nodes == w * h, "Mitsuba's layout: %d of %d texels seen at their nodes", nodes, w * h);
    CHECK(mids == w * (h - 2), "Mitsuba's layout: %d of %d midpoints (the seam's too) the mean of two texels", mids,
          w * (h - 2));
    /* halfway between rows 1 and 2 at texel 3's column */
    cdl_vec3 L = cdl_envmap_eval(&m, uv_dir(3.5 / w, 1.5 / (h - 1)));
    float want = 0.5f * (rgb[3 * (1 * w + 3)] + rgb[3 * (2 * w + 3)]);
    CHECK(fabsf(L.x - want) < 1e-4f, "Mitsuba's layout: between rows %g, expected %g", (double)L.x, (double)want);
    cdl_envmap_free(&m);
    float *c = malloc(sizeof(float) * 3 * (size_t)(w * h));
    for (int i = 0; i < 3 * w * h; i++)
        c[i] = 2.0f;
    die_on(cdl_envmap_init(&m, w, h, c, zup, CDL_ENVMAP_MITSUBA, &err), &err);
    CHECK(fabs(m.flux.x / (8.0 * CDL_PI) - 1.0) < 1e-5, "Mitsuba's layout: a constant 2 has flux %.6f (8 pi)",
          (double)m.flux.x);
    cdl_envmap_free(&m);
    float *small = malloc(sizeof(float) * 3 * 4);
    CHECK(cdl_envmap_init(&m, 2, 2, small, zup, CDL_ENVMAP_MITSUBA, &err) != 0,
          "Mitsuba's layout: a 2x2 map is refused (%s)", err.msg);
    free(small);
}

/* Mean radiance of the film's pixels whose rays through the centre and the
 * four corners all hit (hit = 1) or all miss (0) the scene. */
static double mean_where(const cdl_film *f, const cdl_scene *s, const cdl_camera *cam, int hit, int *count)
{
    double sum = 0.0;
    *count = 0;
    for (int y = 0; y < f->height; y++)
        for (int x = 0; x < f->width; x++) {
            static const float off[5][2] = {{0.5f, 0.5f}, {0, 0}, {1, 0}, {0, 1}, {1, 1}};
            int all = 1;
            for (int k = 0; k < 5; k++) {
                cdl_hit h;
                cdl_vec3 d = cdl_camera_ray(cam, (float)x + off[k][0], (float)y + off[k][1]);
                all &= cdl_intersect(s, cam->eye, d, FLT_MAX, &h) == hit;
            }
            if (!all)
                continue;
            sum += film_pixel(f, x, y, 0);
            (*count)++;
        }
    return *count ? sum / *count : 0.0;
}

/* The unit square in z = 0, facing +z. */
static const float square_z[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};

/* A Lambertian square of albedo rho with corners p (4 x 3). */
static void add_square(cdl_scene *s, const float *p, float rho)
{
    cdl_error err;
    cdl_material mat = cdl_material_default(CDL_MAT_DIFFUSE);
    mat.kd = cdl_v3(rho, rho, rho);
    uint32_t mid, first;
    die_on(cdl_scene_add_material(s, &mat, &mid, &err), &err);
    die_on(cdl_scene_add_vertices(s, 4, p, NULL, NULL, &first, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 1, first + 2, mid, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, first, first + 2, first + 3, mid, -1, 0, &err), &err);
}

/* Commits s and renders it 16 x 16 from eye towards the origin with
 * integ's passes for spp; opt gets the camera. */
static void render_view(const char *integ, cdl_scene *s, cdl_vec3 eye, cdl_vec3 up, float fov, uint32_t spp,
                        cdl_options *opt, cdl_film *f)
{
    cdl_error err;
    die_on(cdl_scene_commit(s, &err), &err);
    cdl_options_default(opt);
    opt->maxdepth = 4;
    die_on(cdl_camera_init(&opt->camera, eye, cdl_v3(0, 0, 0), up, fov, 16, 16, &err), &err);
    render_film(method(integ), s, opt, 16, 16, passes(integ, opt, spp), f);
}

static void plane_under_map(const char *integ, int facing_boundary, int layout)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "envplane", &err), &err);
    const float rho = 0.5f, L1 = 1.0f, L2 = 0.25f;
    /* a square in x = 0 facing +x (the boundary z = 0 cuts its hemisphere
     * in halves), or in z = 0 facing +z */
    static const float px[12] = {0, -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1};
    add_square(&s, facing_boundary ? px : square_z, rho);
    die_on(cdl_scene_add_env_light(&s, cdl_v3(1, 1, 1), two_hemispheres_in(layout, L1, L2, 0, zup), &err), &err);
    cdl_options opt;
    cdl_film f;
    int W = 16, H = 16;
    cdl_vec3 eye = facing_boundary ? cdl_v3(3.0f, 0.2f, 0.3f) : cdl_v3(0.2f, 0.3f, 3.0f);
    cdl_vec3 up = facing_boundary ? cdl_v3(0, 0, 1) : cdl_v3(0, 1, 0);
    render_view(integ, &s, eye, up, 30.0f, 1024, &opt, &f);
    int n;
    double m = mean_where(&f, &s, &opt.camera, 1, &n);
    double expect = facing_boundary ? rho * (L1 + L2) / 2.0 : rho * L1;
    CHECK(n > W * H / 2 && fabs(m / expect - 1.0) < 0.01 * tol_scale,
          "%s: plane facing %s under two hemispheres%s: %.4f, expected %.4f (within %.1f %%)", integ,
          facing_boundary ? "the boundary" : "+z", layout == CDL_ENVMAP_MITSUBA ? " (Mitsuba's map)" : "", m, expect,
          tol_scale);
    cdl_film_free(&f);
    cdl_scene_free(&s);
}

/* A Lambertian square facing +z under a distant light of radiance E at
 * angle theta: rho E cos(theta) / pi. */
static void plane_under_distant(const char *integ)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "distantplane", &err), &err);
    const float rho = 0.5f, E = 2.0f;
    add_square(&s, square_z, rho);
    cdl_vec3 dir = cdl_normalize(cdl_v3(-0.6f, 0.2f, -1.0f)); /* the way the light travels */
    die_on(cdl_scene_add_distant_light(&s, dir, cdl_v3(E, E, E), &err), &err);
    cdl_options opt;
    cdl_film f;
    int W = 16, H = 16;
    render_view(integ, &s, cdl_v3(0.2f, 0.3f, 3.0f), cdl_v3(0, 1, 0), 30.0f, 64, &opt, &f);
    int n;
    double m = mean_where(&f, &s, &opt.camera, 1, &n), expect = rho * E * -dir.z / CDL_PI;
    CHECK(n > W * H / 2 && fabs(m / expect - 1.0) < 0.01 * tol_scale,
          "%s: plane under a distant light: %.5f, expected rho E cos / pi = %.5f (within %.1f %%)", integ, m, expect,
          tol_scale);
    cdl_film_free(&f);
    cdl_scene_free(&s);
}

static void sphere_under_constant(const char *integ, int equal_area)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "envsphere", &err), &err);
    const float a = 0.6f;
    cdl_material mat = cdl_material_default(CDL_MAT_DIFFUSE);
    mat.kd = cdl_v3(a, a, a);
    uint32_t mid;
    die_on(cdl_scene_add_material(&s, &mat, &mid, &err), &err);
    die_on(cdl_scene_add_sphere(&s, cdl_v3(0, 0, 0), 1.0f, mid, -1, 0, &err), &err);
    if (equal_area) /* the constant sky as a pbrt-v4 map */
        die_on(cdl_scene_add_env_light(&s, cdl_v3(1, 1, 1), equal_area_map(1.0f, 1.0f, 0), &err), &err);
    else
        die_on(cdl_scene_add_infinite_light(&s, cdl_v3(1, 1, 1), &err), &err);
    cdl_options opt;
    cdl_film f;
    render_view(integ, &s, cdl_v3(0, 0.5f, 4), cdl_v3(0, 1, 0), 40.0f, 512, &opt, &f);
    int nh, nm;
    double on = mean_where(&f, &s, &opt.camera, 1, &nh), off = mean_where(&f, &s, &opt.camera, 0, &nm);
    CHECK(nh > 10 && fabs(on / a - 1.0) < 0.01 * tol_scale,
          "%s: convex sphere of albedo %.1f under a constant sky%s: %.4f (within %.1f %%)", integ, a,
          equal_area ? " (equal-area map)" : "", on, tol_scale);
    CHECK(nm > 10 && fabs(off - 1.0) < 1e-6, "%s: background %.6f, expected 1", integ, off);
    cdl_film_free(&f);
    cdl_scene_free(&s);
}

/* A pbrt-v3 scene's infinite light with a mapname: the map is read,
 * scaled by L and turned by the CTM (Rotate -90 1 0 0: the map's +z is the
 * world's +y), and a missing map is an error naming it. */
static void pbrt_map(const char *integ)
{
    /* named per integrator: the suite runs its instances in parallel */
    char exr[64], pbrt[64];
    snprintf(exr, sizeof exr, "envsky-%s.exr", integ);
    snprintf(pbrt, sizeof pbrt, "envsky-%s.pbrt", integ);
    cdl_image img;
    cdl_error err;
    die_on(cdl_image_alloc(&img, 8, 4, &err), &err);
    for (int i = 0; i < 8 * 4; i++)
        for (int c = 0; c < 3; c++)
            img.rgb[3 * i + c] = i < 16 ? 2.0f : 0.5f;
    die_on(cdl_image_write(exr, &img, NULL, 0, 0.0f, &err), &err);
    cdl_image_free(&img);
    const char *text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                       "AttributeBegin\nRotate -90 1 0 0\n"
                       "LightSource \"infinite\" \"string mapname\" \"%s\" \"rgb L\" [3 3 3]\nAttributeEnd\n"
                       "Shape \"sphere\" \"float radius\" 1\n";
    for (int missing = 0; missing < 3; missing++) {
        FILE *f = fopen(pbrt, "w");
        fprintf(f, text, missing ? "nosuch.exr" : exr);
        fclose(f);
        if (missing == 2) { /* pbrt-v4's filename: equal-area, so square */
            f = fopen(pbrt, "w");
            fprintf(f, "WorldBegin\nLightSource \"infinite\" \"string filename\" \"%s\"\n"
                       "Shape \"sphere\" \"float radius\" 1\n", exr);
            fclose(f);
        }
        cdl_scene s;
        cdl_scene_settings set;
        int rc = cdl_scene_init(&s, pbrt, &err);
        if (!rc)
            rc = cdl_scene_load(&s, pbrt, &set, &err);
        if (!rc)
            rc = cdl_scene_commit(&s, &err);
        if (missing == 2) {
            CHECK(rc && strstr(err.file, exr) && strstr(err.msg, "square"),
                  "pbrt-v4: an 8x4 equal-area map is an error: %s: %s", err.file, err.msg);
        } else if (missing) {
            CHECK(rc && strstr(err.file, "nosuch.exr"), "pbrt: a missing map is an error naming it (%s)", err.file);
        } else {
            CHECK(!rc && s.envmap, "pbrt: infinite light with mapname loaded");
            if (!rc && s.envmap) {
                cdl_vec3 up = cdl_envmap_eval(s.envmap, cdl_v3(0, 1, 0)), down = cdl_envmap_eval(s.envmap, cdl_v3(0, -1, 0));
                CHECK(up.x == 6.0f && down.x == 1.5f, "pbrt: map turned by the CTM and scaled by L: up %g (6), down %g (1.5)",
                      (double)up.x, (double)down.x);
            }
        }
        cdl_scene_free(&s);
    }
}

int main(int argc, char **argv)
{
    const char *integ = argc > 1 ? argv[1] : "path";
    if (getenv("CDL_TEST_SCALE") && atoi(getenv("CDL_TEST_SCALE")) > 1) {
        spp_div = (uint32_t)atoi(getenv("CDL_TEST_SCALE"));
        tol_scale = sqrt((double)spp_div);
    }
    sampling(CDL_ENVMAP_EQUIRECT);
    equal_area_mapping();
    sampling(CDL_ENVMAP_EQUAL_AREA);
    sampling(CDL_ENVMAP_MITSUBA);
    mitsuba_layout();
    pbrt_map(integ);
    plane_under_map(integ, 1, CDL_ENVMAP_EQUIRECT);
    plane_under_map(integ, 0, CDL_ENVMAP_EQUIRECT);
    plane_under_map(integ, 0, CDL_ENVMAP_MITSUBA);
    plane_under_distant(integ);
    sphere_under_constant(integ, 0);
    sphere_under_constant(integ, 1);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
