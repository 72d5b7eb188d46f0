/* pbrt reader: transforms, camera frame, Include, instancing, orientation
 * of emitting triangles and spheres, materials; then the real scenes.
 * Textures: test_pbrt_textures.c.
 *
 *   test_pbrt [SHARED_SCENES_DIR]
 *
 * Writes small .pbrt files into a fresh temporary directory. The real
 * scenes (cornell-box-bitterli, veach-mis, veach-bidir) are loaded from
 * SHARED_SCENES_DIR/<name>/pbrt-v3/scene.pbrt and skipped when absent. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/log.h"
#include "io/loader.h"
#include "io/pbrt_loader.h"
#include "test_util.h"

static char dir[200];

static void write_file(const char *name, const char *text)
{
    test_write(dir, name, text, strlen(text));
}

/* Loads dir/name; prints and returns the status. */
static int load(const char *name, cdl_scene *s, cdl_scene_settings *set, cdl_error *err)
{
    return test_load(dir, name, s, set, err);
}

static cdl_vec3 vert(const cdl_scene *s, uint32_t i)
{
    return cdl_v3(s->pos[3 * i], s->pos[3 * i + 1], s->pos[3 * i + 2]);
}

static int near3(cdl_vec3 a, cdl_vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

#define V3(v) (double)(v).x, (double)(v).y, (double)(v).z

static void count_warning(void *user, const char *file, int line, const char *msg)
{
    (void)file;
    (void)msg;
    *(int *)user += line == 2;
}

static const char *LIGHT = "LightSource \"point\" \"rgb I\" [1 1 1] \"point from\" [0 0 10]\n";
static const char *TRI = "Shape \"trianglemesh\" \"integer indices\" [0 1 2] "
                         "\"point P\" [1 0 0  0 1 0  0 0 1]\n";

static void test_transforms(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[1024];
    /* p' = T S R p, as pbrt composes the CTM (each directive post-multiplies) */
    snprintf(text, sizeof text,
             "WorldBegin\n%sTranslate 1 2 3\nScale 2 2 2\nRotate 90 0 0 1\n%s", LIGHT, TRI);
    write_file("xf.pbrt", text);
    int rc = load("xf.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.nverts == 3, "Translate/Scale/Rotate scene loads (%u vertices)", s.nverts);
    if (!rc) {
        cdl_vec3 want[3] = {cdl_v3(1, 4, 3), cdl_v3(-1, 2, 3), cdl_v3(1, 2, 5)};
        for (uint32_t i = 0; i < 3; i++)
            CHECK(near3(vert(&s, i), want[i], 1e-5f), "T S R vertex %u = (%g %g %g), expected (%g %g %g)", i,
                  V3(vert(&s, i)), V3(want[i]));
    }
    cdl_scene_free(&s);

    /* LookAt as a world transform: world-to-"camera" of pbrt's LookAt */
    snprintf(text, sizeof text, "WorldBegin\n%sLookAt 0 0 5  0 0 0  0 1 0\n%s", LIGHT, TRI);
    write_file("xf2.pbrt", text);
    rc = load("xf2.pbrt", &s, &set, &err);
    if (!rc) {
        cdl_vec3 want[3] = {cdl_v3(-1, 0, 5), cdl_v3(0, 1, 5), cdl_v3(0, 0, 4)};
        for (uint32_t i = 0; i < 3; i++)
            CHECK(near3(vert(&s, i), want[i], 1e-5f), "LookAt vertex %u = (%g %g %g), expected (%g %g %g)", i,
                  V3(vert(&s, i)), V3(want[i]));
    } else {
        CHECK(0, "LookAt scene loads");
    }
    cdl_scene_free(&s);

    /* Transform/ConcatTransform are column-major; TransformBegin/End and
     * AttributeBegin/End restore the CTM; CoordSysTransform */
    snprintf(text, sizeof text,
             "WorldBegin\n%sCoordinateSystem \"base\"\nTransformBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  "
             "10 20 30 1]\nConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1]\n%sTransformEnd\n"
             "AttributeBegin\nTranslate 5 0 0\nAttributeEnd\nTranslate 0 0 -1\nCoordSysTransform \"base\"\n%s",
             LIGHT, TRI, TRI);
    write_file("xf3.pbrt", text);
    rc = load("xf3.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.nverts == 6, "Transform/ConcatTransform/blocks scene loads (%u vertices)", s.nverts);
    if (!rc) {
        CHECK(near3(vert(&s, 0), cdl_v3(12, 20, 30), 1e-4f), "Transform*ConcatTransform vertex 0 = (%g %g %g), expected (12 20 30)",
              V3(vert(&s, 0)));
        CHECK(near3(vert(&s, 3), cdl_v3(1, 0, 0), 1e-6f), "after the blocks + CoordSysTransform vertex 3 = (%g %g %g), expected (1 0 0)",
              V3(vert(&s, 3)));
    }
    cdl_scene_free(&s);
}

static void test_camera(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[1024];
    snprintf(text, sizeof text,
             "LookAt 1 2 3  1 2 0  0 1 0\nCamera \"perspective\" \"float fov\" [45]\n"
             "Film \"image\" \"integer xresolution\" [320] \"integer yresolution\" [200] \"string filename\" \"out.exr\"\n"
             "Sampler \"sobol\" \"integer pixelsamples\" 32\nIntegrator \"path\" \"integer maxdepth\" [7]\n"
             "WorldBegin\n%s%s",
             LIGHT, TRI);
    write_file("cam.pbrt", text);
    int rc = load("cam.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.has_camera, "LookAt camera scene loads");
    if (!rc) {
        printf("      eye (%g %g %g) right (%g %g %g) up (%g %g %g) fwd (%g %g %g) fov %g\n", V3(set.eye),
               V3(set.right), V3(set.up), V3(set.fwd), (double)set.fov);
        CHECK(near3(set.eye, cdl_v3(1, 2, 3), 1e-5f), "camera eye (%g %g %g) = (1 2 3)", V3(set.eye));
        CHECK(near3(set.fwd, cdl_v3(0, 0, -1), 1e-5f), "camera fwd (%g %g %g) = (0 0 -1)", V3(set.fwd));
        /* pbrt's LookAt: right = cross(up, dir), so the image's +x is -x here */
        CHECK(near3(set.right, cdl_v3(-1, 0, 0), 1e-5f), "camera right (%g %g %g) = (-1 0 0), pbrt's cross(up, dir)",
              V3(set.right));
        CHECK(near3(set.up, cdl_v3(0, 1, 0), 1e-5f), "camera up (%g %g %g) = (0 1 0)", V3(set.up));
        CHECK(set.fov == 45.0f && set.width == 320 && set.height == 200 && set.spp == 32 && set.maxdepth == 7 &&
                  !strcmp(set.integrator, "path") && !strcmp(set.filename, "out.exr"),
              "fov %g, film %dx%d, spp %d, maxdepth %d, integrator %s, filename %s", (double)set.fov, set.width,
              set.height, set.spp, set.maxdepth, set.integrator, set.filename);
    }
    cdl_scene_free(&s);

    /* the usual handedness flip in front of LookAt mirrors the image */
    snprintf(text, sizeof text, "Scale -1 1 1\nLookAt 1 2 3  1 2 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n%s%s",
             LIGHT, TRI);
    write_file("cam2.pbrt", text);
    rc = load("cam2.pbrt", &s, &set, &err);
    CHECK(rc == 0 && near3(set.right, cdl_v3(1, 0, 0), 1e-5f) && near3(set.fwd, cdl_v3(0, 0, -1), 1e-5f) &&
              set.fov == 90.0f,
          "Scale -1 1 1 + LookAt: right (%g %g %g) = (1 0 0), fwd (%g %g %g), default fov %g", V3(set.right),
          V3(set.fwd), (double)set.fov);
    cdl_scene_free(&s);

    /* no Camera: pbrt's default at the origin looking down +z; pbrt defaults */
    snprintf(text, sizeof text, "WorldBegin\n%s%s", LIGHT, TRI);
    write_file("cam3.pbrt", text);
    rc = load("cam3.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.has_camera && near3(set.fwd, cdl_v3(0, 0, 1), 0) && near3(set.eye, cdl_v3(0, 0, 0), 0) &&
              set.width == 640 && set.height == 480 && set.spp == 16 && set.maxdepth == 5,
          "defaults: camera fwd (%g %g %g), %dx%d, %d spp, maxdepth %d", V3(set.fwd), set.width, set.height,
          set.spp, set.maxdepth);
    cdl_scene_free(&s);
}

static void test_include(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[1024], sub[256];
    snprintf(sub, sizeof sub, "%s/sub", dir);
    mkdir(sub, 0755);
    /* pbrt-v3 resolves every Include against the main file's directory */
    snprintf(text, sizeof text, "Include \"sub/more.pbrt\"\n%s", TRI);
    write_file("sub/geom.pbrt", text);
    write_file("sub/more.pbrt", "Translate 0 0 1\nShape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] "
                                "\"point P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n");
    snprintf(text, sizeof text, "WorldBegin\n%sAttributeBegin\nInclude \"sub/geom.pbrt\"\nAttributeEnd\n", LIGHT);
    write_file("inc.pbrt", text);
    int rc = load("inc.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.ntris == 3, "nested Include relative to the main file: %u triangles (expected 3)", s.ntris);
    if (!rc)
        CHECK(near3(vert(&s, 4), cdl_v3(1, 0, 1), 1e-6f), "the included Translate applies: vertex (%g %g %g)",
              V3(vert(&s, 4)));
    cdl_scene_free(&s);

    /* 32 nested files are fine, a 33rd level is an error */
    for (int depth = 32; depth <= 33; depth++) {
        for (int i = 0; i < depth; i++) {
            char name[64];
            snprintf(name, sizeof name, "deep%d.pbrt", i);
            if (i + 1 < depth)
                snprintf(text, sizeof text, "Include \"deep%d.pbrt\"\n", i + 1);
            else
                snprintf(text, sizeof text, "%s", TRI);
            write_file(name, text);
        }
        snprintf(text, sizeof text, "WorldBegin\n%sInclude \"deep0.pbrt\"\n", LIGHT);
        write_file("deep.pbrt", text);
        rc = load("deep.pbrt", &s, &set, &err);
        if (depth == 32)
            CHECK(rc == 0 && s.ntris == 1, "Include nested 32 deep loads (%u triangles)", s.ntris);
        else
            CHECK(rc != 0 && strstr(err.msg, "deeper than 32") && strstr(err.file, "deep31.pbrt") && err.line == 1,
                  "Include nested 33 deep is an error at %s:%d", err.file, err.line);
        cdl_scene_free(&s);
    }

    /* an Include error names the including file and line */
    write_file("inc2.pbrt", "WorldBegin\n\nInclude \"nope.pbrt\"\n");
    const cdl_log_sink quiet = {NULL, NULL, 1};
    const cdl_log_sink *prev = cdl_log_push(&quiet);
    rc = load("inc2.pbrt", &s, &set, &err);
    cdl_log_pop(prev);
    CHECK(rc != 0 && err.line == 3 && strstr(err.file, "inc2.pbrt"), "missing Include reported at %s:%d",
          err.file, err.line);
    cdl_scene_free(&s);
}

static void test_instancing(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[2048];
    snprintf(text, sizeof text,
             "WorldBegin\n%sObjectBegin \"quad\"\nTranslate 0 0 1\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [0 0 0 1 0 0 1 1 0 0 1 0]\n"
             "ObjectEnd\n"
             "ObjectInstance \"quad\"\nAttributeBegin\nTranslate 10 0 0\nObjectInstance \"quad\"\nAttributeEnd\n"
             "AttributeBegin\nScale 2 2 2\nObjectInstance \"quad\"\nAttributeEnd\n",
             LIGHT);
    write_file("inst.pbrt", text);
    int rc = load("inst.pbrt", &s, &set, &err);
    /* Embree instances of one group: no copies of the object's triangles */
    CHECK(rc == 0 && s.ntris == 0 && s.nverts == 4 && s.ngroups == 1 && s.ninsts == 3,
          "3 instances of a 2-triangle object: %u top-level triangles, %u vertices, %u groups, %u instances", s.ntris,
          s.nverts, s.ngroups, s.ninsts);
    if (!rc) {
        /* straight up onto each instance (from below: the Scale 2 one covers the first): object z = 1 as
         * it is, under Translate 10 and under Scale 2 */
        const float xs[3][3] = {{0.5f, 0.5f, 1.0f}, {10.5f, 0.5f, 1.0f}, {1.5f, 1.5f, 2.0f}};
        for (int i = 0; i < 3; i++) {
            cdl_hit h;
            cdl_surface sf;
            memset(&sf, 0, sizeof sf);
            int hit = cdl_intersect(&s, cdl_v3(xs[i][0], xs[i][1], -5.0f), cdl_v3(0, 0, 1), 100.0f, &h);
            if (hit)
                cdl_surface_at(&s, &h, &sf);
            CHECK(hit && h.inst != CDL_NO_INST && near3(sf.p, cdl_v3(xs[i][0], xs[i][1], xs[i][2]), 1e-5f) &&
                      fabsf(sf.ng.z) > 0.9999f,
                  "instance %d is hit at (%g %g %g), expected z = %g", i, V3(sf.p), (double)xs[i][2]);
        }
        CHECK(near3(s.bmax, cdl_v3(11, 2, 2), 1e-6f), "bounds reach (%g %g %g), expected (11 2 2)", V3(s.bmax));
    }
    cdl_scene_free(&s);
}

/* One emitting triangle (CCW normal +z) under `pre`, with normals `n`. */
static cdl_vec3 light_normal(const char *pre, const char *n, int *ok)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[1024];
    snprintf(text, sizeof text,
             "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n%s\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0] %s\nAttributeEnd\n",
             pre, n);
    write_file("orient.pbrt", text);
    int rc = load("orient.pbrt", &s, &set, &err);
    cdl_vec3 r = cdl_v3(0, 0, 0);
    *ok = rc == 0 && s.nlights == 1;
    if (*ok)
        r = s.lights[0].n;
    cdl_scene_free(&s);
    return r;
}

static void test_orientation(void)
{
    int ok;
    cdl_vec3 n = light_normal("", "", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, 1), 1e-6f), "triangle light emits along its CCW normal: (%g %g %g)", V3(n));
    n = light_normal("ReverseOrientation", "", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, -1), 1e-6f), "ReverseOrientation flips it: (%g %g %g)", V3(n));
    n = light_normal("Scale 1 1 -1", "", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, -1), 1e-6f), "a handedness-swapping transform flips it: (%g %g %g)", V3(n));
    n = light_normal("ReverseOrientation Scale 1 1 -1", "", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, 1), 1e-6f), "both flips cancel: (%g %g %g)", V3(n));
    n = light_normal("", "\"normal N\" [0 0 -1 0 0 -1 0 0 -1]", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, -1), 1e-6f), "N facing away from the CCW normal turns the triangle: (%g %g %g)",
          V3(n));
    n = light_normal("ReverseOrientation", "\"normal N\" [0 0 1 0 0 1 0 0 1]", &ok);
    CHECK(ok && near3(n, cdl_v3(0, 0, 1), 1e-6f), "with N, ReverseOrientation does not flip (pbrt-v3): (%g %g %g)",
          V3(n));
}

static void test_bilinear(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    /* pbrt-v4: a patch p00 p10 p01 p11, normal cross(dp/du, dp/dv) = +z */
    write_file("blp.pbrt", "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] "
                           "\"bool twosided\" false\nShape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0] "
                           "\"integer indices\" [0 1 2 3]\nAttributeEnd\n");
    int rc = load("blp.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.ntris == 2 && s.nlights == 2 && near3(s.lights[0].n, cdl_v3(0, 0, 1), 1e-6f) &&
              near3(s.lights[1].n, cdl_v3(0, 0, 1), 1e-6f),
          "bilinearmesh: %u triangles, %u lights facing (%g %g %g)", s.ntris, s.nlights,
          V3(rc ? cdl_v3(0, 0, 0) : s.lights[0].n));
    if (!rc)
        CHECK(fabsf(s.lights[0].area + s.lights[1].area - 1.0f) < 1e-6f, "bilinear patch area %g",
              (double)(s.lights[0].area + s.lights[1].area));
    cdl_scene_free(&s);
}

static void test_spheres(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    char text[1024];
    snprintf(text, sizeof text,
             "WorldBegin\n%sAttributeBegin\nTranslate 1 2 3\nRotate 30 1 1 0\nScale 2 2 2\n"
             "Shape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n"
             "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [2 2 2]\nScale -3 3 3\n"
             "Shape \"sphere\"\nAttributeEnd\n",
             LIGHT);
    write_file("sph.pbrt", text);
    int rc = load("sph.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.nspheres == 2 && s.ntris == 0, "similarity transforms keep spheres analytic: %u spheres, %u triangles",
          s.nspheres, s.ntris);
    if (!rc && s.nspheres == 2) {
        CHECK(near3(cdl_v3(s.sph[0], s.sph[1], s.sph[2]), cdl_v3(1, 2, 3), 1e-5f) && fabsf(s.sph[3] - 1.0f) < 1e-5f,
              "sphere 0 centre (%g %g %g) radius %g, expected (1 2 3) and 1", (double)s.sph[0], (double)s.sph[1],
              (double)s.sph[2], (double)s.sph[3]);
        CHECK(fabsf(s.sph[7] - 3.0f) < 1e-5f && s.sph_inward[1] == 1 && s.sph_inward[0] == 0 && s.nlights == 2,
              "mirrored sphere light: radius %g, inward %d (pbrt: ReverseOrientation XOR handedness), %u lights",
              (double)s.sph[7], s.sph_inward[1], s.nlights);
    }
    cdl_scene_free(&s);

    snprintf(text, sizeof text, "WorldBegin\n%sScale 1 2 1\nShape \"sphere\" \"float radius\" 2\n", LIGHT);
    write_file("sph2.pbrt", text);
    rc = load("sph2.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.nspheres == 0 && s.ntris > 8000, "non-uniform scale tessellates the sphere: %u triangles",
          s.ntris);
    if (!rc) {
        float ymax = 0.0f, xmax = 0.0f;
        int outward = 1;
        for (uint32_t i = 0; i < s.nverts; i++) {
            ymax = cdl_maxf(ymax, s.pos[3 * i + 1]);
            xmax = cdl_maxf(xmax, s.pos[3 * i]);
        }
        for (uint32_t t = 0; t < s.ntris; t++) {
            cdl_vec3 c = cdl_scale(cdl_add(cdl_add(vert(&s, s.idx[3 * t]), vert(&s, s.idx[3 * t + 1])),
                                           vert(&s, s.idx[3 * t + 2])), 1.0f / 3.0f);
            if (cdl_dot(s.face_n[t], c) <= 0.0f)
                outward = 0;
        }
        CHECK(fabsf(ymax - 4.0f) < 1e-4f && fabsf(xmax - 2.0f) < 1e-3f && outward,
              "ellipsoid extents x %g y %g (expected 2, 4), all faces outward %d", (double)xmax, (double)ymax,
              outward);
    }
    cdl_scene_free(&s);
}

static float v3_alpha(float r)
{
    float x = logf(r);
    return 1.62142f + 0.819955f * x + 0.1734f * x * x + 0.0171201f * x * x * x + 0.000640711f * x * x * x * x;
}

static void test_materials(void)
{
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    static const char *names[] = {"a", "b", "c", "d", "e", "f", "g", "h", "i", "j"};
    char text[8192];
    int n = snprintf(text, sizeof text, "WorldBegin\n%s"
             "MakeNamedMaterial \"a\" \"string type\" \"matte\" \"rgb Kd\" [0.1 0.2 0.3]\n"
             "MakeNamedMaterial \"b\" \"string type\" \"metal\" \"float roughness\" 0.1\n"
             "MakeNamedMaterial \"c\" \"string type\" \"metal\" \"bool remaproughness\" \"false\" "
             "\"float uroughness\" 0.05 \"float vroughness\" 0.2 \"spectrum eta\" \"metal-Au-eta\"\n"
             "MakeNamedMaterial \"d\" \"string type\" \"glass\" \"float index\" 1.33\n"
             "MakeNamedMaterial \"e\" \"string type\" \"glass\" \"float uroughness\" 0.3 \"float vroughness\" 0.3\n"
             "MakeNamedMaterial \"f\" \"string type\" \"plastic\" \"rgb Kd\" [0.5 0.5 0.5]\n"
             "MakeNamedMaterial \"g\" \"string type\" \"mirror\"\n"
             "MakeNamedMaterial \"h\" \"string type\" \"conductor\" \"float roughness\" 0.04\n"
             "MakeNamedMaterial \"i\" \"string type\" \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n"
             "MakeNamedMaterial \"j\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.7 0.6 0.5]\n",
             LIGHT);
    for (int i = 0; i < 10; i++)
        n += snprintf(text + n, sizeof text - (size_t)n, "NamedMaterial \"%s\"\nTranslate 0 0 1\n%s", names[i], TRI);
    write_file("mat.pbrt", text);
    int rc = load("mat.pbrt", &s, &set, &err);
    CHECK(rc == 0 && s.ntris == 10, "named materials scene loads (%u triangles)", s.ntris);
    if (rc || s.ntris != 10) {
        cdl_scene_free(&s);
        return;
    }
    const cdl_material *m[10];
    for (int i = 0; i < 10; i++)
        m[i] = &s.mats[s.tri_mat[i]];
    CHECK(m[0]->type == CDL_MAT_DIFFUSE && near3(m[0]->kd, cdl_v3(0.1f, 0.2f, 0.3f), 1e-6f) && !strcmp(m[0]->name, "a"),
          "matte -> DIFFUSE kd (%g %g %g), name %s", V3(m[0]->kd), m[0]->name);
    CHECK(m[1]->type == CDL_MAT_CONDUCTOR && fabsf(m[1]->alpha_x - v3_alpha(0.1f)) < 1e-5f &&
              m[1]->alpha_x == m[1]->alpha_y && near3(m[1]->eta3, cdl_v3(0.2004377f, 0.9240334f, 1.1022120f), 1e-5f),
          "metal roughness 0.1 remapped: alpha %g (pbrt-v3 RoughnessToAlpha %g), copper eta (%g %g %g)",
          (double)m[1]->alpha_x, (double)v3_alpha(0.1f), V3(m[1]->eta3));
    CHECK(m[2]->type == CDL_MAT_CONDUCTOR && m[2]->alpha_x == 0.05f && m[2]->alpha_y == 0.2f &&
              fabsf(m[2]->eta3.z - 1.4424786f) < 1e-5f,
          "metal remaproughness false: alpha (%g, %g), gold eta.z %g", (double)m[2]->alpha_x, (double)m[2]->alpha_y,
          (double)m[2]->eta3.z);
    CHECK(m[3]->type == CDL_MAT_DIELECTRIC && fabsf(m[3]->eta - 1.33f) < 1e-6f, "glass -> DIELECTRIC eta %g",
          (double)m[3]->eta);
    CHECK(m[4]->type == CDL_MAT_ROUGH_DIELECTRIC && fabsf(m[4]->alpha_x - v3_alpha(0.3f)) < 1e-5f,
          "rough glass -> ROUGH_DIELECTRIC alpha %g", (double)m[4]->alpha_x);
    CHECK(m[5]->type == CDL_MAT_PLASTIC && near3(m[5]->ks, cdl_v3(0.25f, 0.25f, 0.25f), 1e-6f) &&
              fabsf(m[5]->alpha_x - v3_alpha(0.1f)) < 1e-5f,
          "plastic -> PLASTIC ks %g alpha %g", (double)m[5]->ks.x, (double)m[5]->alpha_x);
    CHECK(m[6]->type == CDL_MAT_MIRROR && fabsf(m[6]->ks.x - 0.9f) < 1e-6f, "mirror -> MIRROR Kr %g", (double)m[6]->ks.x);
    CHECK(m[7]->type == CDL_MAT_CONDUCTOR && fabsf(m[7]->alpha_x - 0.2f) < 1e-6f,
          "v4 conductor roughness 0.04 -> alpha sqrt = %g", (double)m[7]->alpha_x);
    CHECK(m[8]->type == CDL_MAT_DIELECTRIC && fabsf(m[8]->eta - 1.5168f) < 1e-4f, "v4 dielectric glass-BK7 eta %g",
          (double)m[8]->eta);
    CHECK(m[9]->type == CDL_MAT_DIFFUSE && near3(m[9]->kd, cdl_v3(0.7f, 0.6f, 0.5f), 1e-6f),
          "v4 diffuse reflectance (%g %g %g)", V3(m[9]->kd));
    cdl_scene_free(&s);

    /* sampled spectra through the CIE observer: a constant reflectance is
     * grey, one above 600 nm is red; a light's L as emitted */
    snprintf(text, sizeof text,
             "WorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\" \"spectrum L\" [400 0 600 0 610 1 700 1]\n"
             "Material \"matte\" \"spectrum Kd\" [400 0.5 700 0.5]\n%sAttributeEnd\n"
             "Material \"matte\" \"spectrum Kd\" [400 0 600 0 610 0.8 700 0.8]\nTranslate 0 0 1\n%s",
             TRI, TRI);
    write_file("sampled.pbrt", text);
    if (!load("sampled.pbrt", &s, &set, &err)) {
        cdl_vec3 grey = s.mats[s.tri_mat[0]].kd, red = s.mats[s.tri_mat[1]].kd;
        CHECK(near3(grey, cdl_v3(0.5f, 0.5f, 0.5f), 2e-3f) && red.x > 0.3f && red.x > 5.0f * red.y &&
                  red.x > 5.0f * red.z && s.nlights == 1,
              "sampled Kd: constant 0.5 -> (%g %g %g), above 600 nm -> (%g %g %g)", V3(grey), V3(red));
        cdl_scene_free(&s);
    } else {
        CHECK(0, "sampled.pbrt loads");
    }

    /* a spot whose conedelta (default 5) exceeds its coneangle: pbrt renders
     * it, the falloff clamped to start at the axis; a warning names the line */
    snprintf(text, sizeof text,
             "WorldBegin\nLightSource \"spot\" \"rgb I\" [1 1 1] \"float coneangle\" 3\n%s", TRI);
    write_file("spot.pbrt", text);
    int warned = 0;
    cdl_log_sink count = {count_warning, &warned, 0};
    const cdl_log_sink *prev = cdl_log_push(&count);
    rc = load("spot.pbrt", &s, &set, &err);
    cdl_log_pop(prev);
    CHECK(!rc && warned == 1 && s.nlights == 1 && fabsf(s.lights[0].cos_falloff - 1.0f) < 1e-6f &&
              fabsf(s.lights[0].cos_total - cosf(3.0f * CDL_PI / 180.0f)) < 1e-6f,
          "spot coneangle 3 < conedelta 5 loads, clamped, with %d warning", warned);
    if (!rc)
        cdl_scene_free(&s);

    /* pbrt (v3 and v4) names the falloff width "conedeltaangle": 10 of a
     * 30-degree cone starts the falloff at 20 degrees, without a warning */
    snprintf(text, sizeof text,
             "WorldBegin\nLightSource \"spot\" \"rgb I\" [1 1 1] \"float coneangle\" 30 "
             "\"float conedeltaangle\" 10\n%s", TRI);
    write_file("spot2.pbrt", text);
    warned = 0;
    prev = cdl_log_push(&count);
    rc = load("spot2.pbrt", &s, &set, &err);
    cdl_log_pop(prev);
    CHECK(!rc && warned == 0 && s.nlights == 1 &&
              fabsf(s.lights[0].cos_falloff - cosf(20.0f * CDL_PI / 180.0f)) < 1e-6f &&
              fabsf(s.lights[0].cos_total - cosf(30.0f * CDL_PI / 180.0f)) < 1e-6f,
          "spot conedeltaangle 10 of coneangle 30: falloff from cos %g (cos 20 deg), %d warnings",
          rc ? 0.0 : (double)s.lights[0].cos_falloff, warned);
    if (!rc)
        cdl_scene_free(&s);

    /* pbrt-v4's thindielectric: a dielectric of its eta, with a warning (it
     * was an opaque matte, which hid the light behind a pane) */
    snprintf(text, sizeof text, "WorldBegin\nMaterial \"thindielectric\" \"float eta\" 1.33\n%s%s", LIGHT, TRI);
    write_file("thin.pbrt", text);
    warned = 0;
    prev = cdl_log_push(&count);
    rc = load("thin.pbrt", &s, &set, &err);
    cdl_log_pop(prev);
    CHECK(!rc && warned == 1 && s.mats[s.tri_mat[0]].type == CDL_MAT_DIELECTRIC &&
              fabsf(s.mats[s.tri_mat[0]].eta - 1.33f) < 1e-6f,
          "thindielectric as a dielectric of eta 1.33, with %d warning", warned);
    if (!rc)
        cdl_scene_free(&s);

    /* an area light on Material "none" still emits (pbrt lets rays through
     * the surface; candela's is black), with a warning */
    snprintf(text, sizeof text,
             "WorldBegin\nAttributeBegin\nMaterial \"none\"\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4]\n"
             "Shape \"sphere\" \"float radius\" 0.2\nAttributeEnd\n%s", TRI);
    write_file("none.pbrt", text);
    rc = load("none.pbrt", &s, &set, &err);
    CHECK(!rc && s.nspheres == 1 && s.nlights == 1 && s.nmats == 2 && s.mats[0].kd.x == 0.0f,
          "an area light on material none emits: %u spheres, %u lights", s.nspheres, s.nlights);
    if (!rc)
        cdl_scene_free(&s);

    /* disk, annulus, half disk and cylinder area lights: their areas (128
     * segments a full turn: 0.04 % short of the circle) and orientation
     * (a disk faces +z, a cylinder outwards, ReverseOrientation flips) */
    struct {
        const char *shape;
        double area;
        int axis, outward; /* the normal's sign along +z, or outwards from the z axis */
    } round[] = {
        {"\"disk\" \"float radius\" 2", CDL_PI * 4.0, 1, 0},
        {"\"disk\" \"float radius\" 2 \"float innerradius\" 1 \"float height\" 0.5", CDL_PI * 3.0, 1, 0},
        {"\"disk\" \"float radius\" 2 \"float phimax\" 180", CDL_PI * 2.0, 1, 0},
        {"\"cylinder\" \"float radius\" 1 \"float zmin\" -1 \"float zmax\" 1", CDL_PI * 4.0, 0, 1},
    };
    for (int rev = 0; rev < 2; rev++)
        for (size_t k = 0; k < sizeof round / sizeof round[0]; k++) {
            snprintf(text, sizeof text,
                     "WorldBegin\nAttributeBegin\n%sAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\nShape %s\n"
                     "AttributeEnd\n",
                     rev ? "ReverseOrientation\n" : "", round[k].shape);
            write_file("round.pbrt", text);
            rc = load("round.pbrt", &s, &set, &err);
            double area = 0.0;
            int oriented = 0;
            for (uint32_t i = 0; !rc && i < s.nlights; i++) {
                const cdl_light *l = &s.lights[i];
                area += l->area;
                float sgn = rev ? -1.0f : 1.0f;
                if (round[k].axis)
                    oriented += l->n.z * sgn > 0.99f;
                else { /* the centroid's direction from the axis */
                    cdl_vec3 cc = cdl_add(l->p, cdl_scale(cdl_add(l->e1, l->e2), 1.0f / 3.0f));
                    oriented += (l->n.x * cc.x + l->n.y * cc.y) * sgn > 0.0f && fabsf(l->n.z) < 1e-4f;
                }
            }
            CHECK(!rc && fabs(area / round[k].area - 1.0) < 1e-3 && s.nlights > 0 && oriented == (int)s.nlights,
                  "Shape %s%s: %u lights, area %.4f (%.4f), %d oriented", round[k].shape,
                  rev ? " reversed" : "", s.nlights, area, round[k].area, oriented);
            if (!rc)
                cdl_scene_free(&s);
        }

    /* blackbody: pbrt-v4 (one value) normalizes to luminance 1 */
    snprintf(text, sizeof text, "WorldBegin\nLightSource \"point\" \"blackbody I\" [6500] \"float scale\" 2\n%s", TRI);
    write_file("bb.pbrt", text);
    rc = load("bb.pbrt", &s, &set, &err);
    if (!rc) {
        cdl_vec3 L = s.lights[0].L;
        float Y = cdl_luminance(L);
        CHECK(fabsf(Y - 2.0f) < 0.04f && fabsf(L.x / L.z - 1.0f) < 0.15f,
              "blackbody 6500 K x scale 2: (%g %g %g), luminance %g", V3(L), (double)Y);
    } else {
        CHECK(0, "blackbody scene loads");
    }
    cdl_scene_free(&s);
}

static void real_scene(const char *shared, const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s/pbrt-v3/scene.pbrt", shared, name);
    if (access(path, R_OK) != 0) {
        printf("skip: %s not found\n", path);
        return;
    }
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    cdl_scene_settings_init(&set);
    int rc = cdl_scene_init(&s, path, &err);
    if (!rc)
        rc = cdl_load_pbrt(&s, path, &set, &err);
    if (!rc)
        rc = cdl_scene_commit(&s, &err);
    char buf[2048] = "";
    if (rc)
        cdl_error_format(&err, buf, sizeof buf);
    CHECK(rc == 0 && s.nlights > 0, "%s: %u triangles, %u spheres, %u lights, %u materials %s", name, s.ntris,
          s.nspheres, s.nlights, s.nmats, buf);
    if (!rc)
        printf("      camera eye (%g %g %g) right (%g %g %g) up (%g %g %g) fwd (%g %g %g) fov %g, %dx%d, %d spp, "
               "%s maxdepth %d\n",
               V3(set.eye), V3(set.right), V3(set.up), V3(set.fwd), (double)set.fov, set.width, set.height, set.spp,
               set.integrator, set.maxdepth);
    cdl_scene_free(&s);
}

/* PixelFilter (issue 27): pbrt-v3's widths and alpha, pbrt-v4's radii
 * and sigma (its gaussian's default radius 1.5), samples not clipped. */
static void test_filters(void)
{
    static const char *const files[][2] = {
        {"f3.pbrt", "PixelFilter \"gaussian\"\n"},
        {"f4.pbrt", "PixelFilter \"gaussian\" \"float sigma\" [ 0.25 ]\n"},
        {"ft.pbrt", "PixelFilter \"triangle\" \"float xwidth\" [ 1 ] \"float ywidth\" [ 1.5 ]\n"},
        {"fl.pbrt", "PixelFilter \"lanczos\"\n"}};
    for (int i = 0; i < 4; i++) {
        char text[512];
        snprintf(text, sizeof text,
                 "%sWorldBegin\nAttributeBegin\nAreaLightSource \"diffuse\"\n"
                 "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [0 0 0 1 0 0 0 1 0]\n"
                 "AttributeEnd\nWorldEnd\n",
                 files[i][1]);
        write_file(files[i][0], text);
    }
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    int rc = load("f3.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.has_filter && set.filter.type == CDL_FILTER_GAUSSIAN && set.filter.radius[0] == 2.0f &&
              set.filter.p0 == 2.0f && !set.filter.clip,
          "pbrt-v3 gaussian: width 2, alpha 2, unclipped");
    if (!rc)
        cdl_scene_free(&s);
    rc = load("f4.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.filter.type == CDL_FILTER_GAUSSIAN && set.filter.radius[0] == 1.5f &&
              fabsf(set.filter.p0 - 8.0f) < 1e-5f,
          "pbrt-v4 gaussian: radius 1.5, sigma 0.25");
    if (!rc)
        cdl_scene_free(&s);
    rc = load("ft.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.filter.type == CDL_FILTER_TENT && set.filter.radius[0] == 1.0f &&
              set.filter.radius[1] == 1.5f,
          "pbrt triangle of widths 1 x 1.5");
    if (!rc)
        cdl_scene_free(&s);
    rc = load("fl.pbrt", &s, &set, &err);
    CHECK(rc == 0 && set.filter.type == CDL_FILTER_LANCZOS && set.filter.radius[0] == 4.0f && set.filter.p0 == 3.0f,
          "pbrt-v4 lanczos: radius 4, tau 3");
    if (!rc)
        cdl_scene_free(&s);
}

int main(int argc, char **argv)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/candela-pbrt-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    test_transforms();
    test_camera();
    test_include();
    test_instancing();
    test_orientation();
    test_bilinear();
    test_spheres();
    test_materials();
    test_filters();
    const char *shared = argc > 1 ? argv[1] : "../shared/scenes";
    real_scene(shared, "cornell-box-bitterli");
    real_scene(shared, "veach-mis");
    real_scene(shared, "veach-bidir");
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    printf("%d failure(s)\n", test_failures);
    return test_failures != 0;
}
