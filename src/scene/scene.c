#include "scene/scene.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/grow.h"
#include "core/log.h"
#include "scene/attr.h"
#include "scene/shading.h"
#include "scene/instance.h"


static void embree_error(void *user, enum RTCError code, const char *str)
{
    (void)user;
    fprintf(stderr, "candela: embree error %d: %s\n", (int)code, str ? str : "");
}

int cdl_scene_init(cdl_scene *s, const char *path, cdl_error *err)
{
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path ? path : "");
    s->open_group = -1;
    s->device = rtcNewDevice(NULL);
    if (!s->device)
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "cannot create Embree device (error %d)",
                             (int)rtcGetDeviceError(NULL));
    rtcSetDeviceErrorFunction(s->device, embree_error, NULL);
    return 0;
}

void cdl_scene_free(cdl_scene *s)
{
    if (s->rtc)
        rtcReleaseScene(s->rtc);
    cdl_instances_free(s);
    if (s->device)
        rtcReleaseDevice(s->device);
    free(s->pos);
    free(s->nrm);
    free(s->uv);
    free(s->idx);
    free(s->tri_mat);
    free(s->tri_emit);
    free(s->tri_flags);
    free(s->sph);
    free(s->sph_mat);
    free(s->sph_emit);
    free(s->sph_inward);
    free(s->sph_light);
    free(s->emitters);
    free(s->face_n);
    free(s->tri_light);
    free(s->mats);
    cdl_attrs_free(s);
    for (uint32_t i = 0; i < s->ntexs; i++)
        cdl_texture_free(&s->texs[i]);
    free(s->texs);
    free(s->lights);
    if (s->envmap)
        cdl_envmap_free(s->envmap);
    free(s->envmap);
    cdl_alias_free(&s->light_select);
    memset(s, 0, sizeof *s);
}

int cdl_scene_add_vertices(cdl_scene *s, uint32_t n, const float *p, const float *nrm,
                           const float *uv, uint32_t *first, cdl_error *err)
{
    if (n > UINT32_MAX / 4 - s->nverts)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "too many vertices");
    uint32_t need = s->nverts + n + 1; /* +1: Embree reads 16 bytes per vertex */
    if (need > s->cap_verts) {
        uint32_t cp = s->cap_verts, cn = cp, cu = cp;
        if (cdl_grow((void **)&s->pos, &cp, need, 3 * sizeof(float)) ||
            cdl_grow((void **)&s->nrm, &cn, need, 3 * sizeof(float)) ||
            cdl_grow((void **)&s->uv, &cu, need, 2 * sizeof(float)))
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for %u vertices", need);
        s->cap_verts = cp;
    }
    for (uint32_t i = 0; i < n; i++) {
        for (int k = 0; k < 3; k++) {
            float x = p[3 * i + k];
            if (!isfinite(x) || fabsf(x) > CDL_MAX_COORD)
                return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                                     "vertex %u has an invalid coordinate %g", i, (double)x);
        }
    }
    memcpy(s->pos + 3 * (size_t)s->nverts, p, 3 * sizeof(float) * n);
    if (nrm)
        memcpy(s->nrm + 3 * (size_t)s->nverts, nrm, 3 * sizeof(float) * n);
    else
        memset(s->nrm + 3 * (size_t)s->nverts, 0, 3 * sizeof(float) * n);
    if (uv)
        memcpy(s->uv + 2 * (size_t)s->nverts, uv, 2 * sizeof(float) * n);
    else
        memset(s->uv + 2 * (size_t)s->nverts, 0, 2 * sizeof(float) * n);
    memset(s->pos + 3 * (size_t)(s->nverts + n), 0, 3 * sizeof(float)); /* padding */
    *first = s->nverts;
    s->nverts += n;
    return 0;
}

int cdl_scene_add_triangle(cdl_scene *s, uint32_t a, uint32_t b, uint32_t c,
                           uint32_t mat, int32_t emit, uint8_t flags, cdl_error *err)
{
    if (a >= s->nverts || b >= s->nverts || c >= s->nverts || mat >= s->nmats ||
        emit >= (int32_t)s->nemitters || emit < -1)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "triangle index out of range");
    /* Zero-area triangles carry no light and break normals: skip them. */
    const float *pa = s->pos + 3 * (size_t)a, *pb = s->pos + 3 * (size_t)b, *pc = s->pos + 3 * (size_t)c;
    cdl_vec3 e1 = cdl_v3(pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]);
    cdl_vec3 e2 = cdl_v3(pc[0] - pa[0], pc[1] - pa[1], pc[2] - pa[2]);
    cdl_vec3 n = cdl_cross(e1, e2);
    float len = cdl_length(n);
    /* relative test: with fused multiply-adds the cross product of
     * collinear edges need not cancel to exactly zero */
    if (!(len > 1e-7f * cdl_length(e1) * cdl_length(e2)) || !isfinite(len))
        return 0;
    if (s->ntris == s->cap_tris) {
        uint32_t ci = s->cap_tris, cm = ci, ce = ci, cf = ci;
        if (cdl_grow((void **)&s->idx, &ci, s->ntris + 1, 3 * sizeof(uint32_t)) ||
            cdl_grow((void **)&s->tri_mat, &cm, s->ntris + 1, sizeof(uint32_t)) ||
            cdl_grow((void **)&s->tri_emit, &ce, s->ntris + 1, sizeof(int32_t)) ||
            cdl_grow((void **)&s->tri_flags, &cf, s->ntris + 1, sizeof(uint8_t)))
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for triangles");
        s->cap_tris = ci; /* all four grew to the same capacity */
    }
    uint32_t *t = s->idx + 3 * (size_t)s->ntris;
    t[0] = a;
    t[1] = b;
    t[2] = c;
    s->tri_mat[s->ntris] = mat;
    s->tri_emit[s->ntris] = emit;
    s->tri_flags[s->ntris] = flags;
    s->ntris++;
    return 0;
}

int cdl_scene_add_material(cdl_scene *s, const cdl_material *m, uint32_t *id, cdl_error *err)
{
    const cdl_mat_maps *mm = &m->maps;
    int refs[4] = {mm->alpha_tex[0], mm->alpha_tex[1], mm->bump_tex, mm->normal_tex};
    for (int k = 0; k < 4 && mm->on; k++)
        if (refs[k] < -1 || refs[k] >= (int)s->ntexs)
            return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "material texture %d out of range", refs[k]);
    /* a blend's materials come first, so resolving one always ends */
    if (m->type == CDL_MAT_BLEND &&
        (m->blend[0] < 0 || m->blend[1] < 0 || m->blend[0] >= (int)s->nmats || m->blend[1] >= (int)s->nmats ||
         m->blend_tex < -1 || m->blend_tex >= (int)s->ntexs || m->blend_as < -1 || m->blend_as >= (int)s->nmats ||
         (m->blend_as >= 0 && s->mats[m->blend_as].type == CDL_MAT_BLEND)))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "blend material refers to a missing material");
    if (cdl_grow((void **)&s->mats, &s->cap_mats, s->nmats + 1, sizeof *m))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for materials");
    s->mats[s->nmats] = cdl_material_canonical(*m);
    *id = s->nmats++;
    return 0;
}

int cdl_scene_add_texture(cdl_scene *s, const char *path, int *id, cdl_error *err)
{
    if (cdl_grow((void **)&s->texs, &s->cap_texs, s->ntexs + 1, sizeof(cdl_texture)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for textures");
    int rc = cdl_texture_load(&s->texs[s->ntexs], path, err);
    if (rc)
        return rc;
    *id = (int)s->ntexs++;
    return 0;
}

int cdl_scene_add_texture_data(cdl_scene *s, cdl_texture *t, int *id, cdl_error *err)
{
    int subs[3] = {t->sub[0], t->sub[1], t->type == CDL_TEX_MIX ? t->amount_tex : -1};
    for (int k = 0; k < 3; k++)
        if (subs[k] >= (int)s->ntexs || subs[k] < -1) {
            cdl_texture_free(t);
            return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "sub-texture %d out of range", subs[k]);
        }
    if (cdl_grow((void **)&s->texs, &s->cap_texs, s->ntexs + 1, sizeof(cdl_texture))) {
        cdl_texture_free(t);
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for textures");
    }
    s->texs[s->ntexs] = *t;
    *id = (int)s->ntexs++;
    return 0;
}

int cdl_scene_add_emitter(cdl_scene *s, cdl_vec3 L, int twosided, int32_t *id, cdl_error *err)
{
    if (!cdl_is_finite3(L) || L.x < 0.0f || L.y < 0.0f || L.z < 0.0f)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "emitted radiance must be finite and >= 0");
    if (cdl_grow((void **)&s->emitters, &s->cap_emitters, s->nemitters + 1, sizeof(cdl_emitter)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory");
    s->emitters[s->nemitters] = (cdl_emitter){L, twosided, -1};
    *id = (int32_t)s->nemitters++;
    return 0;
}

int cdl_scene_add_sphere(cdl_scene *s, cdl_vec3 c, float radius, uint32_t mat, int32_t emit,
                         int inward, cdl_error *err)
{
    if (!cdl_is_finite3(c) || fabsf(c.x) > CDL_MAX_COORD || fabsf(c.y) > CDL_MAX_COORD ||
        fabsf(c.z) > CDL_MAX_COORD || !(radius > 0.0f) || radius > CDL_MAX_COORD)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "sphere centre or radius out of range");
    if (mat >= s->nmats || emit >= (int32_t)s->nemitters || emit < -1)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "sphere material or emitter out of range");
    if (s->nspheres == s->cap_spheres) {
        uint32_t a = s->cap_spheres, b = a, c2 = a, d = a;
        if (cdl_grow((void **)&s->sph, &a, s->nspheres + 1, 4 * sizeof(float)) ||
            cdl_grow((void **)&s->sph_mat, &b, s->nspheres + 1, sizeof(uint32_t)) ||
            cdl_grow((void **)&s->sph_emit, &c2, s->nspheres + 1, sizeof(int32_t)) ||
            cdl_grow((void **)&s->sph_inward, &d, s->nspheres + 1, sizeof(uint8_t)))
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for spheres");
        s->cap_spheres = a;
    }
    float *q = s->sph + 4 * (size_t)s->nspheres;
    q[0] = c.x;
    q[1] = c.y;
    q[2] = c.z;
    q[3] = radius;
    s->sph_mat[s->nspheres] = mat;
    s->sph_emit[s->nspheres] = emit;
    s->sph_inward[s->nspheres] = (uint8_t)(inward != 0);
    s->nspheres++;
    return 0;
}

static int add_light(cdl_scene *s, const cdl_light *l, cdl_error *err)
{
    if (cdl_grow((void **)&s->lights, &s->cap_lights, s->nlights + 1, sizeof *l))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for lights");
    s->lights[s->nlights++] = *l;
    return 0;
}

static int check_light(cdl_scene *s, cdl_vec3 p, cdl_vec3 L, cdl_error *err)
{
    if (!cdl_is_finite3(p) || fabsf(p.x) > CDL_MAX_COORD || fabsf(p.y) > CDL_MAX_COORD ||
        fabsf(p.z) > CDL_MAX_COORD)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "light position or direction out of range");
    if (!cdl_is_finite3(L) || L.x < 0.0f || L.y < 0.0f || L.z < 0.0f)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "light intensity must be finite and >= 0");
    return 0;
}

int cdl_scene_add_point_light(cdl_scene *s, cdl_vec3 p, cdl_vec3 I, cdl_error *err)
{
    int rc = check_light(s, p, I, err);
    if (rc)
        return rc;
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.tex_id = -1;
    l.type = CDL_LIGHT_POINT;
    l.p = p;
    l.L = I;
    return add_light(s, &l, err);
}

int cdl_scene_add_light(cdl_scene *s, const cdl_light *l, cdl_error *err)
{
    int rc = check_light(s, l->p, l->L, err);
    if (rc)
        return rc;
    int frame = fabsf(cdl_length(l->n) - 1.0f) < 1e-3f && fabsf(cdl_length(l->ax) - 1.0f) < 1e-3f &&
                fabsf(cdl_length(l->ay) - 1.0f) < 1e-3f;
    int ok = (l->type == CDL_LIGHT_SPOT && l->cos_total < 1.0f && l->cos_falloff >= l->cos_total) ||
             (l->type == CDL_LIGHT_PROJECTOR && l->tan_x > 0.0f && l->tan_y > 0.0f && isfinite(l->tan_x) &&
              isfinite(l->tan_y));
    if (!frame || !ok || l->tex_id < -1 || l->tex_id >= (int32_t)s->ntexs)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "spot or projector light: bad frame, cone or texture");
    cdl_light c = *l;
    c.tex = NULL;
    return add_light(s, &c, err);
}

int cdl_scene_add_spot_light(cdl_scene *s, cdl_vec3 p, cdl_vec3 dir, cdl_vec3 I, float cone_deg,
                             float delta_deg, cdl_error *err)
{
    int rc = check_light(s, p, I, err);
    if (rc || (rc = check_light(s, dir, I, err)))
        return rc;
    float len = cdl_length(dir);
    if (!(len > 0.0f) || !(cone_deg > 0.0f && cone_deg <= 180.0f) || !(delta_deg >= 0.0f && delta_deg <= cone_deg))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "spot light needs a direction and 0 <= conedelta <= coneangle <= 180");
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.tex_id = -1;
    l.type = CDL_LIGHT_SPOT;
    l.p = p;
    l.n = cdl_scale(dir, 1.0f / len);
    l.L = I;
    l.cos_total = cosf(cone_deg * CDL_PI / 180.0f);
    l.cos_falloff = cosf((cone_deg - delta_deg) * CDL_PI / 180.0f);
    return add_light(s, &l, err);
}

int cdl_scene_add_distant_light(cdl_scene *s, cdl_vec3 dir, cdl_vec3 L, cdl_error *err)
{
    int rc = check_light(s, dir, L, err);
    if (rc)
        return rc;
    float len = cdl_length(dir);
    if (!(len > 0.0f))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "distant light needs from != to");
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.tex_id = -1;
    l.type = CDL_LIGHT_DISTANT;
    l.n = cdl_scale(dir, 1.0f / len);
    l.L = L;
    return add_light(s, &l, err);
}

int cdl_scene_add_infinite_light(cdl_scene *s, cdl_vec3 L, cdl_error *err)
{
    return cdl_scene_add_env_light(s, L, NULL, err);
}

int cdl_scene_add_env_light(cdl_scene *s, cdl_vec3 L, cdl_envmap *map, cdl_error *err)
{
    int rc = check_light(s, cdl_v3(0, 0, 0), L, err);
    for (uint32_t i = 0; !rc && i < s->nlights; i++)
        if (s->lights[i].type == CDL_LIGHT_INFINITE)
            rc = cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "only one infinite light is supported");
    cdl_light l;
    memset(&l, 0, sizeof l);
    l.tex_id = -1;
    l.type = CDL_LIGHT_INFINITE;
    l.L = L;
    l.map = map;
    if (!rc)
        rc = add_light(s, &l, err);
    if (rc && map) {
        cdl_envmap_free(map);
        free(map);
    } else if (map) {
        s->envmap = map;
    }
    return rc;
}

/* Area lights from emitting shapes; bounds-dependent lights finished. */
static cdl_vec3 texture_mean(const cdl_texture *t)
{
    double m[3] = {0.0, 0.0, 0.0};
    size_t n = (size_t)t->w * (size_t)t->h;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            m[k] += t->rgb[3 * i + k];
    return n ? cdl_v3((float)(m[0] / n), (float)(m[1] / n), (float)(m[2] / n)) : cdl_v3(0, 0, 0);
}

static int build_lights(cdl_scene *s, cdl_error *err)
{
    s->tri_light = malloc(sizeof(int32_t) * (s->ntris ? s->ntris : 1));
    s->face_n = malloc(sizeof(cdl_vec3) * (s->ntris ? s->ntris : 1));
    s->sph_light = malloc(sizeof(int32_t) * (s->nspheres ? s->nspheres : 1));
    if (!s->tri_light || !s->face_n || !s->sph_light)
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory");
    cdl_vec3 centre = cdl_scale(cdl_add(s->bmin, s->bmax), 0.5f);
    float radius = 0.5f * cdl_length(cdl_sub(s->bmax, s->bmin));
    s->env_light = -1;
    for (uint32_t i = 0; i < s->nlights; i++) {
        cdl_light *l = &s->lights[i];
        if (cdl_light_at_infinity(l)) {
            l->p = centre;
            l->radius = radius > 0.0f ? radius : 1.0f;
        }
        if (l->type == CDL_LIGHT_INFINITE)
            s->env_light = (int32_t)i;
    }
    for (uint32_t i = 0; i < s->ntris; i++) {
        const uint32_t *t = s->idx + 3 * (size_t)i;
        cdl_vec3 p0 = cdl_v3(s->pos[3 * t[0]], s->pos[3 * t[0] + 1], s->pos[3 * t[0] + 2]);
        cdl_vec3 p1 = cdl_v3(s->pos[3 * t[1]], s->pos[3 * t[1] + 1], s->pos[3 * t[1] + 2]);
        cdl_vec3 p2 = cdl_v3(s->pos[3 * t[2]], s->pos[3 * t[2] + 1], s->pos[3 * t[2] + 2]);
        cdl_vec3 e1 = cdl_sub(p1, p0), e2 = cdl_sub(p2, p0);
        cdl_vec3 c = cdl_cross(e1, e2);
        float len = cdl_length(c);
        s->face_n[i] = cdl_scale(c, 1.0f / len);
        s->tri_light[i] = -1;
        if (s->tri_emit[i] < 0 || cdl_is_black(s->emitters[s->tri_emit[i]].L))
            continue;
        const cdl_emitter *em = &s->emitters[s->tri_emit[i]];
        cdl_light l;
        memset(&l, 0, sizeof l);
        l.tex_id = -1;
        l.type = CDL_LIGHT_TRIANGLE;
        l.p = p0;
        l.e1 = e1;
        l.e2 = e2;
        l.n = s->face_n[i];
        l.area = 0.5f * len;
        l.L = em->L;
        l.twosided = em->twosided;
        l.prim = i;
        l.tex_id = em->tex;
        for (int k = 0; k < 3 && em->tex >= 0; k++) {
            l.uv[2 * k] = s->uv[2 * t[k]];
            l.uv[2 * k + 1] = s->uv[2 * t[k] + 1];
        }
        s->tri_light[i] = (int32_t)s->nlights;
        if (add_light(s, &l, err))
            return err->code;
    }
    for (uint32_t i = 0; i < s->nspheres; i++) {
        s->sph_light[i] = -1;
        if (s->sph_emit[i] < 0 || cdl_is_black(s->emitters[s->sph_emit[i]].L))
            continue;
        cdl_light l;
        memset(&l, 0, sizeof l);
        l.tex_id = -1;
        l.type = CDL_LIGHT_SPHERE;
        l.p = cdl_v3(s->sph[4 * i], s->sph[4 * i + 1], s->sph[4 * i + 2]);
        l.radius = s->sph[4 * i + 3];
        l.area = 4.0f * CDL_PI * l.radius * l.radius;
        l.L = s->emitters[s->sph_emit[i]].L;
        if (s->emitters[s->sph_emit[i]].tex >= 0) { /* no uv on candela's analytic spheres */
            l.L = cdl_mul(l.L, texture_mean(&s->texs[s->emitters[s->sph_emit[i]].tex]));
            cdl_warn(s->path, 0, "a textured emitter on an analytic sphere emits the texture's mean");
        }
        l.inward = s->sph_inward[i];
        l.prim = i;
        s->sph_light[i] = (int32_t)s->nlights;
        if (add_light(s, &l, err))
            return err->code;
    }
    if (s->nlights == 0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0,
                             "scene has no light (no emitting surface and no point_light)");
    /* the textures are all loaded now: their addresses stay */
    for (uint32_t i = 0; i < s->nlights; i++) {
        cdl_light *l = &s->lights[i];
        if (l->type == CDL_LIGHT_INFINITE || l->type == CDL_LIGHT_DISTANT || l->tex_id < 0 ||
            l->tex_id >= (int32_t)s->ntexs) {
            l->tex = NULL;
            continue;
        }
        l->tex = &s->texs[l->tex_id];
        l->tex_mean = texture_mean(l->tex);
    }
    float *w = malloc(sizeof(float) * s->nlights);
    double *emit_area = s->light_select_uniform ? calloc(s->nemitters ? s->nemitters : 1, sizeof(double)) : NULL;
    if (!w || (s->light_select_uniform && !emit_area)) {
        free(w);
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory");
    }
    for (uint32_t i = 0; i < s->nlights && emit_area; i++)
        if (s->lights[i].type == CDL_LIGHT_TRIANGLE)
            emit_area[s->tri_emit[s->lights[i].prim]] += s->lights[i].area;
    for (uint32_t i = 0; i < s->nlights; i++) {
        const cdl_light *l = &s->lights[i];
        cdl_vec3 P = cdl_light_power(l);
        w[i] = (P.x + P.y + P.z) / 3.0f;
        /* uniform over emitters (a mesh is one), by area within a mesh */
        if (emit_area && w[i] > 0.0f)
            w[i] = l->type == CDL_LIGHT_TRIANGLE ? (float)(l->area / emit_area[s->tri_emit[l->prim]]) : 1.0f;
    }
    free(emit_area);
    int rc = cdl_alias_build(&s->light_select, w, s->nlights);
    free(w);
    if (rc)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "lights have no finite positive power");
    return 0;
}

/* Occlusion filter of the sphere geometry: drops hits on the sphere the
 * shadow ray is aimed at (cdl_shadow_ctx). */
static void skip_target_sphere(const struct RTCFilterFunctionNArguments *args)
{
    const cdl_shadow_ctx *sc = (const cdl_shadow_ctx *)args->context;
    for (unsigned i = 0; i < args->N; i++)
        /* RTCHitN is SoA: Ng x y z, u, v, then primID (rtcore_ray.h) */
        if (args->valid[i] && ((const unsigned *)args->hit)[5 * args->N + i] == sc->skip_sphere)
            args->valid[i] = 0;
}

int cdl_scene_commit(cdl_scene *s, cdl_error *err)
{
    if (s->open_group >= 0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "a shape group is still open");
    if (s->ntris == 0 && s->nspheres == 0 && s->ninsts == 0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "scene has no (non-degenerate) triangles");
    cdl_vec3 lo = cdl_v3(FLT_MAX, FLT_MAX, FLT_MAX), hi = cdl_scale(lo, -1.0f);
    for (uint32_t i = 0; i < 3 * s->ntris; i++) {
        const float *p = s->pos + 3 * (size_t)s->idx[i];
        lo = cdl_v3(fminf(lo.x, p[0]), fminf(lo.y, p[1]), fminf(lo.z, p[2]));
        hi = cdl_v3(fmaxf(hi.x, p[0]), fmaxf(hi.y, p[1]), fmaxf(hi.z, p[2]));
    }
    for (uint32_t i = 0; i < s->nspheres; i++) {
        const float *q = s->sph + 4 * (size_t)i;
        lo = cdl_v3(fminf(lo.x, q[0] - q[3]), fminf(lo.y, q[1] - q[3]), fminf(lo.z, q[2] - q[3]));
        hi = cdl_v3(fmaxf(hi.x, q[0] + q[3]), fmaxf(hi.y, q[1] + q[3]), fmaxf(hi.z, q[2] + q[3]));
    }
    cdl_instances_bounds(s, &lo, &hi);
    cdl_attrs_commit(s);
    s->bmin = lo;
    s->bmax = hi;
    s->eps = 1e-6f * cdl_max3(cdl_sub(hi, lo));
    int rc = build_lights(s, err);
    if (rc)
        return rc;

    s->rtc = rtcNewScene(s->device);
    if (!s->rtc)
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create the scene");
    rtcSetSceneBuildQuality(s->rtc, RTC_BUILD_QUALITY_HIGH);
    /* Geometry ids are fixed (CDL_GEOM_*) even when a kind is absent. */
    RTCGeometry g;
    if (s->ntris) {
        g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!g)
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create a mesh");
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s->pos, 0,
                                   3 * sizeof(float), s->nverts);
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, s->idx, 0,
                                   3 * sizeof(uint32_t), s->ntris);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s->rtc, g, CDL_GEOM_TRIANGLES);
        rtcReleaseGeometry(g);
    }
    if (s->nspheres) {
        g = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        if (!g)
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create spheres");
        rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, s->sph, 0,
                                   4 * sizeof(float), s->nspheres);
        rtcSetGeometryOccludedFilterFunction(g, skip_target_sphere);
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(s->rtc, g, CDL_GEOM_SPHERES);
        rtcReleaseGeometry(g);
    }
    if ((rc = cdl_instances_commit(s, err)))
        return rc;
    rtcCommitScene(s->rtc);
    enum RTCError e = rtcGetDeviceError(s->device);
    if (e != RTC_ERROR_NONE)
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree failed to build the scene (error %d)", (int)e);
    return 0;
}

void cdl_intersect_packet(const cdl_scene *s, int n, const cdl_vec3 *o, const cdl_vec3 *d,
                          cdl_hit *h, uint8_t *found)
{
    if (s->ninsts) {
        for (int i = 0; i < n; i++)
            found[i] = (uint8_t)cdl_intersect(s, o[i], d[i], FLT_MAX, &h[i]);
        return;
    }
    struct RTCRayHit16 rh;
    _Alignas(64) int valid[16]; /* Embree reads it with aligned loads */
    for (int i = 0; i < 16; i++) {
        int k = i < n ? i : 0; /* inactive lanes copy ray 0: no garbage in the packet */
        valid[i] = i < n ? -1 : 0;
        rh.ray.org_x[i] = o[k].x;
        rh.ray.org_y[i] = o[k].y;
        rh.ray.org_z[i] = o[k].z;
        rh.ray.dir_x[i] = d[k].x;
        rh.ray.dir_y[i] = d[k].y;
        rh.ray.dir_z[i] = d[k].z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.tfar[i] = FLT_MAX;
        rh.ray.mask[i] = 0xFFFFFFFFu;
        rh.ray.flags[i] = 0;
        rh.ray.time[i] = 0.0f;
        rh.ray.id[i] = (unsigned)i;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    rtcIntersect16(valid, s->rtc, &ctx, &rh);
    for (int i = 0; i < n; i++) {
        found[i] = rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        if (!found[i])
            continue;
        h[i].t = rh.ray.tfar[i];
        h[i].b1 = rh.hit.u[i];
        h[i].b2 = rh.hit.v[i];
        h[i].prim = rh.hit.primID[i];
        h[i].geom = rh.hit.geomID[i];
        h[i].inst = CDL_NO_INST;
        h[i].ng = cdl_v3(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]);
        h[i].d = d[i];
    }
}

void cdl_occluded_packet(const cdl_scene *s, int n, const cdl_vec3 *o, const cdl_vec3 *d,
                         const float *tmax, const uint32_t *skip, uint8_t *blocked)
{
    int same = 1;
    for (int i = 1; i < n; i++)
        same &= skip[i] == skip[0];
    if (n < 2 || !same || s->ninsts) {
        for (int i = 0; i < n; i++)
            blocked[i] = (uint8_t)cdl_occluded_skip(s, o[i], d[i], tmax[i], skip[i]);
        return;
    }
    struct RTCRay16 r;
    _Alignas(64) int valid[16]; /* Embree reads it with aligned loads */
    for (int i = 0; i < 16; i++) {
        int k = i < n ? i : 0; /* inactive lanes copy ray 0 */
        valid[i] = i < n ? -1 : 0;
        r.org_x[i] = o[k].x;
        r.org_y[i] = o[k].y;
        r.org_z[i] = o[k].z;
        r.dir_x[i] = d[k].x;
        r.dir_y[i] = d[k].y;
        r.dir_z[i] = d[k].z;
        r.tnear[i] = 0.0f;
        r.tfar[i] = tmax[k];
        r.mask[i] = 0xFFFFFFFFu;
        r.flags[i] = 0;
        r.time[i] = 0.0f;
        r.id[i] = (unsigned)i;
    }
    cdl_shadow_ctx sc;
    rtcInitIntersectContext(&sc.ctx);
    sc.ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    sc.skip_sphere = skip[0];
    rtcOccluded16(valid, s->rtc, &sc.ctx, &r);
    for (int i = 0; i < n; i++)
        blocked[i] = r.tfar[i] < 0.0f;
}

void cdl_occluded_bundle(const cdl_scene *s, uint32_t n, const cdl_vec3 *o,
                         const cdl_vec3 *d, const float *tmax, uint32_t skip_sphere,
                         uint8_t *blocked)
{
    enum { CHUNK = 64 };
    struct RTCRay rays[CHUNK];
    cdl_shadow_ctx sc;
    rtcInitIntersectContext(&sc.ctx);
    /* coherent streams through Embree 3's instances can take minutes (seen
     * in splat's packets and gkde's links): incoherent there */
    sc.ctx.flags = s->ninsts ? RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT : RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    sc.skip_sphere = skip_sphere;
    for (uint32_t base = 0; base < n; base += CHUNK) {
        uint32_t m = n - base < CHUNK ? n - base : CHUNK;
        for (uint32_t i = 0; i < m; i++) {
            struct RTCRay *r = &rays[i];
            r->org_x = o[base + i].x;
            r->org_y = o[base + i].y;
            r->org_z = o[base + i].z;
            r->dir_x = d[base + i].x;
            r->dir_y = d[base + i].y;
            r->dir_z = d[base + i].z;
            r->tnear = 0.0f;
            r->tfar = tmax[base + i];
            r->mask = 0xFFFFFFFFu;
            r->flags = 0;
            r->time = 0.0f;
        }
        rtcOccluded1M(s->rtc, &sc.ctx, rays, m, sizeof(struct RTCRay));
        for (uint32_t i = 0; i < m; i++)
            blocked[base + i] = rays[i].tfar < 0.0f;
    }
}

/* dp/du and dp/dv of a triangle from its uv (Mitsuba's and pbrt's
 * solution of the 2x2 system); zero where the uv are degenerate. */
static void tri_partials(const float *p0, const float *p1, const float *p2, const float *u0, const float *u1,
                         const float *u2, cdl_surface *sf)
{
    float du0 = u1[0] - u0[0], dv0 = u1[1] - u0[1], du1 = u2[0] - u0[0], dv1 = u2[1] - u0[1];
    cdl_vec3 e0 = cdl_v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]);
    cdl_vec3 e1 = cdl_v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]);
    float det = du0 * dv1 - dv0 * du1;
    if (det == 0.0f || !isfinite(1.0f / det))
        return;
    float inv = 1.0f / det;
    sf->dpdu = cdl_scale(cdl_sub(cdl_scale(e0, dv1), cdl_scale(e1, dv0)), inv);
    sf->dpdv = cdl_scale(cdl_sub(cdl_scale(e1, du0), cdl_scale(e0, du1)), inv);
}

void cdl_sphere_surface(const float *q, int inward, cdl_vec3 ng, cdl_surface *sf)
{
    cdl_vec3 c = cdl_v3(q[0], q[1], q[2]);
    cdl_vec3 n = cdl_normalize(ng);
    if (inward)
        n = cdl_neg(n);
    /* the point on the analytic surface, not o + t d with its rounding */
    cdl_vec3 out = inward ? cdl_neg(n) : n;
    sf->p = cdl_madd(c, out, q[3]);
    sf->ng = sf->ns = n;
    sf->u = 0.5f + atan2f(out.z, out.x) * (0.5f * CDL_INV_PI);
    sf->v = acosf(cdl_maxf(-1.0f, cdl_minf(1.0f, out.y))) * CDL_INV_PI;
    /* p = c + r (sin th cos ph, cos th, sin th sin ph), ph = 2 pi (u - 1/2), th = pi v */
    float st = sqrtf(cdl_maxf(0.0f, 1.0f - out.y * out.y)), r = q[3];
    float cp = st > 0.0f ? out.x / st : 1.0f, sp = st > 0.0f ? out.z / st : 0.0f;
    sf->dpdu = cdl_scale(cdl_v3(-st * sp, 0.0f, st * cp), 2.0f * CDL_PI * r);
    sf->dpdv = cdl_scale(cdl_v3(out.y * cp, -st, out.y * sp), CDL_PI * r);
    sf->geom = CDL_GEOM_SPHERES;
}

static inline void triangle_surface(const cdl_scene *s, const uint32_t *t, uint8_t fl, cdl_vec3 face_n, float b1,
                                    float b2, cdl_surface *sf)
{
    float b0 = 1.0f - b1 - b2;
    const float *p0 = s->pos + 3 * (size_t)t[0], *p1 = s->pos + 3 * (size_t)t[1],
                *p2 = s->pos + 3 * (size_t)t[2];
    cdl_vec3 p, ns;
    cdl_triangle_point(s, t, fl, face_n, b1, b2, &p, &ns);
    /* stored once, from registers: copying sf->ng to sf->ns read back
     * parts of two stores, a failed store forward on path's chain */
    sf->p = p;
    sf->ng = face_n;
    sf->ns = ns;
    sf->u = sf->v = 0.0f;
    sf->dpdu = sf->dpdv = cdl_v3(0.0f, 0.0f, 0.0f);
    if (fl & CDL_TRI_HAS_UV) {
        const float *u0 = s->uv + 2 * (size_t)t[0], *u1 = s->uv + 2 * (size_t)t[1],
                    *u2 = s->uv + 2 * (size_t)t[2];
        sf->u = b0 * u0[0] + b1 * u1[0] + b2 * u2[0];
        sf->v = b0 * u0[1] + b1 * u1[1] + b2 * u2[1];
        tri_partials(p0, p1, p2, u0, u1, u2, sf);
    }
    sf->geom = CDL_GEOM_TRIANGLES;
}

void cdl_triangle_surface(const cdl_scene *s, const uint32_t *t, uint8_t fl, cdl_vec3 face_n, float b1, float b2,
                          cdl_surface *sf)
{
    triangle_surface(s, t, fl, face_n, b1, b2, sf);
}

void cdl_surface_at_any(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf)
{
    if (h->inst != CDL_NO_INST) {
        cdl_instance_surface(s, h, sf);
    } else if (h->geom == CDL_GEOM_SPHERES) {
        cdl_sphere_surface(s->sph + 4 * (size_t)h->prim, s->sph_inward[h->prim], h->ng, sf);
        sf->mat = s->sph_mat[h->prim];
        sf->light = s->sph_light[h->prim];
    } else {
        triangle_surface(s, s->idx + 3 * (size_t)h->prim, s->tri_flags[h->prim], s->face_n[h->prim], h->b1, h->b2,
                         sf);
        sf->mat = s->tri_mat[h->prim];
        sf->light = s->tri_light[h->prim];
    }
    sf->prim = h->prim;
    const cdl_material *m = &s->mats[sf->mat];
    if (m->type == CDL_MAT_BLEND || m->hit_kd) {
        cdl_surface_material(s, h, sf);
        m = &s->mats[sf->mat];
    } else {
        sf->kdh = cdl_v3(1.0f, 1.0f, 1.0f); /* as cdl_surface_material leaves it */
    }
    if (cdl_mat_uses_tangent(&m->maps, m->alpha_x, m->alpha_y)) {
        cdl_surface_shade(s, sf, cdl_neg(h->d));
    } else { /* as cdl_surface_shade leaves it */
        sf->nb = sf->ns;
        sf->ts = cdl_v3(0.0f, 0.0f, 0.0f);
    }
}

void cdl_scene_bsdf_any(const cdl_scene *s, const cdl_surface *sf, cdl_bsdf *b)
{
    const cdl_material *m = &s->mats[sf->mat];
    cdl_vec3 kd = m->kd;
    if (m->hit_kd)
        kd = cdl_mul(kd, sf->kdh);
    else if (m->kd_tex >= 0)
        kd = cdl_mul(kd, cdl_texture_eval(s->texs, m->kd_tex, sf->u, sf->v));
    cdl_bsdf_init(b, m, kd, sf->ns, sf->ng);
    if (m->masked && m->opacity_tex >= 0)
        b->opacity *= cdl_minf(1.0f, cdl_maxf(0.0f, cdl_texture_eval1(s->texs, m->opacity_tex, sf->u, sf->v)));
    cdl_scene_bsdf_maps(s, m, sf, b);
    if (m->type == CDL_MAT_PRINCIPLED) {
        cdl_principled_at_init(&b->pr, &m->pr, s->texs, sf->u, sf->v);
        /* the shading tangent the vertex store keeps too, else dp/du */
        cdl_principled_tangent(b, cdl_is_black(sf->ts) ? sf->dpdu : sf->ts);
    }
}
