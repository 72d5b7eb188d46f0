/* Mitsuba's sdfgrid polygonized (scene/sdfgrid.h) and its .vol reader
 * (io/vol.h): a sphere's distance grid gives a closed, outward mesh on the
 * trilinear zero set whose area and volume are the sphere's and converge
 * with the subdivision; normals are unit and outward in both of Mitsuba's
 * methods; malformed .vol files are refused with their name. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/vol.h"
#include "scene/sdfgrid.h"
#include "test_util.h"

#define PI 3.14159265358979323846
#define N 24
#define R 0.3

static float grid[N * N * N];

static void sphere_grid(void)
{
    for (int z = 0; z < N; z++)
        for (int y = 0; y < N; y++)
            for (int x = 0; x < N; x++) {
                double p[3] = {(double)x / (N - 1) - 0.5, (double)y / (N - 1) - 0.5, (double)z / (N - 1) - 0.5};
                grid[(z * N + y) * N + x] = (float)(sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - R);
            }
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Area, enclosed volume (divergence theorem: positive when outward) and
 * whether every edge has exactly two triangles, in opposite directions. */
static void measure(const cdl_mesh *m, double *area, double *vol, int *closed)
{
    *area = *vol = 0.0;
    uint64_t *e = malloc(sizeof *e * 3 * m->ntris);
    for (uint32_t t = 0; t < m->ntris; t++) {
        const uint32_t *i = m->idx + 3 * t;
        const float *a = m->pos + 3 * i[0], *b = m->pos + 3 * i[1], *c = m->pos + 3 * i[2];
        double u[3], v[3], x[3];
        for (int k = 0; k < 3; k++)
            u[k] = b[k] - a[k], v[k] = c[k] - a[k];
        for (int k = 0; k < 3; k++)
            x[k] = u[(k + 1) % 3] * v[(k + 2) % 3] - u[(k + 2) % 3] * v[(k + 1) % 3];
        *area += 0.5 * sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
        *vol += (a[0] * x[0] + a[1] * x[1] + a[2] * x[2]) / 6.0;
        for (int k = 0; k < 3; k++) /* directed edges: each must appear once, its reverse once */
            e[3 * t + k] = (uint64_t)i[k] << 32 | i[(k + 1) % 3];
    }
    qsort(e, 3 * (size_t)m->ntris, sizeof *e, cmp_u64);
    *closed = 1;
    for (size_t k = 0; k < 3 * (size_t)m->ntris; k++) {
        uint64_t rev = e[k] << 32 | e[k] >> 32;
        if ((k && e[k] == e[k - 1]) || !bsearch(&rev, e, 3 * (size_t)m->ntris, sizeof *e, cmp_u64))
            *closed = 0;
    }
    free(e);
}

static void test_sphere(void)
{
    cdl_error err;
    cdl_sdfgrid g = {{N, N, N}, grid};
    double a_exact = 4.0 * PI * R * R, v_exact = 4.0 / 3.0 * PI * R * R * R, areas[3];
    const int levels[3] = {1, 2, 4};
    for (int li = 0; li < 3; li++) {
        cdl_mesh m;
        die_on(cdl_sdfgrid_polygonize(&g, levels[li], CDL_SDF_SMOOTH, 1u << 24, &m, "t", 1, &err), &err);
        double area, vol;
        int closed;
        measure(&m, &area, &vol, &closed);
        areas[li] = area;
        CHECK(closed, "levels %d: %u triangles, closed (each edge twice, opposite directions)", levels[li], m.ntris);
        /* the trilinear interpolant of a convex distance exceeds it: its
         * zero set lies a little inside the sphere (0.6 % of the area, 1.1 %
         * of the volume at 24^3) */
        CHECK(area < a_exact && vol < v_exact && fabs(area / a_exact - 1.0) < 0.015 &&
                  fabs(vol / v_exact - 1.0) < 0.02,
              "levels %d: area %.5f (sphere %.5f, within 1.5 %%), volume %.6f (sphere %.6f, within 2 %%), inside", levels[li], area, a_exact,
              vol, v_exact);
        double worst = 0.0, nerr = 0.0, ang = 0.0;
        int outward = 1;
        for (uint32_t v = 0; v < m.nverts; v++) {
            double p[3] = {m.pos[3 * v], m.pos[3 * v + 1], m.pos[3 * v + 2]}, gr[3], f = cdl_sdfgrid_eval(&g, p, gr);
            double gl = sqrt(gr[0] * gr[0] + gr[1] * gr[1] + gr[2] * gr[2]);
            worst = fmax(worst, fabs(f) / gl); /* distance to the zero set, to first order */
            const float *n = m.nrm + 3 * v;
            double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            double r[3] = {p[0] - 0.5, p[1] - 0.5, p[2] - 0.5}, rl = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
            double c = (n[0] * r[0] + n[1] * r[1] + n[2] * r[2]) / (nl * rl);
            nerr = fmax(nerr, fabs(nl - 1.0));
            ang = fmax(ang, acos(fmin(1.0, c)) * 180.0 / PI);
            outward &= c > 0.0;
        }
        CHECK(worst < 1e-6, "levels %d: every vertex within %.2g of the trilinear zero set (< 1e-6)", levels[li],
              worst);
        CHECK(nerr < 1e-5 && outward && ang < 3.0,
              "levels %d: smooth normals unit (%.1g), outward, at most %.2f deg from the sphere's (< 3)", levels[li],
              nerr, ang);
        cdl_mesh_free(&m);
    }
    /* the mesh converges to the trilinear surface, its chords' error falling
     * as 1 / k^2: |A(2) - A(4)| is 1/5 of |A(1) - A(4)| */
    double d1 = fabs(areas[0] - areas[2]), d2 = fabs(areas[1] - areas[2]);
    CHECK(d1 > 0.0 && d2 < 0.4 * d1, "area converges: |A(k) - A(4)| = %.2e, %.2e for k = 1, 2", d1, d2);
    /* analytic normals: the gradient of the interpolant, unit and outward */
    cdl_mesh m;
    die_on(cdl_sdfgrid_polygonize(&g, 2, CDL_SDF_ANALYTIC, 1u << 24, &m, "t", 1, &err), &err);
    int ok = 1;
    for (uint32_t v = 0; v < m.nverts; v++) {
        const float *n = m.nrm + 3 * v, *p = m.pos + 3 * v;
        double nl = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
        ok &= fabs(nl - 1.0) < 1e-5 && n[0] * (p[0] - 0.5) + n[1] * (p[1] - 0.5) + n[2] * (p[2] - 0.5) > 0.0;
    }
    CHECK(ok, "analytic normals unit and outward (%u vertices)", m.nverts);
    cdl_mesh_free(&m);
    int rc = cdl_sdfgrid_polygonize(&g, 8, CDL_SDF_SMOOTH, 1000, &m, "t.xml", 7, &err);
    CHECK(rc == CDL_ERR_INPUT && err.line == 7 && strstr(err.msg, "1000 triangles"),
          "a triangle cap is an error at the shape's line: %s", err.msg);
    float flat[8] = {1, 1, 1, 1, 1, 1, 1, 1};
    cdl_sdfgrid e = {{2, 2, 2}, flat};
    rc = cdl_sdfgrid_polygonize(&e, 2, CDL_SDF_SMOOTH, 1000, &m, "t.xml", 7, &err);
    CHECK(rc == CDL_ERR_INPUT && strstr(err.msg, "no surface"), "a grid without a sign change: %s", err.msg);
}

/* A .vol file: header fields as given, then count floats of value val. */
static void write_vol(const char *path, const char *magic, int version, int32_t enc, const int32_t res[3],
                      int32_t ch, size_t count, float val)
{
    unsigned char h[48] = {0};
    memcpy(h, magic, 3);
    h[3] = (unsigned char)version;
    int32_t ints[5] = {enc, res[0], res[1], res[2], ch};
    memcpy(h + 4, ints, sizeof ints); /* the test machines are little-endian, as the format */
    FILE *f = fopen(path, "wb");
    fwrite(h, 1, sizeof h, f);
    for (size_t i = 0; i < count; i++) {
        float v = i == count / 2 ? val : (float)i - 3.5f;
        fwrite(&v, 4, 1, f);
    }
    fclose(f);
}

static void test_vol(void)
{
    char dir[] = "/tmp/cdl_sdfXXXXXX", path[256];
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        exit(2);
    }
    snprintf(path, sizeof path, "%s/g.vol", dir);
    const int32_t r2[3] = {2, 3, 4}, r1[3] = {1, 3, 4}, big[3] = {100000, 100000, 100000};
    cdl_vol v;
    cdl_error err;
    write_vol(path, "VOL", 3, 1, r2, 1, 24, 0.5f);
    int rc = cdl_vol_read(path, 1, 2, 1u << 20, &v, &err);
    CHECK(rc == 0 && v.res[0] == 2 && v.res[2] == 4 && v.data[1] == -2.5f && v.data[12] == 0.5f &&
              v.data[23] == 19.5f,
          "a 2 x 3 x 4 float grid reads back, x fastest");
    cdl_vol_free(&v);
    struct {
        const char *what, *magic;
        int version;
        int32_t enc, ch;
        const int32_t *res;
        size_t count;
        float val;
        const char *expect;
    } bad[] = {
        {"magic", "VOX", 3, 1, 1, r2, 24, 0, "VOL"},
        {"version 2", "VOL", 2, 1, 1, r2, 24, 0, "version 2"},
        {"float16 encoding", "VOL", 3, 2, 1, r2, 24, 0, "encoding 2"},
        {"three channels", "VOL", 3, 1, 3, r2, 72, 0, "3 channels"},
        {"a resolution of 1", "VOL", 3, 1, 1, r1, 12, 0, "resolution 1 x 3 x 4"},
        {"truncated data", "VOL", 3, 1, 1, r2, 23, 0, "bytes"},
        {"trailing data", "VOL", 3, 1, 1, r2, 25, 0, "bytes"},
        {"10^15 samples", "VOL", 3, 1, 1, big, 4, 0, "more than"},
        {"a NaN sample", "VOL", 3, 1, 1, r2, 24, NAN, "not finite"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        write_vol(path, bad[i].magic, bad[i].version, bad[i].enc, bad[i].res, bad[i].ch, bad[i].count, bad[i].val);
        memset(&err, 0, sizeof err);
        rc = cdl_vol_read(path, 1, 2, 1u << 20, &v, &err);
        CHECK(rc == CDL_ERR_INPUT && !strcmp(err.file, path) && strstr(err.msg, bad[i].expect) && !v.data,
              "refused: %s (%s)", bad[i].what, err.msg);
    }
    unlink(path);
    rc = cdl_vol_read(path, 1, 2, 1u << 20, &v, &err);
    CHECK(rc == CDL_ERR_INPUT && !strcmp(err.file, path), "a missing file: %s", err.msg);
    rmdir(dir);
}

static void write_text(const char *dir, const char *name, const char *text)
{
    test_write(dir, name, text, strlen(text));
}

/* Through the Mitsuba reader: an instanced sphere grid is hit where the
 * sphere is, facing the ray; an sdfgrid emitter is refused at its line. */
static void test_scene(void)
{
    char dir[] = "/tmp/cdl_sdfXXXXXX";
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        exit(2);
    }
    unsigned char h[48] = {'V', 'O', 'L', 3};
    int32_t ints[5] = {1, N, N, N, 1};
    memcpy(h + 4, ints, sizeof ints);
    unsigned char *buf = malloc(sizeof h + sizeof grid);
    memcpy(buf, h, sizeof h);
    memcpy(buf + sizeof h, grid, sizeof grid);
    test_write(dir, "s.vol", buf, sizeof h + sizeof grid);
    free(buf);
    write_text(dir, "a.xml",
               "<scene version=\"3.0.0\"><emitter type=\"constant\"/>\n"
               "<shape type=\"shapegroup\" id=\"g\"><shape type=\"sdfgrid\">"
               "<string name=\"filename\" value=\"s.vol\"/></shape></shape>\n"
               "<shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\">"
               "<translate x=\"-0.5\" y=\"-0.5\" z=\"-0.5\"/><scale value=\"2\"/></transform></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    int rc = test_load(dir, "a.xml", &s, &set, &err);
    CHECK(rc == 0, "an instanced sdfgrid loads");
    if (!rc) {
        cdl_hit hit;
        cdl_surface sf;
        int got = cdl_intersect(&s, cdl_v3(0.01f, 0.02f, 5.0f), cdl_v3(0.0f, 0.0f, -1.0f), 100.0f, &hit);
        if (got)
            cdl_surface_at(&s, &hit, &sf);
        /* radius 2 * 0.3, less the interpolant's shrinkage (under 1 % at 24^3) */
        CHECK(got && fabsf(sf.p.z - 0.6f) < 0.006f && sf.ns.z > 0.999f,
              "the ray down the z axis hits at z = %.4f (0.6), shading normal z %.5f", got ? sf.p.z : 0.0f,
              got ? sf.ns.z : 0.0f);
        cdl_scene_free(&s);
    } else {
        cdl_scene_free(&s);
    }
    write_text(dir, "b.xml",
               "<scene version=\"3.0.0\"><emitter type=\"constant\"/>\n"
               "<shape type=\"sdfgrid\"><string name=\"filename\" value=\"s.vol\"/>\n"
               "<emitter type=\"area\"/></shape>\n</scene>\n");
    rc = test_load(dir, "b.xml", &s, &set, &err);
    CHECK(rc == CDL_ERR_INPUT && err.line == 3 && strstr(err.msg, "area emitter"), "an sdfgrid emitter: line %d, %s",
          err.line, err.msg);
    cdl_scene_free(&s);
    const char *names[] = {"s.vol", "a.xml", "b.xml"};
    for (int i = 0; i < 3; i++) {
        char p[256];
        snprintf(p, sizeof p, "%s/%s", dir, names[i]);
        unlink(p);
    }
    rmdir(dir);
}

int main(void)
{
    sphere_grid();
    test_sphere();
    test_vol();
    test_scene();
    return test_failures ? 1 : 0;
}
