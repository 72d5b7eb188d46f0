/* pbrt reader, textures: checkerboard cells found by rays (uscale,
 * udelta, negative cells, pbrt's default uv), a float checkerboard as
 * roughness, imagemap mapping, v flip, decodings, wraps, invert and float
 * images (v3 and v4), scale and mix of textures, bump maps (pbrt-v3's
 * frame on meshes with vertex normals), v4's normal map and tessellated
 * textured spheres.
 *
 *   test_pbrt_textures
 *
 * Writes small .pbrt files and images into a fresh temporary directory. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "film/image.h"
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

static int near3(cdl_vec3 a, cdl_vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

#define V3(v) (double)(v).x, (double)(v).y, (double)(v).z

static const char *LIGHT = "LightSource \"point\" \"rgb I\" [1 1 1] \"point from\" [0 0 10]\n";

/* pbrt-v3's RoughnessToAlpha */
static float v3_alpha(float r)
{
    float x = logf(r);
    return 1.62142f + 0.819955f * x + 0.1734f * x * x + 0.0171201f * x * x * x + 0.000640711f * x * x * x * x;
}

/* The unit quad of the xy plane at x offset dx, uv = (x - dx, y), facing
 * +z; with vertex normals when vn. */
static int quad(char *out, size_t n, float dx, int vn)
{
    return snprintf(out, n,
                    "Shape \"trianglemesh\" \"integer indices\" [0 1 2 0 2 3] \"point P\" [%g 0 0  %g 0 0  %g 1 0  %g 1 0] "
                    "\"point2 uv\" [0 0 1 0 1 1 0 1]%s\n",
                    (double)dx, (double)dx + 1.0, (double)dx + 1.0, (double)dx,
                    vn ? " \"normal N\" [0 0 1 0 0 1 0 0 1 0 0 1]" : "");
}

/* The surface and BSDF seen straight down at (x, y). */
static int look(const cdl_scene *s, float x, float y, cdl_surface *sf, cdl_bsdf *b)
{
    cdl_hit h;
    if (!cdl_intersect(s, cdl_v3(x, y, 5.0f), cdl_v3(0, 0, -1), 100.0f, &h))
        return 0;
    cdl_surface_at(s, &h, sf);
    cdl_scene_bsdf(s, sf, b);
    return 1;
}

/* A PNG of 8-bit values (r g b per pixel, top row first). */
static void write_png(const char *name, int w, int h, const unsigned char *bytes)
{
    float px[3 * 16];
    for (int i = 0; i < 3 * w * h; i++)
        px[i] = cdl_srgb_decode((float)bytes[i] / 255.0f); /* the writer encodes it back */
    cdl_image img = {w, h, px};
    char path[512];
    cdl_error err;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    die_on(cdl_image_write(path, &img, NULL, 0, 0.0f, &err), &err);
}

static float srgb(int byte) { return cdl_srgb_decode((float)byte / 255.0f); }

/* Checkerboards on quads: pbrt's cells of (2u + du, 2v), tex1 where
 * floor(s) + floor(t) is even (negative cells too), found by rays; a float
 * checkerboard as textured roughness, remapped as pbrt-v3 does. */
static void test_checkerboard(void)
{
    char text[4096];
    int n = snprintf(text, sizeof text, "WorldBegin\n%s", LIGHT);
    static const char *const du[3] = {"0", "0.5", "-0.5"};
    for (int i = 0; i < 3; i++) {
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "Texture \"c%d\" \"spectrum\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                      "\"float udelta\" [%s] \"rgb tex1\" [0.8 0.1 0.1] \"rgb tex2\" [0.1 0.1 0.8]\n"
                      "Material \"matte\" \"texture Kd\" \"c%d\"\n",
                      i, du[i], i);
        n += quad(text + n, sizeof text - (size_t)n, 2.0f * (float)i, 0);
    }
    n += snprintf(text + n, sizeof text - (size_t)n,
                  "Texture \"r\" \"float\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                  "\"float tex1\" [0.01] \"float tex2\" [0.5]\nMaterial \"metal\" \"texture roughness\" \"r\"\n");
    n += quad(text + n, sizeof text - (size_t)n, 6.0f, 0);
    /* without uv: a triangle has pbrt's (0,0) (1,0) (1,1) at its corners,
     * here (u, v) = (x - 8, y); a bilinear patch (u, v) = (x - 10, y) */
    snprintf(text + n, sizeof text - (size_t)n,
             "Material \"matte\" \"texture Kd\" \"c0\"\n"
             "Shape \"trianglemesh\" \"integer indices\" [0 1 2] \"point P\" [8 0 0  9 0 0  9 1 0]\n"
             "Shape \"bilinearmesh\" \"point3 P\" [10 0 0  11 0 0  10 1 0  11 1 0]\n");
    write_file("checks.pbrt", text);
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    if (load("checks.pbrt", &s, &set, &err)) {
        CHECK(0, "checks.pbrt loads");
        return;
    }
    static const struct {
        float x, y;
        int first;
    } at[] = {{0.1f, 0.1f, 1}, {0.6f, 0.1f, 0}, {0.6f, 0.6f, 1}, {0.1f, 0.6f, 0}, {0.3f, 0.1f, 1},
              /* udelta 0.5 */ {2.1f, 0.1f, 1}, {2.3f, 0.1f, 0},
              /* udelta -0.5: s = -0.3 is cell -1 */ {4.1f, 0.1f, 0}, {4.3f, 0.1f, 1},
              /* no uv */ {8.3f, 0.1f, 1}, {8.6f, 0.1f, 0}, {8.9f, 0.6f, 1},
              /* a bilinear patch's own (u, v) */ {10.1f, 0.6f, 0}, {10.7f, 0.6f, 1}, {10.3f, 0.1f, 1}};
    int bad = 0;
    for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
        cdl_surface sf;
        cdl_bsdf b;
        cdl_vec3 want = at[i].first ? cdl_v3(0.8f, 0.1f, 0.1f) : cdl_v3(0.1f, 0.1f, 0.8f);
        if (!look(&s, at[i].x, at[i].y, &sf, &b) || !near3(b.kd, want, 1e-6f)) {
            printf("      at (%g, %g): kd (%g %g %g), want tex%d\n", (double)at[i].x, (double)at[i].y, V3(b.kd),
                   at[i].first ? 1 : 2);
            bad++;
        }
    }
    CHECK(bad == 0, "checkerboard: tex1/tex2 in pbrt's cells at %zu points (uscale 2, udelta 0, 0.5, -0.5, default uv)",
          sizeof at / sizeof at[0]);
    cdl_surface sf;
    cdl_bsdf b1, b2;
    int hit = look(&s, 6.1f, 0.1f, &sf, &b1) && look(&s, 6.6f, 0.1f, &sf, &b2);
    CHECK(hit && fabsf(b1.ax - v3_alpha(0.01f)) < 1e-5f && fabsf(b2.ax - v3_alpha(0.5f)) < 1e-5f &&
              b1.ay == b1.ax,
          "float checkerboard roughness: alpha %g (v3 of 0.01: %g), %g (v3 of 0.5: %g)", (double)b1.ax,
          (double)v3_alpha(0.01f), (double)b2.ax, (double)v3_alpha(0.5f));
    cdl_scene_free(&s);
}

/* imagemap: (s, t) = (su u + du, sv v + dv) looked up at (s, 1 - t); wrap;
 * sRGB, linear and gamma decoding of 8-bit values; v4's invert; a float
 * image as pbrt-v3 (luminance, then decoded) and v4 (first channel) read
 * it; scale and mix of textures. */
static void test_imagemap(void)
{
    /* 2 x 2: top (255 0 0) (0 128 0), bottom (0 0 64) (128 128 128) */
    static const unsigned char px[12] = {255, 0, 0, 0, 128, 0, 0, 0, 64, 128, 128, 128};
    write_png("img.png", 2, 2, px);
    static const char *const defs[] = {
        "\"string filename\" \"img.png\"",                                                          /* 0 */
        "\"string filename\" \"img.png\" \"float uscale\" [2] \"float udelta\" [0.25] \"float vdelta\" [0.5]",
        "\"string filename\" \"img.png\" \"bool gamma\" \"false\"",                                  /* 2 */
        "\"string filename\" \"img.png\" \"string encoding\" \"gamma 2.2\"",                         /* 3 */
        "\"string filename\" \"img.png\" \"float udelta\" [1]",                                      /* 4 */
        "\"string filename\" \"img.png\" \"float udelta\" [1] \"string wrap\" \"clamp\"",            /* 5 */
        "\"string filename\" \"img.png\" \"float udelta\" [1] \"string wrap\" \"black\"",            /* 6 */
        "\"string filename\" \"img.png\" \"bool invert\" \"true\" \"string encoding\" \"linear\"",   /* 7 */
        "\"string filename\" \"img.png\" \"float scale\" [0.5]",                                     /* 8 */
    };
    enum { NDEF = sizeof defs / sizeof defs[0] };
    char text[8192];
    int n = snprintf(text, sizeof text, "WorldBegin\n%s", LIGHT);
    for (int i = 0; i < NDEF; i++) {
        n += snprintf(text + n, sizeof text - (size_t)n,
                      "Texture \"t%d\" \"spectrum\" \"imagemap\" %s\nMaterial \"matte\" \"texture Kd\" \"t%d\"\n", i,
                      defs[i], i);
        n += quad(text + n, sizeof text - (size_t)n, 2.0f * (float)i, 0);
    }
    /* float images as roughness (alpha = the value: no remapping) */
    n += snprintf(text + n, sizeof text - (size_t)n,
                  "Texture \"f3\" \"float\" \"imagemap\" \"string filename\" \"img.png\"\n"
                  "Texture \"f4\" \"float\" \"imagemap\" \"string filename\" \"img.png\" \"string encoding\" \"sRGB\"\n"
                  "Texture \"half\" \"float\" \"checkerboard\" \"float tex1\" [0.5] \"float tex2\" [2]\n"
                  "Texture \"prod\" \"spectrum\" \"scale\" \"texture tex\" \"t0\" \"texture scale\" \"half\"\n"
                  "Texture \"prod3\" \"spectrum\" \"scale\" \"texture tex1\" \"t0\" \"texture tex2\" \"t2\"\n"
                  "Texture \"mixed\" \"spectrum\" \"mix\" \"texture tex1\" \"t0\" \"rgb tex2\" [0 0 0] "
                  "\"texture amount\" \"half\"\n"
                  "Material \"metal\" \"texture uroughness\" \"f3\" \"texture vroughness\" \"f4\" "
                  "\"bool remaproughness\" \"false\"\n");
    n += quad(text + n, sizeof text - (size_t)n, 2.0f * NDEF, 0);
    static const char *const combos[3] = {"prod", "prod3", "mixed"};
    for (int i = 0; i < 3; i++) {
        n += snprintf(text + n, sizeof text - (size_t)n, "Material \"matte\" \"texture Kd\" \"%s\"\n", combos[i]);
        n += quad(text + n, sizeof text - (size_t)n, 2.0f * (NDEF + 1 + i), 0);
    }
    write_file("img.pbrt", text);
    cdl_scene s;
    cdl_scene_settings set;
    cdl_error err;
    if (load("img.pbrt", &s, &set, &err)) {
        CHECK(0, "img.pbrt loads");
        return;
    }
    /* the texture of quad q at (u, v) */
#define TEX(q, u, v) cdl_texture_eval(s.texs, s.mats[s.tri_mat[2 * (q)]].kd_tex, u, v)
    cdl_vec3 tl = TEX(0, 0.25f, 0.75f), bl = TEX(0, 0.25f, 0.25f), br = TEX(0, 0.75f, 0.25f);
    CHECK(near3(tl, cdl_v3(1, 0, 0), 1e-6f) && near3(bl, cdl_v3(0, 0, srgb(64)), 1e-6f) &&
              near3(br, cdl_v3(srgb(128), srgb(128), srgb(128)), 1e-6f),
          "imagemap at (s, 1 - t): v = 0.75 is the top row (%g %g %g), v = 0.25 the bottom (%g %g %g), sRGB decoded",
          V3(tl), V3(bl));
    cdl_vec3 mv = TEX(1, 0.25f, 0.25f), mv0 = TEX(1, 0.0f, 0.25f);
    CHECK(near3(mv, cdl_v3(0, srgb(128), 0), 1e-6f) && near3(mv0, cdl_v3(1, 0, 0), 1e-6f),
          "uscale 2, udelta 0.25, vdelta 0.5: (0.25, 0.25) looks up the top right texel (%g %g %g), (0, 0.25) the "
          "top left (%g %g %g)",
          V3(mv), V3(mv0));
    float lin = TEX(2, 0.75f, 0.25f).x, gam = TEX(3, 0.75f, 0.25f).x;
    CHECK(fabsf(lin - 128.0f / 255.0f) < 1e-6f && fabsf(gam - powf(128.0f / 255.0f, 2.2f)) < 1e-6f,
          "bool gamma false: %g (128/255), encoding \"gamma 2.2\": %g", (double)lin, (double)gam);
    cdl_vec3 rep = TEX(4, 0.25f, 0.75f), cla = TEX(5, 0.25f, 0.75f), blk = TEX(6, 0.25f, 0.75f);
    CHECK(near3(rep, cdl_v3(1, 0, 0), 1e-6f) && near3(cla, cdl_v3(0, srgb(128), 0), 1e-6f) &&
              near3(blk, cdl_v3(0, 0, 0), 1e-6f),
          "udelta 1 (s = 1.25): repeat (%g %g %g), clamp (%g %g %g), black (%g %g %g)", V3(rep), V3(cla), V3(blk));
    cdl_vec3 inv = TEX(7, 0.75f, 0.75f), sc = TEX(8, 0.25f, 0.75f);
    CHECK(near3(inv, cdl_v3(1, 1.0f - 128.0f / 255.0f, 1), 1e-6f) && near3(sc, cdl_v3(0.5f, 0, 0), 1e-6f),
          "v4 invert with linear encoding: (%g %g %g); scale 0.5: (%g %g %g)", V3(inv), V3(sc));
    const cdl_material *fm = &s.mats[s.tri_mat[2 * NDEF]];
    float f3 = -1.0f, f4 = -1.0f;
    if (fm->maps.on && fm->maps.alpha_tex[0] >= 0 && fm->maps.alpha_tex[1] >= 0) {
        f3 = cdl_texture_eval1(s.texs, fm->maps.alpha_tex[0], 0.25f, 0.75f);
        f4 = cdl_texture_eval1(s.texs, fm->maps.alpha_tex[1], 0.25f, 0.75f);
    }
    float y = cdl_srgb_decode(0.212671f); /* pbrt-v3 y() of (1, 0, 0) */
    CHECK(fabsf(f3 - y) < 1e-6f && fabsf(f4 - 1.0f) < 1e-6f && fm->maps.alpha_remap == CDL_ROUGH_ALPHA,
          "float imagemap of a red texel: v3 decodes its luminance (%g, want %g), v4 its red channel (%g, want 1)",
          (double)f3, (double)y, (double)f4);
    cdl_vec3 p4 = TEX(NDEF + 1, 0.25f, 0.75f), p3 = TEX(NDEF + 2, 0.75f, 0.25f), mx = TEX(NDEF + 3, 0.25f, 0.75f);
    float b128 = srgb(128);
    CHECK(near3(p4, cdl_v3(0.5f, 0, 0), 1e-6f) && near3(p3, cdl_v3(b128 * 128.0f / 255.0f, b128 * 128.0f / 255.0f,
                                                                     b128 * 128.0f / 255.0f), 1e-6f) &&
              near3(mx, cdl_v3(0.5f, 0, 0), 1e-6f),
          "scale: v4 tex x float checker (%g %g %g), v3 image x image (%g %g %g); mix by a float checker (%g %g %g)",
          V3(p4), V3(p3), V3(mx));
#undef TEX
    cdl_scene_free(&s);
}

/* Bump maps: h = 0.05 x texel of an 8-texel ramp along u, gradient 0.4
 * per u. Without vertex normals the normal of z = h tilts by atan(0.4)
 * towards -x (dp/du = (1, 0, 0)); pbrt-v3's meshes with normals displace
 * its unit, reversed frame: atan(0.4) towards +x although dp/du = (2, 0,
 * 0); pbrt-v4's "displacement" keeps its own frame; its normal map is
 * read linear, in the frame of dp/du; a textured sphere is tessellated
 * with pbrt's (u, v). */
static void test_bump(void)
{
    float ramp[8 * 3];
    for (int i = 0; i < 24; i++)
        ramp[i] = 0.1f * (float)(i / 3);
    cdl_image img = {8, 1, ramp};
    char path[512], text[4096];
    cdl_error err;
    snprintf(path, sizeof path, "%s/ramp.pfm", dir);
    die_on(cdl_image_write(path, &img, NULL, 0, 0.0f, &err), &err);
    int n = snprintf(text, sizeof text,
                     "WorldBegin\n%sTexture \"h\" \"float\" \"imagemap\" \"string filename\" \"ramp.pfm\" "
                     "\"float scale\" [0.5]\nMaterial \"matte\" \"texture bumpmap\" \"h\"\n",
                     LIGHT);
    n += quad(text + n, sizeof text - (size_t)n, 0.0f, 0);
    n += snprintf(text + n, sizeof text - (size_t)n, "AttributeBegin\nScale 2 1 1\n");
    n += quad(text + n, sizeof text - (size_t)n, 1.0f, 1);
    n += snprintf(text + n, sizeof text - (size_t)n,
                  "AttributeEnd\nMaterial \"diffuse\" \"texture displacement\" \"h\"\n");
    n += quad(text + n, sizeof text - (size_t)n, 4.0f, 1);
    /* a normal map of (0.5, 0, 0.866) as 8-bit (n + 1) / 2, read linear */
    static const unsigned char nm[3] = {191, 128, 238};
    write_png("nm.png", 1, 1, nm);
    n += snprintf(text + n, sizeof text - (size_t)n, "Material \"diffuse\" \"string normalmap\" \"nm.png\"\n");
    n += quad(text + n, sizeof text - (size_t)n, 6.0f, 0);
    snprintf(text + n, sizeof text - (size_t)n,
             "Texture \"c\" \"spectrum\" \"checkerboard\"\nMaterial \"diffuse\" \"texture reflectance\" \"c\"\n"
             "Translate 10 0 0\nShape \"sphere\"\n");
    write_file("bump.pbrt", text);
    cdl_scene s;
    cdl_scene_settings set;
    if (load("bump.pbrt", &s, &set, &err)) {
        CHECK(0, "bump.pbrt loads");
        return;
    }
    cdl_surface sa, sb;
    cdl_bsdf b;
    int hit = look(&s, 0.5f, 0.5f, &sa, &b) && look(&s, 3.0f, 0.5f, &sb, &b);
    float ta = atan2f(-sa.ns.x, sa.ns.z), tb = atan2f(-sb.ns.x, sb.ns.z);
    CHECK(hit && fabsf(ta - atanf(0.4f)) < 1e-4f && fabsf(tb + atanf(0.4f)) < 1e-4f && fabsf(sa.ns.y) < 1e-6f,
          "bumpmap of a ramp: tilt towards -x %g (atan 0.4 = %g); pbrt-v3 with vertex normals, dp/du twice as "
          "long, %g (-atan 0.4)",
          (double)ta, (double)atanf(0.4f), (double)tb);
    const cdl_material *ma = &s.mats[s.tri_mat[0]], *mb = &s.mats[s.tri_mat[2]], *mc = &s.mats[s.tri_mat[4]];
    CHECK(ma->maps.bump_frame == CDL_BUMP_PARTIALS && mb->maps.bump_frame == CDL_BUMP_PBRT3_VN &&
              mc->maps.bump_frame == CDL_BUMP_PBRT4_VN && mc->maps.bump_tex == ma->maps.bump_tex &&
              ma->maps.bump_scale == 1.0f,
          "bump frames: partials without normals, pbrt-v3's and pbrt-v4's with them (%d %d %d)",
          ma->maps.bump_frame, mb->maps.bump_frame, mc->maps.bump_frame);
    cdl_surface sn;
    cdl_vec3 want = cdl_normalize(cdl_v3(2.0f * 191.0f / 255.0f - 1.0f, 2.0f * 128.0f / 255.0f - 1.0f,
                                         2.0f * 238.0f / 255.0f - 1.0f));
    CHECK(look(&s, 6.5f, 0.5f, &sn, &b) && near3(sn.ns, want, 1e-5f),
          "v4 normalmap: shading normal (%g %g %g), want (%g %g %g) (8-bit values linear, x along dp/du)",
          V3(sn.ns), V3(want));
    CHECK(s.nspheres == 0 && s.ntris > 8, "a sphere under a texture is tessellated (%u analytic spheres)",
          s.nspheres);
    cdl_scene_free(&s);
}

int main(void)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/candela-pbrt-tex-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
        perror("mkdtemp");
        return 2;
    }
    test_checkerboard();
    test_imagemap();
    test_bump();
    char cmd[512];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "could not remove %s\n", dir);
    printf("%d failure(s)\n", test_failures);
    return test_failures != 0;
}
