/* Mitsuba reader on what published scene files do that the first tests did
 * not (issue 27, scenes not seen before): an area emitter declared at the
 * top level and referred to from shapes before or after it, a <ref> to an
 * element candela skips (a medium), Mitsuba 0.3's <lookAt> spelling, and
 * wavelength spectra longer than 64 samples.
 *
 *   test_mitsuba_refs */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/log.h"
#include "io/loader.h"
#include "io/settings.h"
#include "test_util.h"

static char dir[200];
static int warnings;

static void count_warning(void *user, const char *file, int line, const char *msg)
{
    (void)file;
    (void)msg;
    warnings += user == NULL || line == *(const int *)user;
}

/* Loads text as dir/name; counts warnings (at line *at when given). */
static int load(const char *name, const char *text, cdl_scene *s, const int *at)
{
    char path[512];
    test_write(dir, name, text, strlen(text));
    snprintf(path, sizeof path, "%s/%s", dir, name);
    cdl_scene_settings set;
    cdl_scene_settings_init(&set);
    cdl_error err;
    warnings = 0;
    const cdl_log_sink sink = {count_warning, (void *)at, 0};
    const cdl_log_sink *prev = cdl_log_push(&sink);
    int rc = cdl_scene_init(s, path, &err);
    if (!rc)
        rc = cdl_scene_load(s, path, &set, &err);
    if (!rc)
        rc = cdl_scene_commit(s, &err);
    cdl_log_pop(prev);
    if (rc) {
        char buf[1024];
        cdl_error_format(&err, buf, sizeof buf);
        printf("      load %s: %s\n", name, buf);
    }
    return rc;
}

#define RECT(ref) "<shape type=\"rectangle\">" ref "</shape>\n"

/* Mitsuba 3's mitsuba-data docs scenes declare the area emitter after the
 * shape that refers to it; cbox-rgb.xml before. Both shapes emit, at the
 * emitter's radiance; an area emitter no shape refers to warns. */
static void referenced_area_emitters(void)
{
    cdl_scene s;
    int rc = load("area.xml",
                  "<scene version=\"3.0.0\">\n"
                  "<emitter type=\"area\" id=\"before\"><rgb name=\"radiance\" value=\"1, 2, 3\"/></emitter>\n"
                  "<bsdf type=\"twosided\" id=\"white\"><bsdf type=\"diffuse\"/></bsdf>\n" RECT("<ref id=\"white\"/><ref id=\"before\"/>")
                      RECT("<ref id=\"after\"/><ref id=\"white\"/>")
                  "<emitter type=\"area\" id=\"after\"><rgb name=\"radiance\" value=\"4, 5, 6\"/></emitter>\n"
                  "</scene>\n",
                  &s, NULL);
    CHECK(!rc && s.nemitters == 2 && warnings == 0, "two shapes refer to area emitters declared before and after: "
                                                  "%u emitters, %d warnings", rc ? 0 : s.nemitters, warnings);
    if (!rc) {
        int seen = 0;
        for (uint32_t i = 0; i < s.nemitters; i++) {
            cdl_vec3 L = s.emitters[i].L;
            seen |= (fabsf(L.x - 1) < 1e-6f && fabsf(L.z - 3) < 1e-6f) ? 1 : 0;
            seen |= (fabsf(L.x - 4) < 1e-6f && fabsf(L.z - 6) < 1e-6f) ? 2 : 0;
        }
        CHECK(seen == 3, "both radiances (1 2 3) and (4 5 6) are emitted (seen mask %d)", seen);
        cdl_scene_free(&s);
    }
    int line = 2;
    rc = load("area_unused.xml",
              "<scene version=\"3.0.0\">\n"
              "<emitter type=\"area\" id=\"lonely\"><rgb name=\"radiance\" value=\"1\"/></emitter>\n" RECT("")
              "<emitter type=\"point\"/>\n</scene>\n",
              &s, &line);
    CHECK(!rc && warnings == 1 && s.nlights == 1, "an area emitter no shape refers to warns at its line (%d)",
          warnings);
    if (!rc)
        cdl_scene_free(&s);
}

/* Mitsuba's opaque bsdfs are one-sided unless wrapped in twosided (so is
 * its default bsdf); a twosided wrapper around a <ref> to a one-sided bsdf
 * gets a two-sided copy, the original stays one-sided. */
static int material_named(const cdl_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->nmats; i++)
        if (!strcmp(s->mats[i].name, name))
            return (int)i;
    return -1;
}

static void one_sided_bsdfs(void)
{
    cdl_scene s;
    int rc = load("sides.xml",
                  "<scene version=\"3.0.0\">\n"
                  "<bsdf type=\"twosided\" id=\"a\"><bsdf type=\"diffuse\" id=\"a_in\"/></bsdf>\n"
                  "<bsdf type=\"roughconductor\" id=\"b\"/>\n"
                  "<bsdf type=\"diffuse\" id=\"c\"/>\n"
                  "<bsdf type=\"twosided\" id=\"d\"><ref id=\"c\"/></bsdf>\n" RECT("<ref id=\"d\"/>")
                  RECT("<ref id=\"b\"/>") RECT("")
                  "<emitter type=\"point\"/>\n</scene>\n",
                  &s, NULL);
    if (rc)
        return;
    int a = material_named(&s, "a_in"), b = material_named(&s, "b"), c = material_named(&s, "c");
    int dflt = material_named(&s, "mitsuba-default");
    int two = -1; /* d: c's two-sided copy, the shape's material */
    for (uint32_t i = 0; i < s.nmats; i++)
        two = s.mats[i].one_sided == 0 && s.mats[i].type == CDL_MAT_DIFFUSE && (int)i != a ? (int)i : two;
    CHECK(a >= 0 && b >= 0 && c >= 0 && dflt >= 0 && two >= 0 && !s.mats[a].one_sided && s.mats[b].one_sided &&
              s.mats[c].one_sided && s.mats[dflt].one_sided && warnings == 0,
          "one-sided: bare diffuse and conductor and the default bsdf; two-sided: inside twosided and the copy a "
          "twosided <ref> makes (%d %d %d %d %d, %d warnings)",
          a, b, c, dflt, two, warnings);
    cdl_scene_free(&s);
}

/* Mitsuba 0.6's test_bidir_2.xml: a medium (skipped) referred to from
 * shapes: the references are skipped with a warning at their lines, not
 * an error; a <ref> to an id that is nowhere stays an error. */
static void references_to_skipped_elements(void)
{
    cdl_scene s;
    int line = 4;
    int rc = load("medium.xml",
                  "<scene version=\"0.4.0\">\n"
                  "<medium id=\"m\" type=\"homogeneous\"/>\n"
                  "<emitter type=\"point\"/>\n"
                  "<shape type=\"disk\"><ref id=\"m\" name=\"exterior\"/></shape>\n"
                  "</scene>\n",
                  &s, &line);
    CHECK(!rc && warnings == 1 && s.ntris > 0, "a shape's <ref> to a skipped medium warns at its line (%d "
                                               "warnings) and the shape is there",
          warnings);
    if (!rc)
        cdl_scene_free(&s);
    rc = load("nowhere.xml",
              "<scene version=\"3.0.0\">\n<shape type=\"disk\"><ref id=\"nowhere\"/></shape>\n</scene>\n", &s,
              NULL);
    CHECK(rc != 0, "a <ref> to an id declared nowhere is an error");
}

/* <lookAt> (Mitsuba 0.3's spelling, in Mitsuba's own test_bidir_1.xml)
 * places the sensor as <lookat> does. */
static void lookat_spelling(void)
{
    static const char *fmt = "<scene version=\"0.5.0\">\n<sensor type=\"perspective\"><transform name=\"toWorld\">"
                             "<%s origin=\"1, 2, 3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>\n"
                             "<emitter type=\"point\"/><shape type=\"rectangle\"/>\n</scene>\n";
    char text[512], path[512];
    cdl_scene_settings a, b;
    cdl_error err;
    cdl_scene s;
    cdl_scene_settings *set[2] = {&a, &b};
    const char *tag[2] = {"lookat", "lookAt"};
    int ok = 1;
    for (int i = 0; i < 2; i++) {
        snprintf(text, sizeof text, fmt, tag[i]);
        test_write(dir, "look.xml", text, strlen(text));
        snprintf(path, sizeof path, "%s/look.xml", dir);
        cdl_scene_settings_init(set[i]);
        int rc = cdl_scene_init(&s, path, &err);
        if (!rc)
            rc = cdl_scene_load(&s, path, set[i], &err);
        ok &= rc == 0;
        if (!rc)
            cdl_scene_free(&s);
    }
    CHECK(ok && a.has_camera && b.has_camera && fabsf(b.eye.x - 1) < 1e-6f && fabsf(b.eye.z - 3) < 1e-6f &&
              !memcmp(&a.eye, &b.eye, sizeof a.eye) && !memcmp(&a.fwd, &b.fwd, sizeof a.fwd) &&
              !memcmp(&a.up, &b.up, sizeof a.up) && !memcmp(&a.right, &b.right, sizeof a.right),
          "<lookAt> loads and places the camera as <lookat>");
}

/* mitsuba-data's integrator_depth_*.xml give 76 wavelengths a spectrum; a
 * constant one over 200 samples is still grey 0.5. */
static void long_spectra(void)
{
    char text[8192];
    int k = snprintf(text, sizeof text, "<scene version=\"2.0.0\">\n<emitter type=\"point\"/>\n"
                                        "<shape type=\"rectangle\"><bsdf type=\"diffuse\"><spectrum "
                                        "name=\"reflectance\" value=\"");
    for (int i = 0; i < 200; i++)
        k += snprintf(text + k, sizeof text - (size_t)k, "%s%d:0.5", i ? ", " : "", 380 + 2 * i);
    snprintf(text + k, sizeof text - (size_t)k, "\"/></bsdf></shape>\n</scene>\n");
    cdl_scene s;
    int rc = load("long.xml", text, &s, NULL);
    cdl_vec3 kd = rc ? cdl_v3(0, 0, 0) : s.mats[s.tri_mat[0]].kd;
    CHECK(!rc && fabsf(kd.x - 0.5f) < 2e-3f && fabsf(kd.y - 0.5f) < 2e-3f && fabsf(kd.z - 0.5f) < 2e-3f,
          "a 200-sample constant spectrum loads as grey 0.5: (%g %g %g)", (double)kd.x, (double)kd.y,
          (double)kd.z);
    if (!rc)
        cdl_scene_free(&s);
}

int main(void)
{
    snprintf(dir, sizeof dir, "/tmp/candela-mitsuba-refs.XXXXXX");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    referenced_area_emitters();
    references_to_skipped_elements();
    one_sided_bsdfs();
    lookat_spelling();
    long_spectra();
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {
    }
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
