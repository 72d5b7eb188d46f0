/* Mesh attributes and blended bsdfs (issue 27, Mitsuba 3's mesh_attributes
 * tests): the PLY reader's grouping and decoding of extra properties, the
 * values a hit reads (per face, interpolated per vertex), blendbsdf as an
 * exact blend of two diffuse reflectances and as a per-point choice with
 * the weight's probability, and the error on a missing attribute. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/log.h"
#include "io/loader.h"
#include "io/ply.h"
#include "scene/attr.h"
#include "test_util.h"

static char dir[200];

static void write_file(const char *name, const char *text) { test_write(dir, name, text, strlen(text)); }

/* A unit quad in z = 0 as one polygon (two triangles in the fan), vertex
 * colours as uchar "red green blue", face colour_0..2, weight_0, quality. */
static const char *ply =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "element face 1\nproperty list uchar int vertex_indices\nproperty float color_0\nproperty float color_1\n"
    "property float color_2\nproperty float weight_0\nproperty float quality\nend_header\n"
    "-1 -1 0 255 0 0\n1 -1 0 0 255 0\n1 1 0 0 0 255\n-1 1 0 128 128 128\n"
    "4 0 1 2 3 0.25 0.5 0.75 0.3 7\n";

static const cdl_mesh_attr *find(const cdl_mesh *m, const char *name)
{
    for (int k = 0; k < m->nattrs; k++)
        if (!strcmp(m->attrs[k].name, name))
            return &m->attrs[k];
    return NULL;
}

static void ply_attributes(void)
{
    write_file("q.ply", ply);
    char path[512];
    snprintf(path, sizeof path, "%s/q.ply", dir);
    cdl_mesh m;
    cdl_error err;
    if (cdl_ply_read(path, &m, &err)) {
        CHECK(0, "q.ply reads: %s", err.msg);
        return;
    }
    const cdl_mesh_attr *vc = find(&m, "vertex_color"), *fc = find(&m, "face_color"), *fw = find(&m, "face_weight"),
                        *fq = find(&m, "face_quality");
    CHECK(m.nattrs == 4 && vc && fc && fw && fq, "4 attributes: vertex_color, face_color, face_weight, face_quality "
                                                 "(%d found)", m.nattrs);
    if (vc && fc && fw && fq) {
        CHECK(vc->dim == 3 && !vc->per_face && vc->data[0] == 1.0f && vc->data[1] == 0.0f &&
                  fabsf(vc->data[9] - 0.2158605f) < 1e-5f,
              "vertex_color: uchar 255 -> 1, 128 -> sRGB-decoded 0.21586 (got %g)", (double)vc->data[9]);
        CHECK(m.ntris == 2 && fc->dim == 3 && fc->per_face && fc->data[3] == 0.25f && fc->data[5] == 0.75f,
              "face_color: (0.25, 0.5, 0.75) on both triangles of the fan");
        CHECK(fw->dim == 1 && fw->data[1] == 0.3f && fq->dim == 1 && fq->data[0] == 7.0f,
              "face_weight 0.3 (weight_0), face_quality 7 (a lone property)");
    }
    cdl_mesh_free(&m);
}

/* The surface (and its decided material) where the ray from (x, y, 5)
 * straight down meets the scene. */
static int hit_at(const cdl_scene *s, float x, float y, cdl_surface *sf)
{
    cdl_hit h;
    if (!cdl_intersect(s, cdl_v3(x, y, 5.0f), cdl_v3(0.0f, 0.0f, -1.0f), 100.0f, &h))
        return 0;
    cdl_surface_at(s, &h, sf);
    return 1;
}

static int load(const char *name, cdl_scene *s, cdl_error *err)
{
    cdl_scene_settings set;
    int rc = test_load(dir, name, s, &set, err);
    if (rc)
        cdl_scene_free(s);
    return rc;
}

#define HEAD "<scene version=\"3.0.0\"><emitter type=\"directional\"><vector name=\"direction\" value=\"0,0,-1\"/></emitter>\n"

static void hits(void)
{
    write_file("a.xml", HEAD
               "<texture type=\"mesh_attribute\" id=\"vc\"><string name=\"name\" value=\"vertex_color\"/></texture>\n"
               "<texture type=\"mesh_attribute\" id=\"fw\"><string name=\"name\" value=\"face_weight\"/></texture>\n"
               "<bsdf type=\"diffuse\" id=\"d\"><ref name=\"reflectance\" id=\"vc\"/></bsdf>\n"
               "<bsdf type=\"blendbsdf\" id=\"b\"><ref name=\"weight\" id=\"fw\"/>"
               "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0, .5, .5\"/></bsdf>"
               "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"1, 1, 0\"/></bsdf></bsdf>\n"
               "<bsdf type=\"blendbsdf\" id=\"r\"><float name=\"weight\" value=\"0.25\"/>"
               "<bsdf type=\"diffuse\"/><bsdf type=\"roughconductor\"/></bsdf>\n"
               "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><ref id=\"d\"/></shape>\n"
               "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><ref id=\"b\"/>"
               "<transform name=\"to_world\"><translate x=\"3\"/></transform></shape>\n"
               "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><ref id=\"r\"/>"
               "<transform name=\"to_world\"><translate x=\"6\"/></transform></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_error err;
    if (load("a.xml", &s, &err)) {
        CHECK(0, "a.xml loads: %s", err.msg);
        return;
    }
    cdl_surface sf;
    /* (x, y) = (-0.5, -0.5): in triangle (0, 1, 2), barycentrics (0.75, 0, 0.25)
     * of vertex colours red, green, blue */
    CHECK(hit_at(&s, -0.5f, -0.5f, &sf) && s.mats[sf.mat].hit_kd &&
              fabsf(sf.kdh.x - 0.75f) < 1e-4f && fabsf(sf.kdh.y) < 1e-4f && fabsf(sf.kdh.z - 0.25f) < 1e-4f,
          "vertex colours interpolated: (%g, %g, %g), want (0.75, 0, 0.25)", (double)sf.kdh.x, (double)sf.kdh.y,
          (double)sf.kdh.z);
    CHECK(hit_at(&s, 3.4f, 0.3f, &sf) && s.mats[sf.mat].type == CDL_MAT_DIFFUSE && fabsf(sf.kdh.x - 0.3f) < 1e-5f &&
              fabsf(sf.kdh.y - 0.65f) < 1e-5f && fabsf(sf.kdh.z - 0.35f) < 1e-5f,
          "diffuse blend at face weight 0.3: 0.7 (0, .5, .5) + 0.3 (1, 1, 0) = (0.3, 0.65, 0.35), got (%g, %g, %g)",
          (double)sf.kdh.x, (double)sf.kdh.y, (double)sf.kdh.z);
    /* per point: the conductor with probability 0.25, the same at the same point */
    int n = 4000, second = 0, same = 1;
    for (int i = 0; i < n; i++) {
        float x = 5.0f + 1.9f * ((float)(i % 63) + 0.5f) / 63.0f, y = -0.95f + 1.9f * ((float)i + 0.5f) / (float)n;
        cdl_surface a, c;
        if (!hit_at(&s, x, y, &a) || !hit_at(&s, x, y, &c))
            continue;
        second += s.mats[a.mat].type != CDL_MAT_DIFFUSE;
        same &= a.mat == c.mat;
    }
    double p = (double)second / n, sd = sqrt(0.25 * 0.75 / n);
    CHECK(fabs(p - 0.25) < 4.0 * sd && same, "blend weight 0.25: the second bsdf at %.4f of the points (4 sd %.4f), "
                                            "the same choice at the same point: %d", p, 4.0 * sd, same);
    cdl_scene_free(&s);

    write_file("miss.xml", HEAD
               "<texture type=\"mesh_attribute\" id=\"t\"><string name=\"name\" value=\"vertex_weight\"/></texture>\n"
               "<bsdf type=\"diffuse\" id=\"d\"><ref name=\"reflectance\" id=\"t\"/></bsdf>\n"
               "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><ref id=\"d\"/></shape>\n</scene>\n");
    int rc = load("miss.xml", &s, &err);
    CHECK(rc && err.line == 4 && strstr(err.msg, "vertex_weight"),
          "a bsdf reading an attribute the mesh lacks fails at the shape (line %d: %s)", err.line, err.msg);
}

static int attr_warnings;

static void on_warning(void *user, const char *file, int line, const char *msg)
{
    (void)user;
    (void)file;
    attr_warnings += line == 3 && strstr(msg, "mesh_attribute") != NULL;
}

/* An attribute as a roughness is not read at the hit: a warning at the bsdf. */
static void unread_slot(void)
{
    write_file("slot.xml", HEAD
               "<texture type=\"mesh_attribute\" id=\"w\"><string name=\"name\" value=\"face_weight\"/></texture>\n"
               "<bsdf type=\"roughconductor\" id=\"c\"><ref name=\"alpha\" id=\"w\"/></bsdf>\n"
               "<shape type=\"ply\"><string name=\"filename\" value=\"q.ply\"/><ref id=\"c\"/></shape>\n</scene>\n");
    cdl_scene s;
    cdl_error err;
    const cdl_log_sink sink = {on_warning, NULL, 0};
    const cdl_log_sink *prev = cdl_log_push(&sink);
    int rc = load("slot.xml", &s, &err);
    cdl_log_pop(prev);
    CHECK(rc == 0 && attr_warnings == 1, "an attribute as roughness loads with a warning at its bsdf (%d)",
          attr_warnings);
    if (!rc)
        cdl_scene_free(&s);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/candela-attr.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    ply_attributes();
    hits();
    unread_slot();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
