#include "scene/attr.h"

#include <stdlib.h>
#include <string.h>

#include "core/grow.h"
#include "core/rng.h"
#include "scene/instance.h"

int cdl_scene_attr_wanted(const cdl_scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->ntexs; i++)
        if (s->texs[i].type == CDL_TEX_ATTRIBUTE && !strcmp(s->texs[i].attr, name))
            return 1;
    return 0;
}

/* The attribute texture tex reads (itself or scaled), or -1. */
static int attr_tex(const cdl_scene *s, int tex)
{
    if (tex >= 0 && s->texs[tex].type == CDL_TEX_SCALE)
        tex = s->texs[tex].sub[0];
    return tex >= 0 && s->texs[tex].type == CDL_TEX_ATTRIBUTE ? tex : -1;
}

/* Checks texture tex (if an attribute) against m; the name when missing. */
static const char *tex_missing(const cdl_scene *s, int tex, const cdl_mesh *m, int *face)
{
    if ((tex = attr_tex(s, tex)) < 0)
        return NULL;
    const char *name = s->texs[tex].attr;
    for (int k = 0; m && k < m->nattrs; k++)
        if (!strcmp(m->attrs[k].name, name)) {
            *face |= m->attrs[k].per_face;
            return NULL;
        }
    return name;
}

const char *cdl_material_missing_attr(const cdl_scene *s, uint32_t mat, const cdl_mesh *m, int *face)
{
    const cdl_material *x = &s->mats[mat];
    const char *miss = tex_missing(s, x->kd_tex, m, face);
    if (!miss && x->type == CDL_MAT_BLEND) {
        miss = tex_missing(s, x->blend_tex, m, face);
        for (int k = 0; k < 2 && !miss; k++) /* children precede: this ends */
            miss = cdl_material_missing_attr(s, (uint32_t)x->blend[k], m, face);
    }
    return miss;
}

static int push_attr(cdl_scene *s, const cdl_mesh_attr *ma, uint32_t first, uint32_t count, float *data,
                     const char *file, int line, cdl_error *err)
{
    if (s->nattrs == s->cap_attrs && cdl_grow((void **)&s->attrs, &s->cap_attrs, s->nattrs + 1, sizeof *s->attrs)) {
        free(data);
        return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory for mesh attributes");
    }
    cdl_attr *a = &s->attrs[s->nattrs];
    memset(a, 0, sizeof *a);
    memcpy(a->name, ma->name, sizeof a->name);
    a->per_face = ma->per_face;
    a->dim = ma->dim;
    a->first = first;
    a->count = count;
    a->data = data;
    a->key = (int)s->nattrs;
    for (uint32_t i = 0; i < s->nattrs; i++)
        if (!strcmp(s->attrs[i].name, a->name)) {
            a->key = s->attrs[i].key;
            break;
        }
    s->nattrs++;
    return 0;
}

int cdl_scene_add_attrs(cdl_scene *s, const cdl_mesh *m, uint32_t first_vert, const uint32_t *tri_of,
                        const char *file, int line, cdl_error *err)
{
    for (int k = 0; k < m->nattrs; k++) {
        const cdl_mesh_attr *ma = &m->attrs[k];
        if (!cdl_scene_attr_wanted(s, ma->name))
            continue;
        size_t dim = (size_t)ma->dim;
        if (!ma->per_face) {
            float *d = malloc(sizeof(float) * dim * (m->nverts ? m->nverts : 1));
            if (!d)
                return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory for mesh attributes");
            memcpy(d, ma->data, sizeof(float) * dim * m->nverts);
            int rc = push_attr(s, ma, first_vert, m->nverts, d, file, line, err);
            if (rc)
                return rc;
            continue;
        }
        /* the scene's triangles of this mesh are consecutive, some dropped */
        uint32_t lo = UINT32_MAX, hi = 0;
        for (uint32_t t = 0; t < m->ntris; t++)
            if (tri_of[t] != UINT32_MAX) {
                lo = tri_of[t] < lo ? tri_of[t] : lo;
                hi = tri_of[t] + 1 > hi ? tri_of[t] + 1 : hi;
            }
        if (lo == UINT32_MAX)
            continue;
        float *d = calloc(dim * (hi - lo), sizeof(float));
        if (!d)
            return cdl_error_set(err, CDL_ERR_SYSTEM, file, line, "out of memory for mesh attributes");
        for (uint32_t t = 0; t < m->ntris; t++)
            if (tri_of[t] != UINT32_MAX)
                memcpy(d + dim * (tri_of[t] - lo), ma->data + dim * t, sizeof(float) * dim);
        int rc = push_attr(s, ma, lo, hi - lo, d, file, line, err);
        if (rc)
            return rc;
    }
    return 0;
}

void cdl_attrs_free(cdl_scene *s)
{
    for (uint32_t i = 0; i < s->nattrs; i++)
        free(s->attrs[i].data);
    free(s->attrs);
    s->attrs = NULL;
    s->nattrs = s->cap_attrs = 0;
}

void cdl_attrs_commit(cdl_scene *s)
{
    for (uint32_t i = 0; i < s->ntexs; i++) {
        cdl_texture *t = &s->texs[i];
        if (t->type != CDL_TEX_ATTRIBUTE)
            continue;
        t->attr_key = -1;
        for (uint32_t k = 0; k < s->nattrs && t->attr_key < 0; k++)
            if (!strcmp(s->attrs[k].name, t->attr))
                t->attr_key = s->attrs[k].key;
    }
    for (uint32_t i = 0; i < s->nmats; i++) {
        cdl_material *m = &s->mats[i];
        if (m->type != CDL_MAT_BLEND && attr_tex(s, m->kd_tex) >= 0)
            m->hit_kd = 1;
    }
}

static cdl_vec3 attr_value(const cdl_attr *a, uint32_t i)
{
    const float *v = a->data + (size_t)a->dim * i;
    return a->dim == 1 ? cdl_v3(v[0], v[0], v[0]) : cdl_v3(v[0], v[1], a->dim > 2 ? v[2] : 0.0f);
}

/* Attribute `key` at a hit on triangle t (scene vertex indices; prim: the
 * scene's triangle, UINT32_MAX inside an instance); 0 where the shape has
 * none. */
static cdl_vec3 attr_at(const cdl_scene *s, int key, const uint32_t *t, uint32_t prim, float b1, float b2)
{
    for (uint32_t i = key < 0 ? s->nattrs : (uint32_t)key; t && i < s->nattrs; i++) {
        const cdl_attr *a = &s->attrs[i];
        if (a->key != key)
            continue;
        if (a->per_face) {
            if (prim - a->first < a->count)
                return attr_value(a, prim - a->first);
        } else if (t[0] - a->first < a->count && t[1] - a->first < a->count && t[2] - a->first < a->count) {
            cdl_vec3 v = cdl_scale(attr_value(a, t[0] - a->first), 1.0f - b1 - b2);
            v = cdl_madd(v, attr_value(a, t[1] - a->first), b1);
            return cdl_madd(v, attr_value(a, t[2] - a->first), b2);
        }
    }
    return cdl_v3(0.0f, 0.0f, 0.0f);
}

typedef struct hit_at {
    const uint32_t *t; /* the triangle's vertices, or NULL (a sphere) */
    uint32_t prim;     /* the scene's triangle, or UINT32_MAX */
    float b1, b2;
} hit_at;

static cdl_vec3 tex_at(const cdl_scene *s, int tex, const cdl_surface *sf, const hit_at *h)
{
    const cdl_texture *t = &s->texs[tex];
    if (t->type == CDL_TEX_SCALE && t->sub[0] >= 0 && s->texs[t->sub[0]].type == CDL_TEX_ATTRIBUTE) {
        cdl_vec3 b = t->sub[1] >= 0 ? cdl_texture_eval(s->texs, t->sub[1], sf->u, sf->v) : t->b;
        return cdl_scale(cdl_mul(tex_at(s, t->sub[0], sf, h), b), t->scale);
    }
    if (t->type == CDL_TEX_ATTRIBUTE)
        return cdl_scale(attr_at(s, t->attr_key, h->t, h->prim, h->b1, h->b2), t->scale);
    return cdl_texture_eval(s->texs, tex, sf->u, sf->v);
}

static cdl_vec3 kd_at(const cdl_scene *s, const cdl_material *m, const cdl_surface *sf, const hit_at *h)
{
    return m->kd_tex >= 0 ? cdl_mul(m->kd, tex_at(s, m->kd_tex, sf, h)) : m->kd;
}

/* A number in [0, 1) fixed by the hit point: the same at every rebuild of
 * the vertex, independent between points. */
static float point_random(cdl_vec3 p, uint32_t prim, int depth)
{
    uint32_t b[3];
    memcpy(b, &p, sizeof b);
    uint64_t z = cdl_mix64(((uint64_t)b[0] << 32 | b[1]) ^ cdl_mix64((uint64_t)b[2] << 32 | prim) ^ (uint64_t)depth);
    return (float)(z >> 40) * 0x1p-24f;
}

void cdl_surface_material(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf)
{
    sf->kdh = cdl_v3(1.0f, 1.0f, 1.0f);
    const cdl_material *m = &s->mats[sf->mat];
    if (m->type != CDL_MAT_BLEND && !m->hit_kd)
        return;
    hit_at at = {NULL, UINT32_MAX, h->b1, h->b2};
    if (h->geom != CDL_GEOM_SPHERES) {
        if (h->inst == CDL_NO_INST) {
            at.t = s->idx + 3 * (size_t)h->prim;
            at.prim = h->prim;
        } else {
            at.t = s->groups[s->insts[h->inst].group].idx + 3 * (size_t)h->prim;
        }
    }
    /* ends: a blend's materials precede it (cdl_scene_add_material) */
    for (int depth = 0; m->type == CDL_MAT_BLEND; depth++) {
        float w = m->blend_w;
        if (m->blend_tex >= 0)
            w *= cdl_tex_luminance(tex_at(s, m->blend_tex, sf, &at));
        w = w > 0.0f ? (w < 1.0f ? w : 1.0f) : 0.0f;
        if (m->blend_as >= 0) {
            sf->kdh = cdl_add(cdl_scale(kd_at(s, &s->mats[m->blend[0]], sf, &at), 1.0f - w),
                              cdl_scale(kd_at(s, &s->mats[m->blend[1]], sf, &at), w));
            sf->mat = (uint32_t)m->blend_as;
            return;
        }
        /* (1 - w) f0 + w f1 in expectation over the points of a pixel */
        sf->mat = (uint32_t)m->blend[point_random(sf->p, h->prim, depth) < w];
        m = &s->mats[sf->mat];
    }
    if (m->hit_kd)
        sf->kdh = tex_at(s, m->kd_tex, sf, &at);
}
