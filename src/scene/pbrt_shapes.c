/* pbrt shapes: triangle, bilinear-patch and PLY meshes, spheres (analytic
 * under similarity transforms, tessellated otherwise), and flattened object
 * instances. Orientation follows pbrt-v3 exactly, since area lights emit
 * from the front face only: a triangle's normal is cross(p0 - p2, p1 - p2)
 * (= the CCW normal), turned towards the shading normals when the mesh has
 * N (FaceForward), else flipped by ReverseOrientation XOR a handedness-
 * swapping transform. We store every triangle with its pbrt normal as CCW. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/pbrt_internal.h"
#include "scene/ply.h"

#define SPHERE_NPHI 96
#define SPHERE_NTHETA 48
#define PI 3.14159265358979323846

void cdl_pbrt_shape_free(cdl_pbrt_shape *sh)
{
    free(sh->mesh.p);
    free(sh->mesh.n);
    free(sh->mesh.uv);
    free(sh->mesh.idx);
    memset(sh, 0, sizeof *sh);
}

static int oom(cdl_pbrt_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
}

static int mesh_alloc(cdl_pbrt_ctx *c, cdl_pbrt_mesh *m, uint32_t nv, uint32_t nt, int has_n, int has_uv)
{
    m->nv = nv;
    m->nt = nt;
    m->p = malloc(sizeof(float) * 3 * (size_t)nv);
    m->idx = malloc(sizeof(uint32_t) * 3 * (size_t)(nt ? nt : 1));
    m->n = has_n ? malloc(sizeof(float) * 3 * (size_t)nv) : NULL;
    m->uv = has_uv ? malloc(sizeof(float) * 2 * (size_t)nv) : NULL;
    if (!m->p || !m->idx || (has_n && !m->n) || (has_uv && !m->uv))
        return oom(c);
    return 0;
}

/* trianglemesh (quads = 0) or pbrt-v4 bilinearmesh (quads = 1, split
 * into two triangles (p00, p10, p11), (p00, p11, p01) that keep the
 * patch's normal cross(dp/du, dp/dv)). */
static int read_mesh(cdl_pbrt_ctx *c, int quads, cdl_pbrt_mesh *m)
{
    cdl_pbrt_params *ps = &c->ps;
    const char *what = quads ? "bilinearmesh" : "trianglemesh";
    size_t per = quads ? 4 : 3;
    cdl_pbrt_param *P = cdl_pbrt_find(ps, "P"), *I = cdl_pbrt_find(ps, "indices");
    cdl_pbrt_param *N = cdl_pbrt_find(ps, "N"), *UV = cdl_pbrt_find(ps, "uv");
    if (!UV)
        UV = cdl_pbrt_find(ps, "st"); /* pbrt-v3's other name */
    cdl_pbrt_find(ps, "S");           /* tangents: shading frames are built from N */
    cdl_pbrt_find(ps, "faceIndices");
    if (!P)
        return cdl_pbrt_error(c, c->line, "%s needs \"point3 P\"", what);
    if (P->type != CDL_PT_POINT3)
        return cdl_pbrt_error(c, P->line, "%s: P must be point3, not %s", what, P->tname);
    if (P->n == 0 || P->n / 3 >= UINT32_MAX / 4)
        return cdl_pbrt_error(c, P->line, "%s: P has %zu points", what, P->n / 3);
    uint32_t nv = (uint32_t)(P->n / 3);
    static const double def4[4] = {0, 1, 2, 3};
    const double *iv = def4;
    size_t ni = per;
    if (I) {
        if (I->type != CDL_PT_INT)
            return cdl_pbrt_error(c, I->line, "%s: indices must be integer, not %s", what, I->tname);
        iv = cdl_pbrt_nums(ps, I);
        ni = I->n;
    } else if (nv != per) {
        return cdl_pbrt_error(c, c->line, "%s needs \"integer indices\" (it has %u points)", what, nv);
    }
    if (ni == 0 || ni % per)
        return cdl_pbrt_error(c, I ? I->line : c->line, "%s: %zu indices is not a multiple of %zu", what,
                              ni, per);
    for (size_t i = 0; i < ni; i++)
        if (iv[i] < 0 || iv[i] >= nv)
            return cdl_pbrt_error(c, I ? I->line : c->line,
                                  "%s: index %g (number %zu) out of range: there are %u points", what,
                                  iv[i], i, nv);
    if (N && (N->type != CDL_PT_NORMAL || N->n != P->n))
        return cdl_pbrt_error(c, N->line, "%s: N must be %u normals (normal3), got %zu %s values", what,
                              nv, N->n, N->tname);
    if (UV && (!(UV->type == CDL_PT_FLOAT || UV->type == CDL_PT_POINT2) || UV->n != 2 * (size_t)nv))
        return cdl_pbrt_error(c, UV->line, "%s: %s must be %u point2 (or 2 floats each), got %zu %s values",
                              what, UV->name, nv, UV->n, UV->tname);
    size_t nt = ni / per * (quads ? 2 : 1);
    if (nt >= UINT32_MAX / 4)
        return cdl_pbrt_error(c, c->line, "%s: too many triangles", what);
    int rc = mesh_alloc(c, m, nv, (uint32_t)nt, N != NULL, UV != NULL);
    if (rc)
        return rc;
    const double *pv = cdl_pbrt_nums(ps, P);
    for (size_t i = 0; i < 3 * (size_t)nv; i++)
        m->p[i] = (float)pv[i];
    if (N) {
        const double *nv3 = cdl_pbrt_nums(ps, N);
        for (size_t i = 0; i < 3 * (size_t)nv; i++)
            m->n[i] = (float)nv3[i];
    }
    if (UV) {
        const double *uv = cdl_pbrt_nums(ps, UV);
        for (size_t i = 0; i < 2 * (size_t)nv; i++)
            m->uv[i] = (float)uv[i];
    }
    uint32_t *t = m->idx;
    for (size_t f = 0; f < ni; f += per) {
        uint32_t a = (uint32_t)iv[f], b = (uint32_t)iv[f + 1], d = (uint32_t)iv[f + 2];
        if (!quads) {
            *t++ = a, *t++ = b, *t++ = d;
        } else {
            uint32_t e = (uint32_t)iv[f + 3]; /* p00 p10 p01 p11 */
            *t++ = a, *t++ = b, *t++ = e;
            *t++ = a, *t++ = e, *t++ = d;
        }
    }
    return 0;
}

static int read_ply(cdl_pbrt_ctx *c, cdl_pbrt_mesh *m)
{
    const char *fn;
    char path[1024];
    int rc = cdl_pbrt_get_string(&c->ps, "filename", NULL, &fn, c->err);
    if (rc)
        return rc;
    if (!fn)
        return cdl_pbrt_error(c, c->line, "plymesh needs \"string filename\"");
    cdl_pbrt_resolve(c, fn, path, sizeof path);
    if ((rc = cdl_pbrt_check_file(c, "plymesh file", path)))
        return rc;
    cdl_ply_mesh ply;
    memset(&ply, 0, sizeof ply);
    if ((rc = cdl_ply_read(path, &ply, c->err)))
        return rc; /* names the PLY file and its problem */
    rc = mesh_alloc(c, m, ply.nverts, ply.ntris, ply.nrm != NULL, ply.uv != NULL);
    if (!rc && (ply.nverts == 0 || ply.ntris == 0))
        rc = cdl_pbrt_error(c, c->line, "plymesh \"%s\" has no triangles", path);
    for (size_t i = 0; !rc && i < 3 * (size_t)ply.ntris; i++)
        if (ply.idx[i] >= ply.nverts)
            rc = cdl_pbrt_error(c, c->line, "plymesh \"%s\": vertex index %u out of range", path, ply.idx[i]);
    for (size_t i = 0; !rc && i < 3 * (size_t)ply.nverts; i++)
        if (!isfinite(ply.pos[i]) || fabsf(ply.pos[i]) > CDL_MAX_COORD || (ply.nrm && !isfinite(ply.nrm[i])))
            rc = cdl_pbrt_error(c, c->line, "plymesh \"%s\": vertex %zu is not finite or beyond 1e20", path,
                                i / 3);
    if (!rc) {
        memcpy(m->p, ply.pos, sizeof(float) * 3 * (size_t)ply.nverts);
        memcpy(m->idx, ply.idx, sizeof(uint32_t) * 3 * (size_t)ply.ntris);
        if (ply.nrm)
            memcpy(m->n, ply.nrm, sizeof(float) * 3 * (size_t)ply.nverts);
        if (ply.uv)
            memcpy(m->uv, ply.uv, sizeof(float) * 2 * (size_t)ply.nverts);
    }
    cdl_ply_free(&ply);
    return rc;
}

/* Object space, radius r; normals point outwards, or inwards when flip. */
static int tessellate_sphere(cdl_pbrt_ctx *c, double r, int flip, cdl_pbrt_mesh *m)
{
    const int np = SPHERE_NPHI, nth = SPHERE_NTHETA;
    int rc = mesh_alloc(c, m, (uint32_t)((np + 1) * (nth + 1)), (uint32_t)(2 * np * nth), 1, 1);
    if (rc)
        return rc;
    float s = flip ? -1.0f : 1.0f;
    for (int j = 0, v = 0; j <= nth; j++) {
        double th = PI * j / nth;
        /* exact poles: their fans degenerate and are dropped, not slivers */
        double st = j == 0 || j == nth ? 0.0 : sin(th), ct = j == 0 ? 1.0 : j == nth ? -1.0 : cos(th);
        for (int i = 0; i <= np; i++, v++) {
            double ph = 2.0 * PI * i / np;
            double n[3] = {st * cos(ph), st * sin(ph), ct};
            for (int k = 0; k < 3; k++) {
                m->p[3 * v + k] = (float)(r * n[k]);
                m->n[3 * v + k] = s * (float)n[k];
            }
            /* pbrt's sphere (u, v): u = phi / 2pi, v = 0 at z = -r */
            m->uv[2 * v] = (float)i / (float)np;
            m->uv[2 * v + 1] = 1.0f - (float)j / (float)nth;
        }
    }
    uint32_t *t = m->idx;
    for (int j = 0; j < nth; j++)
        for (int i = 0; i < np; i++) {
            uint32_t v00 = (uint32_t)(j * (np + 1) + i), v01 = v00 + 1;
            uint32_t v10 = v00 + (uint32_t)(np + 1), v11 = v10 + 1;
            if (j < nth - 1)
                *t++ = v00, *t++ = v10, *t++ = v11;
            if (j > 0)
                *t++ = v00, *t++ = v11, *t++ = v01;
        }
    m->nt = (uint32_t)((t - m->idx) / 3);
    return 0;
}

static int same_point(const float *a, const float *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

static int emit_mesh(cdl_pbrt_ctx *c, const cdl_pbrt_mesh *m, const cdl_mat4 *ctm, int reverse,
                     uint32_t mat, int32_t emit)
{
    cdl_mat4 inv;
    if (m->n && cdl_mat4_inverse(ctm, &inv))
        return cdl_pbrt_error(c, c->line, "the shape's transform is singular");
    float *p = malloc(sizeof(float) * 3 * (size_t)m->nv);
    float *n = m->n ? malloc(sizeof(float) * 3 * (size_t)m->nv) : NULL;
    if (!p || (m->n && !n)) {
        free(p);
        free(n);
        return oom(c);
    }
    int rc = 0;
    for (uint32_t i = 0; i < m->nv && !rc; i++) {
        double in[3] = {m->p[3 * i], m->p[3 * i + 1], m->p[3 * i + 2]}, o[3];
        cdl_mat4_point(ctm, in, o);
        for (int k = 0; k < 3; k++) {
            if (!isfinite(o[k]) || fabs(o[k]) > CDL_MAX_COORD)
                rc = cdl_pbrt_error(c, c->line, "vertex %u is transformed to (%g, %g, %g): not finite or beyond 1e20",
                                    i, o[0], o[1], o[2]);
            p[3 * i + k] = (float)o[k];
        }
        if (n) {
            double nin[3] = {m->n[3 * i], m->n[3 * i + 1], m->n[3 * i + 2]}, no[3];
            cdl_mat4_normal(&inv, nin, no);
            double l = sqrt(no[0] * no[0] + no[1] * no[1] + no[2] * no[2]);
            for (int k = 0; k < 3; k++)
                n[3 * i + k] = l > 0.0 && isfinite(l) ? (float)(no[k] / l) : 0.0f;
        }
    }
    uint32_t first = 0;
    if (!rc)
        rc = cdl_pbrt_scene_rc(c, cdl_scene_add_vertices(c->s, m->nv, p, n, m->uv, &first, c->err));
    int flip_all = reverse ^ cdl_mat4_swaps_handedness(ctm);
    uint8_t flags = (uint8_t)((n ? CDL_TRI_HAS_N : 0) | (m->uv ? CDL_TRI_HAS_UV : 0));
    for (uint32_t t = 0; t < m->nt && !rc; t++) {
        uint32_t a = m->idx[3 * t], b = m->idx[3 * t + 1], d = m->idx[3 * t + 2];
        int flip = flip_all;
        const float *pa = p + 3 * (size_t)a, *pb = p + 3 * (size_t)b, *pd = p + 3 * (size_t)d;
        /* two equal corners: no area (the scene's cross-product test can
         * miss this when the compiler contracts it into FMAs) */
        if (same_point(pa, pb) || same_point(pb, pd) || same_point(pa, pd))
            continue;
        if (n) {
            cdl_vec3 e1 = cdl_v3(pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]);
            cdl_vec3 e2 = cdl_v3(pd[0] - pa[0], pd[1] - pa[1], pd[2] - pa[2]);
            cdl_vec3 s = cdl_v3(0, 0, 0);
            for (int k = 0; k < 3; k++) {
                const float *nk = n + 3 * (size_t)m->idx[3 * t + k];
                s = cdl_add(s, cdl_v3(nk[0], nk[1], nk[2]));
            }
            flip = cdl_dot(cdl_cross(e1, e2), s) < 0.0f;
        }
        if (flip) {
            uint32_t tmp = b;
            b = d;
            d = tmp;
        }
        rc = cdl_pbrt_scene_rc(c, cdl_scene_add_triangle(c->s, first + a, first + b, first + d, mat, emit,
                                                         flags, c->err));
    }
    free(p);
    free(n);
    return rc;
}

/* swap_def: the handedness of the transform the sphere was defined
 * under. pbrt flips a sphere's normal by ReverseOrientation XOR it in
 * object space; an instance transform only carries that normal along. */
static int emit_shape(cdl_pbrt_ctx *c, const cdl_pbrt_shape *sh, const cdl_mat4 *ctm, int reverse,
                      int swap_def, uint32_t mat, int32_t emit)
{
    if (!sh->sphere)
        return emit_mesh(c, &sh->mesh, ctm, reverse, mat, emit);
    double scale;
    int inward = reverse ^ swap_def;
    if (cdl_mat4_is_similarity(ctm, 1e-4, &scale)) {
        cdl_vec3 ctr = cdl_mat4_point3(ctm, cdl_v3(0, 0, 0));
        return cdl_pbrt_scene_rc(c, cdl_scene_add_sphere(c->s, ctr, (float)(sh->radius * scale), mat, emit,
                                                         inward, c->err));
    }
    cdl_pbrt_mesh m;
    memset(&m, 0, sizeof m);
    int rc = tessellate_sphere(c, sh->radius, inward, &m);
    if (!rc)
        rc = emit_mesh(c, &m, ctm, reverse, mat, emit);
    cdl_pbrt_shape sh2 = {0, 0.0, m};
    cdl_pbrt_shape_free(&sh2);
    return rc;
}

static int read_sphere(cdl_pbrt_ctx *c, cdl_pbrt_shape *sh)
{
    cdl_pbrt_params *ps = &c->ps;
    double r, zmin, zmax, phimax;
    int rc;
    if ((rc = cdl_pbrt_get_float(ps, "radius", 1.0, &r, c->err)))
        return rc;
    if (!(r > 0.0))
        return cdl_pbrt_error(c, c->line, "sphere radius %g must be > 0", r);
    if ((rc = cdl_pbrt_get_float(ps, "zmin", -r, &zmin, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "zmax", r, &zmax, c->err)) ||
        (rc = cdl_pbrt_get_float(ps, "phimax", 360.0, &phimax, c->err)))
        return rc;
    if (zmin > -r || zmax < r || phimax < 360.0)
        cdl_pbrt_warn(c, c->line, "partial sphere (zmin, zmax, phimax) rendered as a full sphere");
    sh->sphere = 1;
    sh->radius = r;
    return 0;
}

int cdl_pbrt_shape_directive(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_shape sh;
    memset(&sh, 0, sizeof sh);
    int rc;
    if (!strcmp(type, "trianglemesh"))
        rc = read_mesh(c, 0, &sh.mesh);
    else if (!strcmp(type, "bilinearmesh"))
        rc = read_mesh(c, 1, &sh.mesh);
    else if (!strcmp(type, "plymesh"))
        rc = read_ply(c, &sh.mesh);
    else if (!strcmp(type, "sphere"))
        rc = read_sphere(c, &sh);
    else {
        cdl_pbrt_warn(c, c->line, "Shape \"%s\" is not supported (skipped)", type);
        for (size_t i = 0; i < c->ps.n; i++)
            c->ps.p[i].used = 1;
        return 0;
    }
    if (rc) {
        cdl_pbrt_shape_free(&sh);
        return rc;
    }
    if (c->gs.mat == CDL_PBRT_MAT_NONE) {
        if (!c->warned_none)
            cdl_pbrt_warn(c, c->line, "shapes without a surface (material \"none\"/\"interface\") are skipped");
        c->warned_none = 1;
        cdl_pbrt_shape_free(&sh);
        return 0;
    }
    int32_t mat;
    if ((rc = cdl_pbrt_current_material(c, &mat))) {
        cdl_pbrt_shape_free(&sh);
        return rc;
    }
    if (c->cur_obj >= 0) {
        /* kept in object space, instanced by ObjectInstance */
        cdl_pbrt_object *o = &c->objs[c->cur_obj];
        if (c->gs.area && !c->warned_inst_light) {
            cdl_pbrt_warn(c, c->line, "area lights inside ObjectBegin are not supported (as in pbrt-v3): "
                                      "the shapes do not emit");
            c->warned_inst_light = 1;
        }
        if (o->n == o->cap) {
            uint32_t cap = o->cap ? 2 * o->cap : 8;
            cdl_pbrt_inst_shape *p = realloc(o->shapes, sizeof *p * cap);
            if (!p) {
                cdl_pbrt_shape_free(&sh);
                return oom(c);
            }
            o->shapes = p;
            o->cap = cap;
        }
        cdl_pbrt_inst_shape *r = &o->shapes[o->n];
        r->shape = sh;
        r->ctm = c->gs.ctm;
        r->reverse = c->gs.reverse;
        r->mat = mat;
        r->line = c->line;
        r->file = strdup(c->file);
        if (!r->file) {
            cdl_pbrt_shape_free(&sh);
            return oom(c);
        }
        o->n++;
        return 0;
    }
    int32_t emit = -1;
    if (c->gs.area)
        rc = cdl_pbrt_scene_rc(c, cdl_scene_add_emitter(c->s, c->gs.area_L, c->gs.area_twosided, &emit, c->err));
    if (!rc)
        rc = emit_shape(c, &sh, &c->gs.ctm, c->gs.reverse, cdl_mat4_swaps_handedness(&c->gs.ctm),
                        (uint32_t)mat, emit);
    c->nshapes++;
    cdl_pbrt_shape_free(&sh);
    return rc;
}

int cdl_pbrt_object_instance(cdl_pbrt_ctx *c, const char *name)
{
    int i = c->nobjs;
    while (i-- > 0 && strcmp(c->objs[i].name, name))
        ;
    if (i < 0)
        return cdl_pbrt_error(c, c->line, "ObjectInstance: object \"%s\" is not defined", name);
    const cdl_pbrt_object *o = &c->objs[i];
    for (uint32_t k = 0; k < o->n; k++) {
        const cdl_pbrt_inst_shape *r = &o->shapes[k];
        cdl_mat4 total = cdl_mat4_mul(&c->gs.ctm, &r->ctm);
        int rc = emit_shape(c, &r->shape, &total, r->reverse, cdl_mat4_swaps_handedness(&r->ctm),
                            (uint32_t)r->mat, -1);
        if (rc)
            return rc;
        c->nshapes++;
    }
    return 0;
}
