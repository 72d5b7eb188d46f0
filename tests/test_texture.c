/* Textures and shading frames as Mitsuba 3 defines them (issue 27):
 * bitmap lookups at known texels with each wrap and filter mode, the
 * checkerboard's two conventions, the bilinear gradient, a bump map of a
 * linear height field tilting the normal by the analytic angle, and an
 * identity normal map leaving the BSDF unchanged. Then pbrt's: its
 * checkerboard cells, black wrap, products and mixes of textures with
 * their gradients, the bump frames of its meshes with vertex normals and
 * textured roughness remapped at each lookup. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "core/sampling.h"
#include "scene/shading.h"
#include "test_util.h"

static int near3(cdl_vec3 a, cdl_vec3 b, float tol)
{
    return fabsf(a.x - b.x) <= tol && fabsf(a.y - b.y) <= tol && fabsf(a.z - b.z) <= tol;
}

/* A w x h grey image whose texel (x, y) holds f(x, y). */
static cdl_texture grey(int w, int h, float (*f)(int, int))
{
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_BITMAP);
    t.w = w;
    t.h = h;
    t.rgb = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = 0; k < 3; k++)
                t.rgb[3 * (y * w + x) + k] = f(x, y);
    return t;
}

static float index_value(int x, int y) { return (float)(x + 10 * y); }
static float ramp(int x, int y)
{
    (void)y;
    return 0.1f * (float)x;
}

/* Image coordinates (s, t) of the texture are (u, 1 - v) by default:
 * surface (u, v) for a given s, t. */
static float val(const cdl_texture *t, float s, float tt) { return cdl_texture_eval(t, 0, s, 1.0f - tt).x; }

static void lookups(void)
{
    cdl_texture t = grey(4, 2, index_value);
    /* texel centres at (i + 0.5) / w; t = 0 is the top row */
    CHECK(fabsf(val(&t, 0.625f, 0.25f) - 2.0f) < 1e-5f, "bilinear at texel (2, 0)'s centre: %g (2)",
          (double)val(&t, 0.625f, 0.25f));
    CHECK(fabsf(val(&t, 0.5f, 0.75f) - 11.5f) < 1e-5f, "bilinear between (1, 1) and (2, 1): %g (11.5)",
          (double)val(&t, 0.5f, 0.75f));
    /* at s = 0 the lookup straddles texel -1 and texel 0 */
    float rep = val(&t, 0.0f, 0.25f);
    t.wrap = CDL_WRAP_MIRROR;
    float mir = val(&t, 0.0f, 0.25f);
    t.wrap = CDL_WRAP_CLAMP;
    float cla = val(&t, 0.0f, 0.25f);
    CHECK(fabsf(rep - 1.5f) < 1e-5f && fabsf(mir) < 1e-5f && fabsf(cla) < 1e-5f,
          "left edge: repeat %g (1.5, texels 3 and 0), mirror %g (0), clamp %g (0)", (double)rep, (double)mir,
          (double)cla);
    /* nearest, one texel past the right edge and two widths to the left */
    t.nearest = 1;
    float r[3], l[3];
    for (int m = 0; m < 3; m++) {
        t.wrap = m;
        r[m] = val(&t, 1.0f + 0.125f, 0.25f);
        l[m] = val(&t, -2.0f + 0.375f, 0.25f); /* texel -7 */
    }
    CHECK(r[CDL_WRAP_REPEAT] == 0.0f && r[CDL_WRAP_MIRROR] == 3.0f && r[CDL_WRAP_CLAMP] == 3.0f,
          "texel 4: repeat %g (0), mirror %g (3), clamp %g (3)", (double)r[0], (double)r[1], (double)r[2]);
    CHECK(l[CDL_WRAP_REPEAT] == 1.0f && l[CDL_WRAP_MIRROR] == 1.0f && l[CDL_WRAP_CLAMP] == 0.0f,
          "texel -7: repeat %g (1), mirror %g (1: 0 1 2 3 3 2 1 0 ...), clamp %g (0)", (double)l[0],
          (double)l[1], (double)l[2]);
    /* a to_uv of scale 2, translate -0.5 (texture_interp's) */
    t.nearest = 0;
    t.wrap = CDL_WRAP_REPEAT;
    t.m[0] = 2.0f, t.m[1] = 0.0f, t.m[2] = -0.5f;
    float v0 = cdl_texture_eval(&t, 0, 0.3125f, 0.5f).x; /* s = 0.125 */
    CHECK(fabsf(v0 - 5.0f) < 1e-5f, "uv map: s = 0.125, t = 0.5 gives %g (5)", (double)v0);
    cdl_texture_free(&t);
}

static void checker(void)
{
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_CHECKER);
    t.a = cdl_v3(0.05f, 0.05f, 0.05f);
    t.b = cdl_v3(0.3f, 0.3f, 0.3f);
    /* (s, t) = (0.25, 0.25): both halves below 0.5 */
    cdl_vec3 c = cdl_texture_eval(&t, 0, 0.25f, 0.75f);
    float f = cdl_texture_eval1(&t, 0, 0.25f, 0.75f);
    CHECK(near3(c, t.a, 1e-6f) && fabsf(f - 0.3f) < 1e-6f,
          "checkerboard: color0 where the halves agree (%g), its scalar value color1 (%g)", (double)c.x, (double)f);
    c = cdl_texture_eval(&t, 0, 0.75f, 0.75f);
    f = cdl_texture_eval1(&t, 0, 0.75f, 0.75f);
    CHECK(near3(c, t.b, 1e-6f) && fabsf(f - 0.05f) < 1e-6f, "checkerboard: and the other way round (%g, %g)",
          (double)c.x, (double)f);
}

/* A surface of the xy plane, uv = (x, y), normal +z. */
static cdl_surface plane(uint32_t mat)
{
    cdl_surface sf;
    memset(&sf, 0, sizeof sf);
    sf.ng = sf.ns = cdl_v3(0, 0, 1);
    sf.dpdu = cdl_v3(1, 0, 0);
    sf.dpdv = cdl_v3(0, 1, 0);
    sf.u = 0.5f;
    sf.v = 0.5f;
    sf.mat = mat;
    return sf;
}

static void bump(void)
{
    cdl_texture texs[1] = {grey(8, 8, ramp)};
    float g[2];
    cdl_texture_grad1(texs, 0, 0.5f, 0.5f, g);
    /* 0.1 per texel, 8 texels per unit of u */
    CHECK(fabsf(g[0] - 0.8f) < 1e-4f && fabsf(g[1]) < 1e-6f, "gradient of the ramp (%g, %g) (0.8, 0)", (double)g[0],
          (double)g[1]);
    cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
    m.maps.on = 1;
    m.maps.bump_tex = 0;
    m.maps.bump_scale = 0.5f;
    cdl_scene s;
    memset(&s, 0, sizeof s);
    s.mats = &m;
    s.nmats = 1;
    s.texs = texs;
    s.ntexs = 1;
    cdl_surface sf = plane(0);
    cdl_surface_shade(&s, &sf, cdl_v3(0, 0, 1));
    /* height h = 0.4 u: the normal of z = 0.4 u tilts by atan(0.4) towards -x */
    float angle = acosf(cdl_dot(sf.ns, sf.nb)), want = atanf(0.4f);
    CHECK(fabsf(angle - want) < 1e-4f && sf.ns.x < 0.0f && fabsf(sf.ns.y) < 1e-6f,
          "bump map of a linear height tilts the normal by %g rad (atan 0.4 = %g) towards -x", (double)angle,
          (double)want);
    cdl_bsdf b;
    cdl_scene_bsdf(&s, &sf, &b);
    CHECK(b.perturbed && fabsf(cdl_dot(b.frame.n, b.frame.t)) < 1e-6f, "the BSDF's frame is the perturbed one");
    cdl_texture_free(&texs[0]);
}

static void identity_normal_map(void)
{
    cdl_texture texs[1];
    cdl_texture_init(&texs[0], CDL_TEX_CONST);
    texs[0].a = cdl_v3(0.5f, 0.5f, 1.0f);
    cdl_material m[2];
    m[0] = cdl_material_default(CDL_MAT_CONDUCTOR);
    m[0].alpha_x = 0.25f;
    m[0].alpha_y = 0.05f;
    m[1] = m[0];
    m[1].maps.on = 1;
    m[1].maps.normal_tex = 0;
    cdl_scene s;
    memset(&s, 0, sizeof s);
    s.mats = m;
    s.nmats = 2;
    s.texs = texs;
    s.ntexs = 1;
    /* a tilted, non-orthogonal parameterization */
    cdl_surface a = plane(0), b = plane(1);
    a.dpdu = b.dpdu = cdl_v3(0.6f, 0.8f, 0.0f);
    a.dpdv = b.dpdv = cdl_v3(-0.3f, 0.5f, 0.0f);
    cdl_vec3 wo = cdl_normalize(cdl_v3(0.3f, -0.2f, 0.9f));
    cdl_surface_shade(&s, &a, wo);
    cdl_surface_shade(&s, &b, wo);
    cdl_bsdf ba, bb;
    cdl_scene_bsdf(&s, &a, &ba);
    cdl_scene_bsdf(&s, &b, &bb);
    CHECK(near3(ba.frame.t, bb.frame.t, 1e-6f) && near3(ba.frame.n, bb.frame.n, 1e-6f) && !bb.perturbed,
          "identity normal map: the same frame (tangent along dp/du: %.3f %.3f %.3f)", (double)ba.frame.t.x,
          (double)ba.frame.t.y, (double)ba.frame.t.z);
    float worst = 0.0f;
    cdl_rng rng;
    cdl_rng_seed(&rng, 7, 0);
    for (int i = 0; i < 200; i++) {
        cdl_vec3 wi = cdl_sample_cosine_hemisphere(cdl_rng_float(&rng), cdl_rng_float(&rng));
        cdl_vec3 fa = cdl_bsdf_eval(&ba, wo, wi, 0), fb = cdl_bsdf_eval(&bb, wo, wi, 0);
        float d = fabsf(fa.x - fb.x) / (fabsf(fa.x) + 1e-3f);
        worst = d > worst ? d : worst;
    }
    CHECK(worst < 1e-5f, "identity normal map: the same f (worst relative difference %g)", (double)worst);
    /* and the anisotropic lobe follows dp/du: swapping the roughnesses changes f */
    cdl_bsdf bc = ba;
    bc.ax = ba.ay;
    bc.ay = ba.ax;
    cdl_vec3 wi = cdl_reflect(wo, cdl_v3(0, 0, 1));
    wi = cdl_normalize(cdl_add(wi, cdl_scale(ba.frame.t, 0.3f)));
    CHECK(fabsf(cdl_bsdf_eval(&ba, wo, wi, 0).x - cdl_bsdf_eval(&bc, wo, wi, 0).x) > 1e-3f,
          "the anisotropic lobe is oriented by the tangent");
}

/* pbrt's checkerboard: tex1 where floor(s) + floor(t) is even, for the
 * colour and the scalar alike, negative cells included; t is v itself. */
static void pbrt_checker(void)
{
    cdl_texture t;
    cdl_texture_init(&t, CDL_TEX_CHECKER);
    t.unit_cells = 1;
    t.m[0] = 2.0f, t.m[1] = 0.0f, t.m[2] = 0.0f; /* s = 2 u, t = 2 v */
    t.m[3] = 0.0f, t.m[4] = 2.0f, t.m[5] = 0.0f;
    t.a = cdl_v3(0.25f, 0.25f, 0.25f);
    t.b = cdl_v3(0.75f, 0.75f, 0.75f);
    static const struct {
        float u, v;
        int first;
    } at[] = {{0.1f, 0.1f, 1}, {0.6f, 0.1f, 0}, {0.6f, 0.6f, 1}, {0.1f, 0.6f, 0},
              {-0.1f, 0.1f, 0}, {-0.1f, -0.1f, 1}, {-0.6f, 0.1f, 1}, {1.0f, 0.1f, 1}};
    int bad = 0;
    for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
        float want = at[i].first ? 0.25f : 0.75f;
        float c = cdl_texture_eval(&t, 0, at[i].u, at[i].v).x, f = cdl_texture_eval1(&t, 0, at[i].u, at[i].v);
        if (c != want || f != want) {
            printf("      (u, v) = (%g, %g): colour %g, scalar %g, want %g\n", (double)at[i].u, (double)at[i].v,
                   (double)c, (double)f, (double)want);
            bad++;
        }
    }
    CHECK(bad == 0, "pbrt checkerboard: tex1 where floor(2u) + floor(2v) is even, colour and scalar, at %zu points",
          sizeof at / sizeof at[0]);
}

/* pbrt's black wrap, the product of two textures and a mix, with their
 * gradients by the product rule. */
static void pbrt_combinations(void)
{
    cdl_texture texs[5];
    texs[0] = grey(8, 8, ramp); /* 0.8 u (+ const) along u */
    texs[0].wrap = CDL_WRAP_BLACK;
    float in = cdl_texture_eval(texs, 0, 0.5f / 8.0f, 0.5f).x, edge = cdl_texture_eval(texs, 0, 0.0f, 0.5f).x,
          out = cdl_texture_eval(texs, 0, -0.5f, 0.5f).x, right = cdl_texture_eval(texs, 0, 1.0f, 0.5f).x;
    CHECK(in == 0.0f && edge == 0.0f && out == 0.0f && fabsf(right - 0.35f) < 1e-6f,
          "black wrap: texel 0 %g, left edge %g, outside %g, right edge %g (half of texel 7's 0.7)", (double)in,
          (double)edge, (double)out, (double)right);
    texs[0].wrap = CDL_WRAP_REPEAT;
    cdl_texture_init(&texs[1], CDL_TEX_CONST);
    texs[1].a = cdl_v3(0.5f, 0.5f, 0.5f);
    /* 2: ramp * ramp * 2; 3: mix of the ramp and 0.5 by the ramp */
    cdl_texture_init(&texs[2], CDL_TEX_SCALE);
    texs[2].sub[0] = texs[2].sub[1] = 0;
    texs[2].scale = 2.0f;
    cdl_texture_init(&texs[3], CDL_TEX_MIX);
    texs[3].sub[0] = 0;
    texs[3].sub[1] = 1;
    texs[3].amount_tex = 0;
    float u = 0.5f, v = 0.5f, h = cdl_texture_eval1(texs, 0, u, v), g[2];
    float p = cdl_texture_eval(texs, 2, u, v).x, p1 = cdl_texture_eval1(texs, 2, u, v);
    cdl_texture_grad1(texs, 2, u, v, g);
    CHECK(fabsf(p - 2.0f * h * h) < 1e-5f && fabsf(p1 - p) < 1e-5f && fabsf(g[0] - 4.0f * h * 0.8f) < 1e-4f &&
              fabsf(g[1]) < 1e-6f,
          "scale of two textures: %g (2 h^2 = %g), gradient %g (4 h h' = %g)", (double)p, (double)(2.0f * h * h),
          (double)g[0], (double)(4.0f * h * 0.8f));
    float mx = cdl_texture_eval(texs, 3, u, v).x, m1 = cdl_texture_eval1(texs, 3, u, v);
    cdl_texture_grad1(texs, 3, u, v, g);
    float want = (1.0f - h) * h + h * 0.5f, dwant = (1.0f - 2.0f * h + 0.5f) * 0.8f;
    CHECK(fabsf(mx - want) < 1e-5f && fabsf(m1 - want) < 1e-5f && fabsf(g[0] - dwant) < 1e-4f,
          "mix by a texture: %g (%g), gradient %g (%g)", (double)mx, (double)want, (double)g[0], (double)dwant);
    cdl_texture_free(&texs[0]);
}

/* pbrt's bump frames on meshes with vertex normals: v3 displaces its
 * unit, reversed shading frame (the tilt has the other sign and ignores
 * |dp/du|), v4 its shading frame of |dp/du|'s length. A height h = 0.4 u
 * over a plane where dp/du = (2, 0, 0), dp/dv = (0, 1, 0). */
static void pbrt_bump_frames(void)
{
    cdl_texture texs[1] = {grey(8, 8, ramp)};
    cdl_material m[3];
    for (int i = 0; i < 3; i++) {
        m[i] = cdl_material_default(CDL_MAT_DIFFUSE);
        m[i].maps.on = 1;
        m[i].maps.bump_tex = 0;
        m[i].maps.bump_scale = 0.5f;
        m[i].maps.bump_frame = i; /* PARTIALS, PBRT3_VN, PBRT4_VN */
    }
    cdl_scene s;
    memset(&s, 0, sizeof s);
    s.mats = m;
    s.nmats = 3;
    s.texs = texs;
    s.ntexs = 1;
    float tilt[3];
    for (int i = 0; i < 3; i++) {
        cdl_surface sf = plane((uint32_t)i);
        sf.dpdu = cdl_v3(2, 0, 0);
        cdl_surface_shade(&s, &sf, cdl_v3(0, 0, 1));
        tilt[i] = atan2f(-sf.ns.x, sf.ns.z); /* towards -x positive */
    }
    CHECK(fabsf(tilt[0] - atanf(0.2f)) < 1e-4f && fabsf(tilt[1] + atanf(0.4f)) < 1e-4f &&
              fabsf(tilt[2] - atanf(0.2f)) < 1e-4f,
          "bump tilt towards -x: partials %g (atan 0.2 = %g), pbrt-v3 with normals %g (-atan 0.4 = %g), pbrt-v4 %g",
          (double)tilt[0], (double)atanf(0.2f), (double)tilt[1], (double)-atanf(0.4f), (double)tilt[2]);
    /* a ramp along v (h = 0.4 v) tells v4's frame (|dp/du| t) from the partials (dp/dv) */
    texs[0].m[0] = 0.0f, texs[0].m[1] = 1.0f, texs[0].m[2] = 0.0f; /* s = v */
    for (int i = 0; i < 3; i += 2) {
        cdl_surface sf = plane((uint32_t)i);
        sf.dpdu = cdl_v3(2, 0, 0);
        cdl_surface_shade(&s, &sf, cdl_v3(0, 0, 1));
        tilt[i] = atan2f(-sf.ns.y, sf.ns.z);
    }
    CHECK(fabsf(tilt[0] - atanf(0.4f)) < 1e-4f && fabsf(tilt[2] - atanf(0.2f)) < 1e-4f,
          "bump along v: partials %g (atan 0.4 = %g), pbrt-v4 with normals %g (atan 0.2 = %g)", (double)tilt[0],
          (double)atanf(0.4f), (double)tilt[2], (double)atanf(0.2f));
    cdl_texture_free(&texs[0]);
}

/* A textured roughness becomes alpha at each lookup as pbrt remaps it. */
static void pbrt_roughness(void)
{
    cdl_texture texs[1];
    cdl_texture_init(&texs[0], CDL_TEX_CONST);
    texs[0].a = cdl_v3(0.25f, 0.25f, 0.25f);
    cdl_material m[2];
    for (int i = 0; i < 2; i++) {
        m[i] = cdl_material_default(CDL_MAT_CONDUCTOR);
        m[i].maps.on = 1;
        m[i].maps.alpha_tex[0] = m[i].maps.alpha_tex[1] = 0;
        m[i].maps.alpha_remap = i ? CDL_ROUGH_PBRT4 : CDL_ROUGH_PBRT3;
    }
    cdl_scene s;
    memset(&s, 0, sizeof s);
    s.mats = m;
    s.nmats = 2;
    s.texs = texs;
    s.ntexs = 1;
    float a[2];
    for (int i = 0; i < 2; i++) {
        cdl_surface sf = plane((uint32_t)i);
        cdl_surface_shade(&s, &sf, cdl_v3(0, 0, 1));
        cdl_bsdf b;
        cdl_scene_bsdf(&s, &sf, &b);
        a[i] = b.ax;
    }
    float x = logf(0.25f);
    float v3 = 1.62142f + 0.819955f * x + 0.1734f * x * x + 0.0171201f * x * x * x + 0.000640711f * x * x * x * x;
    CHECK(fabsf(a[0] - v3) < 1e-5f && fabsf(a[1] - 0.5f) < 1e-6f,
          "textured roughness 0.25: pbrt-v3 alpha %g (%g), pbrt-v4 %g (sqrt: 0.5)", (double)a[0], (double)v3,
          (double)a[1]);
}

int main(void)
{
    lookups();
    checker();
    bump();
    identity_normal_map();
    pbrt_checker();
    pbrt_combinations();
    pbrt_bump_frames();
    pbrt_roughness();
    if (test_failures)
        printf("%d check(s) failed\n", test_failures);
    return test_failures != 0;
}
