/* Shape groups and instances (instance.h). */
#include "scene/instance.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/grow.h"

int cdl_scene_group_begin(cdl_scene *s, uint32_t *id, cdl_error *err)
{
    if (s->open_group >= 0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "shape groups do not nest");
    if (s->ngroups >= (uint32_t)INT32_MAX ||
        cdl_grow((void **)&s->groups, &s->cap_groups, s->ngroups + 1, sizeof(cdl_group)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for shape groups");
    cdl_group *g = &s->groups[s->ngroups];
    memset(g, 0, sizeof *g);
    g->first_tri = s->ntris;
    g->first_sph = s->nspheres;
    *id = s->ngroups;
    s->open_group = (int32_t)s->ngroups++;
    return 0;
}

/* A copy of items first .. first + n of size sz from the array base (NULL
 * when n is 0, and base is not touched: it may be NULL); 0 on success. */
static int take(void **out, const void *base, uint32_t first, uint32_t n, size_t sz)
{
    *out = NULL;
    if (!n)
        return 0;
    *out = malloc(sz * n);
    if (!*out)
        return -1;
    memcpy(*out, (const char *)base + sz * first, sz * n);
    return 0;
}

static void grow_box(cdl_vec3 *lo, cdl_vec3 *hi, cdl_vec3 p, float r)
{
    *lo = cdl_v3(fminf(lo->x, p.x - r), fminf(lo->y, p.y - r), fminf(lo->z, p.z - r));
    *hi = cdl_v3(fmaxf(hi->x, p.x + r), fmaxf(hi->y, p.y + r), fmaxf(hi->z, p.z + r));
}

int cdl_scene_group_end(cdl_scene *s, cdl_error *err)
{
    if (s->open_group < 0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "no shape group is open");
    cdl_group *g = &s->groups[s->open_group];
    uint32_t nt = s->ntris - g->first_tri, ns = s->nspheres - g->first_sph;
    if (take((void **)&g->idx, s->idx, g->first_tri, nt, 3 * sizeof(uint32_t)) ||
        take((void **)&g->tri_mat, s->tri_mat, g->first_tri, nt, sizeof(uint32_t)) ||
        take((void **)&g->tri_flags, s->tri_flags, g->first_tri, nt, sizeof(uint8_t)) ||
        take((void **)&g->sph, s->sph, g->first_sph, ns, 4 * sizeof(float)) ||
        take((void **)&g->sph_mat, s->sph_mat, g->first_sph, ns, sizeof(uint32_t)) ||
        take((void **)&g->sph_inward, s->sph_inward, g->first_sph, ns, sizeof(uint8_t)) ||
        (nt && !(g->face_n = malloc(sizeof(cdl_vec3) * nt))))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for a shape group");
    g->ntris = nt;
    g->nspheres = ns;
    /* the top level gives the shapes back; the vertices stay where they are */
    s->ntris = g->first_tri;
    s->nspheres = g->first_sph;
    s->open_group = -1;
    g->bmin = cdl_v3(FLT_MAX, FLT_MAX, FLT_MAX);
    g->bmax = cdl_scale(g->bmin, -1.0f);
    for (uint32_t i = 0; i < nt; i++) {
        const uint32_t *t = g->idx + 3 * (size_t)i;
        cdl_vec3 p[3];
        for (int k = 0; k < 3; k++) {
            const float *q = s->pos + 3 * (size_t)t[k];
            p[k] = cdl_v3(q[0], q[1], q[2]);
            grow_box(&g->bmin, &g->bmax, p[k], 0.0f);
        }
        g->face_n[i] = cdl_normalize(cdl_cross(cdl_sub(p[1], p[0]), cdl_sub(p[2], p[0])));
    }
    for (uint32_t i = 0; i < ns; i++) {
        const float *q = g->sph + 4 * (size_t)i;
        grow_box(&g->bmin, &g->bmax, cdl_v3(q[0], q[1], q[2]), q[3]);
    }
    return 0;
}

int cdl_scene_add_instance(cdl_scene *s, uint32_t group, const cdl_mat4 *xf, cdl_error *err)
{
    if (group >= s->ngroups || (int32_t)group == s->open_group)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "instance of an unknown or unfinished shape group");
    cdl_mat4 inv;
    if (!cdl_mat4_is_finite(xf) || cdl_mat4_inverse(xf, &inv))
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the instance's transform is singular or not finite");
    if (xf->m[3][0] != 0.0 || xf->m[3][1] != 0.0 || xf->m[3][2] != 0.0 || xf->m[3][3] != 1.0)
        return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the instance's transform is projective");
    for (int r = 0; r < 3; r++)
        if (fabs(xf->m[r][3]) > CDL_MAX_COORD)
            return cdl_error_set(err, CDL_ERR_INPUT, s->path, 0, "the instance is moved beyond 1e20");
    if (s->ninsts >= UINT32_MAX - CDL_GEOM_INSTANCE0 ||
        cdl_grow((void **)&s->insts, &s->cap_insts, s->ninsts + 1, sizeof(cdl_instance)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory for instances");
    cdl_instance *in = &s->insts[s->ninsts++];
    in->group = group;
    for (int r = 0; r < 3; r++)
        for (int k = 0; k < 4; k++)
            in->xf[4 * r + k] = (float)xf->m[r][k];
    for (int r = 0; r < 3; r++) /* (M^-1)^T */
        for (int k = 0; k < 3; k++)
            in->nm[3 * r + k] = (float)inv.m[k][r];
    return 0;
}

static cdl_vec3 xf_point(const float *m, cdl_vec3 p)
{
    return cdl_v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                  m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* a tangent vector (dp/du): the linear part alone */
static cdl_vec3 xf_vector(const float *m, cdl_vec3 v)
{
    return cdl_v3(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                  m[8] * v.x + m[9] * v.y + m[10] * v.z);
}

static cdl_vec3 xf_normal(const float *n, cdl_vec3 v)
{
    return cdl_normalize(cdl_v3(n[0] * v.x + n[1] * v.y + n[2] * v.z, n[3] * v.x + n[4] * v.y + n[5] * v.z,
                                n[6] * v.x + n[7] * v.y + n[8] * v.z));
}

void cdl_instances_bounds(const cdl_scene *s, cdl_vec3 *lo, cdl_vec3 *hi)
{
    for (uint32_t i = 0; i < s->ninsts; i++) {
        const cdl_instance *in = &s->insts[i];
        const cdl_group *g = &s->groups[in->group];
        if (g->ntris == 0 && g->nspheres == 0)
            continue;
        for (int c = 0; c < 8; c++) {
            cdl_vec3 p = cdl_v3(c & 1 ? g->bmax.x : g->bmin.x, c & 2 ? g->bmax.y : g->bmin.y,
                                c & 4 ? g->bmax.z : g->bmin.z);
            grow_box(lo, hi, xf_point(in->xf, p), 0.0f);
        }
    }
}

static int group_commit(cdl_scene *s, cdl_group *g, cdl_error *err)
{
    g->rtc = rtcNewScene(s->device);
    if (!g->rtc)
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create a group's scene");
    rtcSetSceneBuildQuality(g->rtc, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geo;
    if (g->ntris) {
        if (!(geo = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_TRIANGLE)))
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create a mesh");
        /* all of the scene's vertices, shared with the top level and the other groups */
        rtcSetSharedGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, s->pos, 0, 3 * sizeof(float),
                                   s->nverts);
        rtcSetSharedGeometryBuffer(geo, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, g->idx, 0, 3 * sizeof(uint32_t),
                                   g->ntris);
        rtcCommitGeometry(geo);
        rtcAttachGeometryByID(g->rtc, geo, CDL_GEOM_TRIANGLES);
        rtcReleaseGeometry(geo);
    }
    if (g->nspheres) {
        if (!(geo = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_SPHERE_POINT)))
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create spheres");
        /* no shadow-ray filter: spheres in groups are never the light a ray aims at */
        rtcSetSharedGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, g->sph, 0, 4 * sizeof(float),
                                   g->nspheres);
        rtcCommitGeometry(geo);
        rtcAttachGeometryByID(g->rtc, geo, CDL_GEOM_SPHERES);
        rtcReleaseGeometry(geo);
    }
    rtcCommitScene(g->rtc);
    return 0;
}

int cdl_instances_commit(cdl_scene *s, cdl_error *err)
{
    for (uint32_t i = 0; i < s->ninsts; i++) {
        const cdl_instance *in = &s->insts[i];
        cdl_group *g = &s->groups[in->group];
        if (g->ntris == 0 && g->nspheres == 0)
            continue; /* an empty group: nothing to hit */
        int rc;
        if (!g->rtc && (rc = group_commit(s, g, err)))
            return rc;
        RTCGeometry geo = rtcNewGeometry(s->device, RTC_GEOMETRY_TYPE_INSTANCE);
        if (!geo)
            return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "Embree could not create an instance");
        rtcSetGeometryInstancedScene(geo, g->rtc);
        rtcSetGeometryTransform(geo, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, in->xf);
        rtcCommitGeometry(geo);
        rtcAttachGeometryByID(s->rtc, geo, CDL_GEOM_INSTANCE0 + i);
        rtcReleaseGeometry(geo);
    }
    return 0;
}

void cdl_instances_free(cdl_scene *s)
{
    for (uint32_t i = 0; i < s->ngroups; i++) {
        cdl_group *g = &s->groups[i];
        if (g->rtc)
            rtcReleaseScene(g->rtc);
        free(g->idx);
        free(g->tri_mat);
        free(g->tri_flags);
        free(g->face_n);
        free(g->sph);
        free(g->sph_mat);
        free(g->sph_inward);
    }
    free(s->groups);
    free(s->insts);
    s->groups = NULL;
    s->insts = NULL;
    s->ngroups = s->ninsts = s->cap_groups = s->cap_insts = 0;
}

void cdl_instance_surface(const cdl_scene *s, const cdl_hit *h, cdl_surface *sf)
{
    const cdl_instance *in = &s->insts[h->inst];
    const cdl_group *g = &s->groups[in->group];
    if (h->geom == CDL_GEOM_SPHERES) {
        cdl_sphere_surface(g->sph + 4 * (size_t)h->prim, g->sph_inward[h->prim], h->ng, sf);
        sf->mat = g->sph_mat[h->prim];
    } else {
        cdl_triangle_surface(s, g->idx + 3 * (size_t)h->prim, g->tri_flags[h->prim], g->face_n[h->prim], h->b1,
                             h->b2, sf);
        sf->mat = g->tri_mat[h->prim];
    }
    /* object to world: normals by the inverse transpose, which keeps a
     * normal on the side it was on under mirroring transforms too */
    sf->p = xf_point(in->xf, sf->p);
    sf->ng = xf_normal(in->nm, sf->ng);
    sf->ns = xf_normal(in->nm, sf->ns);
    sf->dpdu = xf_vector(in->xf, sf->dpdu);
    sf->dpdv = xf_vector(in->xf, sf->dpdv);
    sf->prim = h->prim;
    sf->light = -1;
}
