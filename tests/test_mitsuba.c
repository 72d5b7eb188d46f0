/* Mitsuba reader: camera frame and fov axes, transform order, defaults and
 * $variables, include, camelCase (0.6) names, built-in shapes and their
 * orientation, materials, emitters, and the environment map's orientation
 * texel by texel; then the real scenes.
 *
 *   test_mitsuba [SHARED_SCENES_DIR]
 *
 * Writes small .xml files into a fresh temporary directory. The shared
 * scenes (veach-mis, veach-bidir mitsuba3 and sponza mitsuba) are loaded
 * and compared with their pbrt-v3 twins' cameras when present. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/log.h"
#include "core/transform.h"
#include "film/image.h"
#include "io/loader.h"
#include "scene/microfacet_mts.h"
#include "scene/plastic.h"
#include "io/settings.h"
#include "test_util.h"

#define PI 3.14159265358979323846

static char dir[200];

static void write_file(const char *name, const char *text)
{
    test_write(dir, name, text, strlen(text));
}

static int load_path(const char *path, cdl_scene *s, cdl_scene_settings *set)
{
    cdl_error err;
    int rc = cdl_scene_init(s, path, &err);
    if (!rc)
        rc = cdl_scene_load(s, path, set, &err);
    if (!rc)
        rc = cdl_scene_commit(s, &err);
    if (rc) {
        char buf[2048];
        cdl_error_format(&err, buf, sizeof buf);
        printf("      load %s: %s\n", path, buf);
    }
    return rc;
}

static int load(const char *name, cdl_scene *s, cdl_scene_settings *set)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return load_path(path, s, set);
}

static int near3(cdl_vec3 a, cdl_vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

static cdl_vec3 unit(cdl_vec3 v)
{
    return cdl_scale(v, 1.0f / cdl_length(v));
}

#define LIGHT "<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"0\" z=\"9\"/></emitter>\n"

/* lookat camera, fov along x on a wide film, $variables with defaults,
 * and the transform order (scale, then translate). */
static void camera_and_transforms(void)
{
    write_file("cam.xml", "<scene version=\"3.0.0\">\n"
                          "<default name=\"w\" value=\"200\"/><default name=\"w\" value=\"999\"/>\n"
                          "<sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/>\n"
                          "<transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>"
                          "</transform>\n"
                          "<sampler type=\"independent\"><integer name=\"sample_count\" value=\"7\"/></sampler>\n"
                          "<film type=\"hdrfilm\"><integer name=\"width\" value=\"$w\"/>"
                          "<integer name=\"height\" value=\"100\"/></film></sensor>\n"
                          "<integrator type=\"bdpt\"><integer name=\"max_depth\" value=\"5\"/></integrator>\n" LIGHT
                          "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"2\"/>"
                          "<translate x=\"10\"/></transform></shape>\n"
                          "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("cam.xml", &s, &set)) {
        CHECK(0, "cam.xml loads");
        return;
    }
    double want = 2.0 * atan(tan(30.0 * PI / 180.0) * 100.0 / 200.0) * 180.0 / PI;
    CHECK(set.has_camera && near3(set.eye, cdl_v3(0, 0, 5), 1e-6f) && near3(unit(set.fwd), cdl_v3(0, 0, -1), 1e-6f) &&
              near3(unit(set.up), cdl_v3(0, 1, 0), 1e-6f) && near3(unit(set.right), cdl_v3(1, 0, 0), 1e-6f),
          "lookat: eye (%g %g %g), fwd (%g %g %g), right (%g %g %g) = +x (Mitsuba's +x is the image's left)",
          (double)set.eye.x, (double)set.eye.y, (double)set.eye.z, (double)set.fwd.x, (double)set.fwd.y,
          (double)set.fwd.z, (double)set.right.x, (double)set.right.y, (double)set.right.z);
    CHECK(fabs(set.fov - want) < 1e-4, "fov 60 along x on 200 x 100 is %.4f on the short axis (%.4f)", (double)set.fov,
          want);
    CHECK(set.width == 200 && set.height == 100 && set.spp == 7, "film $w = 200 (first default wins), 100, 7 spp");
    CHECK(!strcmp(set.integrator, "bdpt") && set.maxdepth == 4, "bdpt, max_depth 5 = maxdepth %d (4 bounces)",
          set.maxdepth);
    float xmin = 1e30f, xmax = -1e30f;
    for (uint32_t i = 0; i < s.nverts; i++)
        xmin = fminf(xmin, s.pos[3 * i]), xmax = fmaxf(xmax, s.pos[3 * i]);
    CHECK(s.ntris == 2 && xmin == 8.0f && xmax == 12.0f, "scale 2 then translate 10: x in [%g, %g] (8, 12)",
          (double)xmin, (double)xmax);
    cdl_scene_free(&s);

    /* -D w=64 (Mitsuba's command line) wins over the file's <default>s;
     * the focal length's default of 50 mm spans the film's diagonal */
    const char defs[2][CDL_DEFINE_LEN] = {"w=64", "unknown=1"};
    char path[512];
    snprintf(path, sizeof path, "%s/cam.xml", dir);
    cdl_error err;
    int rc = cdl_scene_init(&s, path, &err);
    if (!rc)
        rc = cdl_scene_load_defined(&s, path, defs, 2, &set, &err);
    CHECK(!rc && set.width == 64, "define w=64: film width %d", set.width);
    cdl_scene_free(&s);
    write_file("focal.xml", "<scene version=\"3.0.0\"><sensor type=\"perspective\">\n"
                            "<film type=\"hdrfilm\"><integer name=\"width\" value=\"300\"/>"
                            "<integer name=\"height\" value=\"100\"/></film></sensor>\n" LIGHT
                            "<shape type=\"sphere\"/></scene>\n");
    if (!load("focal.xml", &s, &set)) {
        double diag = 2.0 * atan(sqrt(36.0 * 36.0 + 24.0 * 24.0) / 100.0);
        want = 2.0 * atan(tan(diag / 2.0) * 100.0 / sqrt(300.0 * 300.0 + 100.0 * 100.0)) * 180.0 / PI;
        CHECK(fabs(set.fov - want) < 1e-4, "50 mm on 300 x 100: %.4f degrees on the short axis (%.4f)",
              (double)set.fov, want);
        cdl_scene_free(&s);
    } else {
        CHECK(0, "focal.xml loads");
    }
}

/* mask: a copy of the nested material with its opacity; plastic. */
static void mask_and_plastic(void)
{
    write_file("mask.xml", "<scene version=\"3.0.0\">\n" LIGHT
                           "<bsdf type=\"diffuse\" id=\"leaf\"><rgb name=\"reflectance\" value=\"0.1, 0.8, 0.1\"/></bsdf>\n"
                           "<shape type=\"rectangle\"><bsdf type=\"mask\"><float name=\"opacity\" value=\"0.25\"/>"
                           "<ref id=\"leaf\"/></bsdf></shape>\n"
                           "<shape type=\"rectangle\"><bsdf type=\"plastic\"><float name=\"int_ior\" value=\"1.9\"/>"
                           "<boolean name=\"nonlinear\" value=\"true\"/></bsdf></shape>\n"
                           "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("mask.xml", &s, &set)) {
        CHECK(0, "mask.xml loads");
        return;
    }
    const cdl_material *m = s.mats;
    CHECK(s.nmats == 3 && !m[0].masked && m[1].masked && m[1].opacity == 0.25f && m[1].opacity_tex < 0 &&
              m[1].type == CDL_MAT_DIFFUSE && near3(m[1].kd, m[0].kd, 0.0f),
          "mask over a referenced diffuse: a masked copy, opacity 0.25 (%u materials)", s.nmats);
    CHECK(s.nmats == 3 && m[2].type == CDL_MAT_COATED && fabsf(m[2].eta - (float)(1.9 / 1.000277)) < 1e-5f &&
              m[2].nonlinear && fabsf(m[2].spec_weight - 1.0f / 1.5f) < 1e-6f &&
              fabsf(m[2].coat_ri - cdl_fresnel_diffuse_reflectance(1.0f / m[2].eta)) < 1e-6f,
          "plastic: smooth coat, int_ior 1.9, nonlinear, default kd 0.5 (weight 1 / 1.5), Fdr from inside");
    cdl_scene_free(&s);
}

/* Mitsuba 0.6 spelling (toWorld, intIOR, specularReflectance), include,
 * refs, the default bsdf, materials and emitters. */
static void materials_and_include(void)
{
    write_file("inc.xml", "<scene version=\"0.6.0\">\n<bsdf type=\"roughconductor\" id=\"metal\">"
                          "<string name=\"material\" value=\"Au\"/><float name=\"alpha\" value=\"0.2\"/>"
                          "<rgb name=\"specularReflectance\" value=\"0.3\"/></bsdf>\n</scene>\n");
    write_file("mat.xml",
               "<scene version=\"0.6.0\">\n<include filename=\"inc.xml\"/>\n" LIGHT
               "<shape type=\"cube\"><ref id=\"metal\"/></shape>\n"
               "<shape type=\"cube\"><bsdf type=\"dielectric\"><float name=\"intIOR\" value=\"1.6\"/>"
               "<float name=\"extIOR\" value=\"1.0\"/></bsdf></shape>\n"
               "<shape type=\"disk\"><bsdf type=\"twosided\"><bsdf type=\"roughplastic\">"
               "<rgb name=\"diffuseReflectance\" value=\"0.1, 0.2, 0.3\"/><string name=\"intIOR\" value=\"water\"/>"
               "</bsdf></bsdf></shape>\n"
               "<shape type=\"rectangle\"/>\n"
               "<shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/><float name=\"radius\" value=\"0.5\"/>"
               "<transform name=\"toWorld\"><scale value=\"2\"/></transform>"
               "<emitter type=\"area\"><spectrum name=\"radiance\" value=\"4\"/></emitter></shape>\n"
               "<emitter type=\"spot\"><float name=\"cutoffAngle\" value=\"30\"/>"
               "<transform name=\"toWorld\"><lookat origin=\"0,5,0\" target=\"0,0,0\" up=\"0,0,1\"/></transform>"
               "</emitter>\n"
               "<emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"-1\" z=\"0\"/>"
               "<rgb name=\"irradiance\" value=\"3\"/></emitter>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("mat.xml", &s, &set)) {
        CHECK(0, "mat.xml loads");
        return;
    }
    CHECK(s.nmats == 4, "%u materials: gold, glass, plastic, Mitsuba's default diffuse (rectangle and sphere)",
          s.nmats);
    const cdl_material *m = s.mats;
    CHECK(m[0].type == CDL_MAT_CONDUCTOR && fabsf(m[0].alpha_x - 0.2f) < 1e-6f && fabsf(m[0].ks.x - 0.3f) < 1e-6f &&
              fabsf(m[0].eta3.x - 0.1431f) < 1e-3f,
          "included roughconductor Au, alpha 0.2, specularReflectance 0.3");
    CHECK(m[1].type == CDL_MAT_DIELECTRIC && fabsf(m[1].eta - 1.6f) < 1e-6f, "dielectric intIOR/extIOR = %g",
          (double)m[1].eta);
    CHECK(m[2].type == CDL_MAT_ROUGH_COATED && fabsf(m[2].eta - (float)(1.333 / 1.000277)) < 1e-4f &&
              near3(m[2].kd, cdl_v3(0.1f, 0.2f, 0.3f), 1e-6f) && fabsf(m[2].alpha_x - 0.1f) < 1e-6f &&
              m[2].mf == CDL_MF_BECKMANN && fabsf(m[2].spec_weight - 1.0f / 1.2f) < 1e-6f && m[2].coat_ri > 0.3f &&
              m[2].coat_ri < 0.6f && m[2].coat_t[CDL_COAT_RES - 1] > 0.9f && !m[2].nonlinear,
          "twosided roughplastic: Mitsuba's coated model, water / air = %g, kd, beckmann alpha 0.1, specular "
          "sampling weight %g (1 / 1.2), inside reflectance %g, transmittance at normal incidence %g",
          (double)m[2].eta, (double)m[2].spec_weight, (double)m[2].coat_ri, (double)m[2].coat_t[CDL_COAT_RES - 1]);
    CHECK(m[3].type == CDL_MAT_DIFFUSE && near3(m[3].kd, cdl_v3(0.5f, 0.5f, 0.5f), 0.0f),
          "a shape without bsdf gets diffuse 0.5");
    CHECK(s.nspheres == 1 && near3(cdl_v3(s.sph[0], s.sph[1], s.sph[2]), cdl_v3(2, 4, 6), 1e-5f) &&
              fabsf(s.sph[3] - 1.0f) < 1e-6f && s.sph_emit[0] >= 0 && s.emitters[s.sph_emit[0]].L.x == 4.0f,
          "sphere center (1 2 3) r 0.5 under scale 2: (%g %g %g) r %g, emitting 4", (double)s.sph[0],
          (double)s.sph[1], (double)s.sph[2], (double)s.sph[3]);
    /* cube 12 + cube 12 + disk 128 + rectangle 2 */
    CHECK(s.ntris == 154, "triangles: 2 cubes, a 128-segment disk, a rectangle = %u (154)", s.ntris);
    /* every cube face's CCW normal points outwards */
    int outward = 0;
    for (uint32_t t = 0; t < 12; t++) {
        const uint32_t *ix = s.idx + 3 * t;
        cdl_vec3 a = cdl_v3(s.pos[3 * ix[0]], s.pos[3 * ix[0] + 1], s.pos[3 * ix[0] + 2]);
        cdl_vec3 b = cdl_v3(s.pos[3 * ix[1]], s.pos[3 * ix[1] + 1], s.pos[3 * ix[1] + 2]);
        cdl_vec3 c = cdl_v3(s.pos[3 * ix[2]], s.pos[3 * ix[2] + 1], s.pos[3 * ix[2] + 2]);
        cdl_vec3 ctr = cdl_scale(cdl_add(cdl_add(a, b), c), 1.0f / 3.0f);
        outward += cdl_dot(cdl_cross(cdl_sub(b, a), cdl_sub(c, a)), ctr) > 0.0f;
    }
    CHECK(outward == 12, "cube: %d of 12 triangles face outwards", outward);
    int spot = -1, dist = -1;
    for (uint32_t i = 0; i < s.nlights; i++) {
        if (s.lights[i].type == CDL_LIGHT_SPOT)
            spot = (int)i;
        if (s.lights[i].type == CDL_LIGHT_DISTANT)
            dist = (int)i;
    }
    CHECK(spot >= 0 && near3(s.lights[spot].p, cdl_v3(0, 5, 0), 1e-6f) &&
              near3(unit(s.lights[spot].n), cdl_v3(0, -1, 0), 1e-6f),
          "spot at (0 5 0) looking down its lookat");
    CHECK(dist >= 0 && near3(unit(s.lights[dist].n), cdl_v3(0, -1, 0), 1e-6f) && s.lights[dist].L.y == 3.0f,
          "directional light along -y, irradiance 3");
    cdl_scene_free(&s);
}

/* An OBJ shape's uvs: as the file has them by default (Mitsuba flips v and
 * looks textures up from the top: candela's convention), flipped with
 * flip_tex_coords false. */
static void obj_uvs(void)
{
    write_file("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0.25\nvt 1 0.25\nvt 0 1\nf 1/1 2/2 3/3\n");
    for (int flip = 0; flip < 2; flip++) {
        char xml[512];
        snprintf(xml, sizeof xml,
                 "<scene version=\"3.0.0\">\n" LIGHT "<shape type=\"obj\"><string name=\"filename\" value=\"tri.obj\"/>"
                 "%s</shape>\n</scene>\n",
                 flip ? "<boolean name=\"flip_tex_coords\" value=\"false\"/>" : "");
        write_file("obj.xml", xml);
        cdl_scene s;
        cdl_scene_settings set;
        if (load("obj.xml", &s, &set)) {
            CHECK(0, "obj.xml loads");
            return;
        }
        float v0 = s.uv[1];
        CHECK(s.nverts == 3 && fabsf(v0 - (flip ? 0.75f : 0.25f)) < 1e-6f, "obj uv v %g with flip_tex_coords %s",
              (double)v0, flip ? "false" : "true (default)");
        cdl_scene_free(&s);
    }
}

/* Spectra: three numbers are RGB (Mitsuba 0.6's RGB build); wavelength
 * pairs go through the CIE observer, reflectances under D65 (a constant
 * spectrum is grey, a long-wavelength one red), not averaged to grey. A
 * negative conductor eta is taken as Mitsuba takes it. */
static void spectra(void)
{
    write_file("spec.xml",
               "<scene version=\"3.0.0\">\n" LIGHT
               "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" "
               "value=\"0.2 0.4 0.6\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" "
               "value=\"400:0.5, 700:0.5\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum name=\"reflectance\" "
               "value=\"400:0.05, 550:0.05, 600:0.6, 700:0.6\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"conductor\"><rgb name=\"eta\" value=\"-0.2, -0.9, 1.1\"/>"
               "<rgb name=\"k\" value=\"3.9, 2.4, 2.1\"/></bsdf></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("spec.xml", &s, &set)) {
        CHECK(0, "spec.xml loads");
        return;
    }
    const cdl_material *m = s.mats;
    CHECK(s.nmats == 4 && near3(m[0].kd, cdl_v3(0.2f, 0.4f, 0.6f), 1e-6f), "three-number spectrum as RGB");
    CHECK(near3(m[3].eta3, cdl_v3(0.2f, 0.9f, 1.1f), 1e-6f), "a negative conductor eta is read as its magnitude");
    CHECK(near3(m[1].kd, cdl_v3(0.5f, 0.5f, 0.5f), 1e-4f), "constant spectrum 0.5 gives (%g, %g, %g)",
          (double)m[1].kd.x, (double)m[1].kd.y, (double)m[1].kd.z);
    CHECK(m[2].kd.x > 0.4f && m[2].kd.y < 0.25f && m[2].kd.z < 0.1f, "a red wall's spectrum reads red: (%g, %g, %g)",
          (double)m[2].kd.x, (double)m[2].kd.y, (double)m[2].kd.z);
    cdl_scene_free(&s);
}

/* Ids at any depth: a bsdf (and a texture) declared inside another
 * element is known from there on, as Mitsuba knows it. */
static void nested_ids(void)
{
    write_file("ids.xml",
               "<scene version=\"3.0.0\">\n" LIGHT
               "<shape type=\"rectangle\"><bsdf type=\"twosided\"><bsdf type=\"diffuse\" id=\"inner\">"
               "<rgb name=\"reflectance\" value=\"0.1, 0.2, 0.3\"/></bsdf></bsdf></shape>\n"
               "<shape type=\"cube\"><ref id=\"inner\"/></shape>\n"
               "<bsdf type=\"diffuse\" id=\"textured\"><texture type=\"bitmap\" name=\"reflectance\" id=\"tex\">"
               "<string name=\"filename\" value=\"px.png\"/></texture></bsdf>\n"
               "<bsdf type=\"diffuse\" id=\"again\"><ref name=\"reflectance\" id=\"tex\"/></bsdf>\n"
               "</scene>\n");
    float px[3] = {0.25f, 0.5f, 0.75f};
    cdl_image img = {1, 1, px};
    char path[512];
    snprintf(path, sizeof path, "%s/px.png", dir);
    cdl_error err;
    die_on(cdl_image_write(path, &img, NULL, 0, 0.0f, &err), &err);
    cdl_scene s;
    cdl_scene_settings set;
    if (load("ids.xml", &s, &set)) {
        CHECK(0, "ids.xml loads (a nested id referred to later)");
        return;
    }
    uint32_t rect = s.tri_mat[0], cube = s.tri_mat[2];
    CHECK(rect == cube && near3(s.mats[cube].kd, cdl_v3(0.1f, 0.2f, 0.3f), 1e-6f),
          "the cube's <ref id=\"inner\"> is the rectangle's nested bsdf (materials %u, %u)", rect, cube);
    cdl_scene_free(&s);
}

/* A shapegroup placed by two instances: Embree instances, not copies; an
 * emitter inside is dropped with a warning; an instance of something that
 * is not a shapegroup is an error naming its line. */
static int group_warnings;

static void on_group_warning(void *user, const char *file, int line, const char *msg)
{
    (void)user;
    (void)file;
    group_warnings += line == 4 && strstr(msg, "shapegroup") != NULL;
}

static void instancing(void)
{
    write_file("inst.xml",
               "<scene version=\"3.0.0\">\n" LIGHT
               "<shape type=\"shapegroup\" id=\"g\"><shape type=\"rectangle\"/>\n"
               "<shape type=\"sphere\"><emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter>"
               "<point name=\"center\" x=\"0\" y=\"0\" z=\"3\"/></shape></shape>\n"
               "<shape type=\"instance\"><ref id=\"g\"/></shape>\n"
               "<shape type=\"instance\"><ref id=\"g\"/><transform name=\"to_world\"><scale value=\"2\"/>"
               "<translate x=\"10\"/></transform></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    const cdl_log_sink sink = {on_group_warning, NULL, 0};
    const cdl_log_sink *prev = cdl_log_push(&sink);
    int rc = load("inst.xml", &s, &set);
    cdl_log_pop(prev);
    CHECK(rc == 0 && s.ntris == 0 && s.nspheres == 0 && s.ngroups == 1 && s.ninsts == 2 && s.nlights == 1,
          "a shapegroup and 2 instances: %u groups, %u instances, no top-level shapes, only the point light (%u)",
          s.ngroups, s.ninsts, s.nlights);
    CHECK(group_warnings == 1, "the emitter in the shapegroup is dropped with a warning at its line");
    if (!rc) {
        cdl_hit h;
        cdl_surface sf;
        memset(&sf, 0, sizeof sf);
        int hit = cdl_intersect(&s, cdl_v3(10.5f, 0.5f, -5.0f), cdl_v3(0, 0, 1), 100.0f, &h);
        if (hit)
            cdl_surface_at(&s, &h, &sf);
        CHECK(hit && h.inst == 1 && fabsf(sf.p.z) < 1e-5f && fabsf(sf.ng.z) > 0.9999f,
              "the second instance's rectangle is hit at (%g %g %g)", (double)sf.p.x, (double)sf.p.y,
              (double)sf.p.z);
        hit = cdl_intersect(&s, cdl_v3(10.0f, 0.0f, 20.0f), cdl_v3(0, 0, -1), 100.0f, &h);
        if (hit)
            cdl_surface_at(&s, &h, &sf);
        CHECK(hit && h.inst == 1 && h.geom == CDL_GEOM_SPHERES && fabsf(sf.p.z - 8.0f) < 1e-4f,
              "its sphere (centre z 3, radius 1, scaled 2) is hit at z = %g (8)", (double)sf.p.z);
    }
    cdl_scene_free(&s);
    write_file("inst_bad.xml", "<scene version=\"3.0.0\">\n" LIGHT "<bsdf type=\"diffuse\" id=\"d\"/>\n"
                               "<shape type=\"instance\">\n<ref id=\"d\"/></shape>\n</scene>\n");
    const cdl_log_sink quiet = {NULL, NULL, 1};
    prev = cdl_log_push(&quiet);
    char path[512];
    snprintf(path, sizeof path, "%s/inst_bad.xml", dir);
    cdl_error err;
    rc = cdl_scene_init(&s, path, &err);
    if (!rc)
        rc = cdl_scene_load(&s, path, &set, &err);
    cdl_log_pop(prev);
    CHECK(rc != 0 && err.line == 5, "an instance of a bsdf is an error at its <ref> (line %d)", err.line);
    cdl_scene_free(&s);
}

/* A cylinder from p0 to p1 (along x) of radius 0.5: its area and normals
 * outwards, inwards with flip_normals. */
static void cylinder(void)
{
    for (int flip = 0; flip < 2; flip++) {
        char xml[768];
        snprintf(xml, sizeof xml,
                 "<scene version=\"3.0.0\">\n<shape type=\"cylinder\"><point name=\"p0\" x=\"1\" y=\"2\" z=\"3\"/>"
                 "<point name=\"p1\" x=\"4\" y=\"2\" z=\"3\"/><float name=\"radius\" value=\"0.5\"/>%s"
                 "<emitter type=\"area\"><rgb name=\"radiance\" value=\"1\"/></emitter></shape>\n</scene>\n",
                 flip ? "<boolean name=\"flip_normals\" value=\"true\"/>" : "");
        write_file("cyl.xml", xml);
        cdl_scene s;
        cdl_scene_settings set;
        if (load("cyl.xml", &s, &set)) {
            CHECK(0, "cyl.xml loads");
            return;
        }
        double area = 0.0;
        int outward = 0;
        for (uint32_t i = 0; i < s.nlights; i++) {
            const cdl_light *l = &s.lights[i];
            cdl_vec3 cc = cdl_add(l->p, cdl_scale(cdl_add(l->e1, l->e2), 1.0f / 3.0f));
            area += l->area;
            outward += (l->n.y * (cc.y - 2.0f) + l->n.z * (cc.z - 3.0f)) * (flip ? -1.0f : 1.0f) > 0.0f &&
                       fabsf(l->n.x) < 1e-4f && cc.x > 1.0f && cc.x < 4.0f;
        }
        CHECK(fabs(area / (PI * 3.0) - 1.0) < 1e-3 && outward == (int)s.nlights && s.nlights > 0,
              "cylinder%s: area %.4f (%.4f), %d of %u triangles facing %s", flip ? " flipped" : "", area, PI * 3.0,
              outward, s.nlights, flip ? "in" : "out");
        cdl_scene_free(&s);
    }
}

/* <path value>: a folder relative to the file it is in, searched before
 * the main file's folder (the later <path> first); without it the mesh is
 * not found. */
static void search_paths(void)
{
    char sub[400];
    snprintf(sub, sizeof sub, "%s/meshes", dir);
    mkdir(sub, 0755);
    snprintf(sub, sizeof sub, "%s/other", dir);
    mkdir(sub, 0755);
    write_file("meshes/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
    write_file("other/quad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const char *shape = "<shape type=\"obj\"><string name=\"filename\" value=\"quad.obj\"/></shape>\n";
    char xml[1024];
    cdl_scene s;
    cdl_scene_settings set;
    snprintf(xml, sizeof xml, "<scene version=\"3.0.0\">\n" LIGHT "%s</scene>\n", shape);
    write_file("nopath.xml", xml);
    int rc = load("nopath.xml", &s, &set);
    CHECK(rc != 0, "a mesh in a subfolder without <path> is not found");
    cdl_scene_free(&s); /* loaded in part */
    snprintf(xml, sizeof xml,
             "<scene version=\"3.0.0\">\n<path value=\"other\"/>\n<path value=\"meshes\"/>\n" LIGHT "%s</scene>\n",
             shape);
    write_file("path.xml", xml);
    if (load("path.xml", &s, &set)) {
        CHECK(0, "<path> finds the mesh");
        return;
    }
    CHECK(s.ntris == 2, "the later <path> is searched first: %u triangles (meshes/quad.obj has 2)", s.ntris);
    cdl_scene_free(&s);
}

/* Each texel of an 8 x 4 map is seen in Mitsuba's direction for it:
 * local d = (sin phi sin theta, cos theta, -cos phi sin theta) with
 * phi = 2 pi u, theta = pi v, turned by to_world, where Mitsuba puts the
 * texel's node: u = (x + 1/2) / 8, v = y / 3 (the rows from pole to pole);
 * halfway between two nodes of a row is their mean. */
static void envmap_orientation(void)
{
    cdl_image img;
    cdl_error err;
    die_on(cdl_image_alloc(&img, 8, 4, &err), &err);
    for (int i = 0; i < 32; i++)
        for (int c = 0; c < 3; c++)
            img.rgb[3 * i + c] = (float)(i + 1);
    char path[512];
    snprintf(path, sizeof path, "%s/env.exr", dir);
    die_on(cdl_image_write(path, &img, NULL, 0, 0.0f, &err), &err);
    cdl_image_free(&img);
    write_file("env.xml", "<scene version=\"3.0.0\">\n<emitter type=\"envmap\"><string name=\"filename\" value=\"env.exr\"/>"
                          "<float name=\"scale\" value=\"2\"/><transform name=\"to_world\">"
                          "<rotate x=\"1\" angle=\"90\"/></transform></emitter>\n"
                          "<shape type=\"rectangle\"/>\n</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("env.xml", &s, &set) || !s.envmap) {
        CHECK(0, "env.xml loads with a map");
        return;
    }
    cdl_mat4 rot;
    cdl_mat4_rotate(90.0, 1, 0, 0, &rot);
    int good = 0, mid = 0;
    for (int y = 1; y < 3; y++) /* rows 0 and 3 are the poles: one direction each */
        for (int x = 0; x < 8; x++)
            for (int half = 0; half < 2; half++) {
                double phi = 2.0 * PI * (x + 0.5 + 0.5 * half) / 8.0, th = PI * y / 3.0;
                cdl_vec3 d = cdl_v3((float)(sin(phi) * sin(th)), (float)cos(th), (float)(-cos(phi) * sin(th)));
                cdl_vec3 L = cdl_envmap_eval(s.envmap, cdl_mat4_vector3(&rot, d));
                float want = 2.0f * (float)(y * 8 + x + 1) + (half ? (x == 7 ? -7.0f : 1.0f) : 0.0f);
                if (half)
                    mid += fabsf(L.x - want) < 1e-3f;
                else
                    good += fabsf(L.x - want) < 1e-3f;
            }
    CHECK(good == 16 && mid == 16 && s.envmap->layout == CDL_ENVMAP_MITSUBA,
          "envmap: %d of 16 texels seen in Mitsuba's direction (turned by to_world), scaled by 2, and %d of 16 "
          "midpoints the mean of their two texels",
          good, mid);
    cdl_scene_free(&s);
}

/* Mitsuba's daylight emitters: the sun where sunDirection puts it in Mitsuba
 * 0.6's y-up frame and in Mitsuba 3's z-up one, nothing below the horizon,
 * "sky" and "sun" merged into one environment light equal to "sunsky", and
 * a sun of radius 0 as a distant light. */
static void sunsky(void)
{
    const char *v06 = "<scene version=\"0.6.0\">\n<shape type=\"rectangle\"/>\n";
    char text[2048];
    snprintf(text, sizeof text,
             "%s<emitter type=\"sunsky\"><vector name=\"sunDirection\" x=\"1\" y=\"1\" z=\"0\"/>"
             "<integer name=\"resolution\" value=\"256\"/></emitter>\n</scene>\n",
             v06);
    write_file("sunsky06.xml", text);
    snprintf(text, sizeof text,
             "%s<emitter type=\"sky\"><vector name=\"sunDirection\" x=\"1\" y=\"1\" z=\"0\"/>"
             "<integer name=\"resolution\" value=\"256\"/></emitter>\n"
             "<emitter type=\"sun\"><vector name=\"sunDirection\" x=\"1\" y=\"1\" z=\"0\"/>"
             "<integer name=\"resolution\" value=\"256\"/></emitter>\n</scene>\n",
             v06);
    write_file("skysun06.xml", text);
    snprintf(text, sizeof text,
             "%s<emitter type=\"sunsky\"><vector name=\"sunDirection\" x=\"1\" y=\"1\" z=\"0\"/>"
             "<float name=\"sunRadiusScale\" value=\"0\"/></emitter>\n</scene>\n",
             v06);
    write_file("sundir06.xml", text);
    write_file("sunsky3.xml", "<scene version=\"3.0.0\">\n<shape type=\"rectangle\"/>\n<emitter type=\"sunsky\">"
                              "<vector name=\"sun_direction\" x=\"0\" y=\"1\" z=\"1\"/></emitter>\n</scene>\n");
    cdl_scene s, t;
    cdl_scene_settings set;
    const cdl_vec3 sun06 = unit(cdl_v3(1, 1, 0)), sun3 = unit(cdl_v3(0, 1, 1));
    if (!load("sunsky06.xml", &s, &set)) {
        cdl_vec3 at = cdl_envmap_eval(s.envmap, sun06), up = cdl_envmap_eval(s.envmap, cdl_v3(0, 1, 0));
        cdl_vec3 down = cdl_envmap_eval(s.envmap, cdl_v3(0.3f, -0.9f, 0.1f));
        CHECK(s.envmap && at.y > 1e3f * up.y && up.z > up.x && cdl_max3(down) == 0.0f,
              "sunsky (0.6): the sun %g where sunDirection points, the zenith sky (%g, %g, %g), nothing below",
              (double)at.y, (double)up.x, (double)up.y, (double)up.z);
        if (!load("skysun06.xml", &t, &set)) {
            int same = t.envmap && t.envmap->w == s.envmap->w && t.envmap->h == s.envmap->h;
            for (int i = 0; same && i < 3 * s.envmap->w * s.envmap->h; i++)
                same = fabsf(t.envmap->rgb[i] - s.envmap->rgb[i]) <= 1e-5f * fmaxf(1.0f, s.envmap->rgb[i]);
            CHECK(same && t.nlights == s.nlights, "sky + sun (0.6): one environment light, equal to sunsky's");
            cdl_scene_free(&t);
        } else {
            CHECK(0, "skysun06.xml loads");
        }
        if (!load("sundir06.xml", &t, &set)) {
            int distant = -1;
            for (uint32_t i = 0; i < t.nlights; i++)
                if (t.lights[i].type == CDL_LIGHT_DISTANT)
                    distant = (int)i;
            cdl_vec3 at0 = t.envmap ? cdl_envmap_eval(t.envmap, sun06) : cdl_v3(0, 0, 0);
            CHECK(distant >= 0 && near3(t.lights[distant].n, cdl_scale(sun06, -1.0f), 1e-5f) && at0.y < 1.0f,
                  "sunRadiusScale 0: a distant light along -sunDirection, the sky alone in the map (%g there)",
                  (double)at0.y);
            cdl_scene_free(&t);
        } else {
            CHECK(0, "sundir06.xml loads");
        }
        cdl_scene_free(&s);
    } else {
        CHECK(0, "sunsky06.xml loads");
    }
    if (!load("sunsky3.xml", &s, &set)) {
        cdl_vec3 at = cdl_envmap_eval(s.envmap, sun3), up = cdl_envmap_eval(s.envmap, cdl_v3(0, 0, 1));
        cdl_vec3 down = cdl_envmap_eval(s.envmap, cdl_v3(0.1f, 0.3f, -0.9f));
        CHECK(at.y > 1e3f * up.y && up.y > 0.0f && cdl_max3(down) == 0.0f,
              "sunsky (Mitsuba 3, z up): the sun %g along sun_direction, sky %g at +z, nothing at -z", (double)at.y,
              (double)up.y);
        cdl_scene_free(&s);
    } else {
        CHECK(0, "sunsky3.xml loads");
    }
}

/* The shared scenes: load, and the Veach scenes' cameras equal their
 * pbrt-v3 twins'. */
static void shared_scenes(const char *root)
{
    static const char *const twins[] = {"veach-mis", "veach-bidir"};
    for (int i = 0; i < 2; i++) {
        char mp[600], pp[600];
        snprintf(mp, sizeof mp, "%s/%s/mitsuba3/scene.xml", root, twins[i]);
        snprintf(pp, sizeof pp, "%s/%s/pbrt-v3/scene.pbrt", root, twins[i]);
        if (access(mp, R_OK) || access(pp, R_OK)) {
            printf("skip: %s (not in %s)\n", twins[i], root);
            continue;
        }
        cdl_scene a, b;
        cdl_scene_settings sa, sb;
        if (load_path(mp, &a, &sa)) {
            CHECK(0, "%s loads", mp);
            continue;
        }
        if (load_path(pp, &b, &sb)) {
            CHECK(0, "%s loads", pp);
            cdl_scene_free(&a);
            continue;
        }
        CHECK(near3(sa.eye, sb.eye, 1e-4f) && near3(unit(sa.fwd), unit(sb.fwd), 1e-5f) &&
                  near3(unit(sa.up), unit(sb.up), 1e-5f) && near3(unit(sa.right), unit(sb.right), 1e-5f) &&
                  fabsf(sa.fov - sb.fov) < 1e-3f && sa.width == sb.width && sa.height == sb.height,
              "%s: Mitsuba camera = pbrt-v3 camera (fov %.4f vs %.4f, %dx%d)", twins[i], (double)sa.fov,
              (double)sb.fov, sa.width, sa.height);
        CHECK(sa.maxdepth == sb.maxdepth - 1, "%s: max_depth %d (Mitsuba) = maxdepth %d bounces; pbrt's file says %d",
              twins[i], sa.maxdepth + 1, sa.maxdepth, sb.maxdepth);
        CHECK(a.nlights == b.nlights, "%s: %u lights (pbrt twin %u)", twins[i], a.nlights, b.nlights);
        CHECK(fabsf(a.bmin.x - b.bmin.x) < 1e-3f && fabsf(a.bmax.y - b.bmax.y) < 1e-3f &&
                  fabsf(a.bmax.z - b.bmax.z) < 1e-3f,
              "%s: same bounds", twins[i]);
        cdl_scene_free(&a);
        cdl_scene_free(&b);
    }
    char sp[600];
    snprintf(sp, sizeof sp, "%s/sponza-dabrovic/mitsuba/sponza.xml", root);
    if (access(sp, R_OK)) {
        printf("skip: sponza (not in %s)\n", root);
        return;
    }
    cdl_scene s;
    cdl_scene_settings set;
    if (load_path(sp, &s, &set)) {
        CHECK(0, "sponza.xml loads");
        return;
    }
    CHECK(s.ntris > 66000 && s.ntexs == 10 && s.nspheres == 1 && set.width == 768 && set.height == 575,
          "sponza: %u triangles from 37 serialized shapes, %u textures, the sphere light, film %dx%d", s.ntris,
          s.ntexs, set.width, set.height);
    cdl_scene_free(&s);
}


/* Mitsuba textures (issue 27): a checkerboard alpha_u with to_uv, a-C, a
 * bitmap's wrap, filter and to_uv, bumpmap and normalmap over a nested
 * bsdf, and the rectangle's uv in candela's convention. */
static void textures_and_maps(void)
{
    write_file("maps.xml",
               "<scene version=\"3.0.0\">\n" LIGHT
               "<shape type=\"rectangle\"><bsdf type=\"roughconductor\"><string name=\"material\" value=\"a-C\"/>"
               "<texture name=\"alpha_u\" type=\"checkerboard\"><transform name=\"to_uv\"><scale x=\"25\" y=\"25\"/>"
               "</transform><float name=\"color0\" value=\"0.05\"/><float name=\"color1\" value=\"0.3\"/></texture>"
               "<float name=\"alpha_v\" value=\"0.2\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"bumpmap\"><float name=\"scale\" value=\"0.02\"/>"
               "<texture name=\"h\" type=\"bitmap\"><boolean name=\"raw\" value=\"true\"/>"
               "<string name=\"filename\" value=\"px.png\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"normalmap\"><texture name=\"normalmap\" type=\"rawconstant\">"
               "<vector name=\"value\" value=\"0.5, 0.5, 1.0\"/></texture><bsdf type=\"diffuse\"/></bsdf></shape>\n"
               "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><texture type=\"bitmap\" name=\"reflectance\">"
               "<transform name=\"to_uv\"><scale value=\"2\"/><translate value=\"-.5,-.5, 0\"/></transform>"
               "<string name=\"filename\" value=\"px.png\"/><string name=\"wrap_mode\" value=\"mirror\"/>"
               "<string name=\"filter_type\" value=\"nearest\"/></texture></bsdf></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    if (load("maps.xml", &s, &set)) {
        CHECK(0, "maps.xml loads");
        return;
    }
    const cdl_material *cond = &s.mats[s.tri_mat[0]], *bump = &s.mats[s.tri_mat[2]], *nm = &s.mats[s.tri_mat[4]],
                       *bm = &s.mats[s.tri_mat[6]];
    int at = cond->maps.alpha_tex[0];
    CHECK(at >= 0 && s.texs[at].type == CDL_TEX_CHECKER && cond->maps.alpha_tex[1] < 0 &&
              fabsf(cond->alpha_y - 0.2f) < 1e-6f && fabsf(s.texs[at].m[0] - 25.0f) < 1e-5f,
          "alpha_u is a checkerboard with to_uv scale 25, alpha_v the float 0.2");
    CHECK(near3(cond->eta3, cdl_v3(2.943f, 2.228f, 1.965f), 2e-3f) && near3(cond->k3, cdl_v3(0.887f, 0.799f, 0.814f), 2e-3f),
          "a-C: eta (%.3f %.3f %.3f), k (%.3f %.3f %.3f)", (double)cond->eta3.x, (double)cond->eta3.y,
          (double)cond->eta3.z, (double)cond->k3.x, (double)cond->k3.y, (double)cond->k3.z);
    int bt = bump->maps.bump_tex;
    CHECK(bump->type == CDL_MAT_DIFFUSE && bt >= 0 && s.texs[bt].type == CDL_TEX_BITMAP &&
              fabsf(s.texs[bt].rgb[0] - 0.537f) < 0.003f && fabsf(bump->maps.bump_scale - 0.02f) < 1e-7f,
          "bumpmap: diffuse with a raw bitmap (texel %g: the file's sRGB 0.537 of 0.25, undecoded) and scale 0.02",
          bt >= 0 ? (double)s.texs[bt].rgb[0] : -1.0);
    int nt = nm->maps.normal_tex;
    CHECK(nt >= 0 && s.texs[nt].type == CDL_TEX_CONST && near3(s.texs[nt].a, cdl_v3(0.5f, 0.5f, 1.0f), 0.0f),
          "normalmap: the rawconstant (0.5, 0.5, 1)");
    int kt = bm->kd_tex;
    CHECK(kt >= 0 && s.texs[kt].wrap == CDL_WRAP_MIRROR && s.texs[kt].nearest && fabsf(s.texs[kt].m[0] - 2.0f) < 1e-6f &&
              fabsf(s.texs[kt].m[2] + 0.5f) < 1e-6f && fabsf(s.texs[kt].m[4] + 2.0f) < 1e-6f &&
              fabsf(s.texs[kt].m[5] - 1.5f) < 1e-6f,
          "bitmap: mirror, nearest, to_uv (2 u - 0.5, 2 (1 - v) - 0.5)");
    const float *uv0 = s.uv + 2 * (size_t)s.idx[0];
    CHECK(uv0[0] == 0.0f && uv0[1] == 1.0f, "rectangle corner (-1, -1): candela uv (%g, %g), Mitsuba's (0, 0) flipped",
          (double)uv0[0], (double)uv0[1]);
    cdl_scene_free(&s);
}

/* Issue 27: film filters (Mitsuba's default gaussian when the film names
 * none), the orthographic sensor's frame and extent, Mitsuba's spot
 * (linear falloff, its cone) and projector (pi scale irradiance, the
 * texture's aspect), and emitters chosen uniformly, a mesh as one. */
static void sensors_and_emitters(void)
{
    static const unsigned char ppm[] = {'P', '6', '\n', '2', ' ', '1', '\n', '2', '5', '5', '\n', 255, 0, 0, 0, 255, 0};
    test_write(dir, "tex2x1.ppm", ppm, sizeof ppm);
    write_file("filters.xml",
               "<scene version=\"3.0.0\">\n"
               "  <sensor type=\"orthographic\"><float name=\"near_clip\" value=\"0.5\"/>\n"
               "    <transform name=\"to_world\"><scale x=\"1.5\" y=\"1.5\"/>\n"
               "      <lookat origin=\"-5, 0, 3\" target=\"0, 0, 1\" up=\"0, 0, 1\"/></transform>\n"
               "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"20\"/>"
               "<integer name=\"height\" value=\"10\"/></film></sensor>\n"
               "  <emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"30\"/>"
               "<float name=\"beam_width\" value=\"10\"/></emitter>\n"
               "  <emitter type=\"projector\"><float name=\"fov\" value=\"90\"/>"
               "<float name=\"scale\" value=\"2\"/>\n"
               "    <texture type=\"bitmap\" name=\"irradiance\"><string name=\"filename\" value=\"tex2x1.ppm\"/>"
               "</texture></emitter>\n"
               "  <shape type=\"rectangle\"><emitter type=\"area\"/></shape>\n"
               "  <shape type=\"cube\"><emitter type=\"area\"/></shape>\n"
               "</scene>\n");
    cdl_scene s;
    cdl_scene_settings set;
    cdl_scene_settings_init(&set);
    int rc = load("filters.xml", &s, &set);
    CHECK(rc == 0, "orthographic sensor, spot, projector load");
    if (rc)
        return;
    CHECK(set.has_filter && set.filter.type == CDL_FILTER_GAUSSIAN && fabsf(set.filter.radius[0] - 2.0f) < 1e-6f &&
              fabsf(set.filter.p0 - 2.0f) < 1e-6f && set.filter.clip,
          "a film without rfilter: Mitsuba's gaussian, stddev 0.5, radius 2");
    CHECK(set.has_camera && set.ortho && set.ortho_near == 0.5f && set.width == 20 && set.height == 10,
          "orthographic sensor: near clip and film");
    CHECK(fabsf(cdl_length(set.right) - 1.5f) < 1e-5f && fabsf(cdl_length(set.up) - 1.5f) < 1e-5f &&
              near3(unit(set.fwd), unit(cdl_v3(5, 0, -2)), 1e-5f),
          "orthographic frame keeps the scale 1.5 and looks at the target");
    int spot = -1, proj = -1, ntri = 0;
    for (uint32_t i = 0; i < s.nlights; i++) {
        spot = s.lights[i].type == CDL_LIGHT_SPOT ? (int)i : spot;
        proj = s.lights[i].type == CDL_LIGHT_PROJECTOR ? (int)i : proj;
        ntri += s.lights[i].type == CDL_LIGHT_TRIANGLE;
    }
    CHECK(spot >= 0 && s.lights[spot].spot_linear && fabsf(s.lights[spot].cutoff - (float)(PI / 6.0)) < 1e-6f &&
              fabsf(s.lights[spot].beam - (float)(PI / 18.0)) < 1e-6f,
          "spot: Mitsuba's linear falloff from 10 to 30 degrees");
    /* texture 2 x 1: tan_y = tan_x / 2; L = pi scale */
    CHECK(proj >= 0 && fabsf(s.lights[proj].tan_x - 1.0f) < 1e-5f && fabsf(s.lights[proj].tan_y - 0.5f) < 1e-5f &&
              fabsf(s.lights[proj].L.x - 2.0f * (float)PI) < 1e-4f && s.lights[proj].tex,
          "projector: fov 90 along x, the texture's aspect, pi scale");
    /* uniform over 4 emitters: the rectangle's 2 and the cube's 12 triangles share theirs by area */
    double prect = 0.0, pcube = 0.0;
    for (uint32_t i = 0; i < s.nlights; i++)
        if (s.lights[i].type == CDL_LIGHT_TRIANGLE)
            *(s.lights[i].area < 2.5f && ntri == 14 && s.tri_emit[s.lights[i].prim] == s.tri_emit[s.lights[0].prim]
                  ? &prect
                  : &pcube) += s.light_select.pmf[i];
    CHECK(fabs(s.light_select.pmf[spot] - 0.25) < 1e-6 && fabs(s.light_select.pmf[proj] - 0.25) < 1e-6 &&
              fabs(prect + pcube - 0.5) < 1e-5,
          "emitters chosen uniformly (spot %g, projector %g, meshes %g)", s.light_select.pmf[spot],
          s.light_select.pmf[proj], prect + pcube);
    cdl_scene_free(&s);
    write_file("rfilters.xml",
               "<scene version=\"3.0.0\"><sensor type=\"perspective\"><film type=\"hdrfilm\">"
               "<rfilter type=\"lanczos\"><integer name=\"lobes\" value=\"2\"/></rfilter></film></sensor>\n"
               "<shape type=\"rectangle\"><emitter type=\"area\"/></shape></scene>\n");
    cdl_scene_settings_init(&set);
    rc = load("rfilters.xml", &s, &set);
    CHECK(rc == 0 && set.filter.type == CDL_FILTER_LANCZOS && set.filter.radius[0] == 2.0f && set.filter.p0 == 2.0f,
          "rfilter lanczos with 2 lobes");
    if (!rc)
        cdl_scene_free(&s);
    write_file("rfilterbox.xml",
               "<scene version=\"3.0.0\"><sensor type=\"perspective\"><film type=\"hdrfilm\">"
               "<rfilter type=\"box\"/></film></sensor>\n"
               "<shape type=\"rectangle\"><emitter type=\"area\"/></shape></scene>\n");
    cdl_scene_settings_init(&set);
    rc = load("rfilterbox.xml", &s, &set);
    CHECK(rc == 0 && set.filter.type == CDL_FILTER_BOX && !set.filter.wide, "rfilter box: the one-pixel box");
    if (!rc)
        cdl_scene_free(&s);
}

int main(int argc, char **argv)
{
    snprintf(dir, sizeof dir, "/tmp/candela-mitsuba.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    camera_and_transforms();
    materials_and_include();
    mask_and_plastic();
    obj_uvs();
    search_paths();
    spectra();
    cylinder();
    nested_ids();
    textures_and_maps();
    instancing();
    envmap_orientation();
    sunsky();
    sensors_and_emitters();
    if (argc > 1)
        shared_scenes(argv[1]);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
