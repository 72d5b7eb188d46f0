/* pbrt shapes: triangle, bilinear-patch and PLY meshes, spheres (analytic
 * under similarity transforms and untextured materials, tessellated
 * otherwise), disks and cylinders (tessellated), and flattened object
 * instances. Orientation follows pbrt-v3 exactly, since area lights emit
 * from the front face only: a triangle's normal is cross(p0 - p2, p1 - p2)
 * (= the CCW normal), turned towards the shading normals when the mesh has
 * N (FaceForward), else flipped by ReverseOrientation XOR a handedness-
 * swapping transform. We store every triangle with its pbrt normal as CCW. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "scene/instance.h"
#include "scene/mesh.h"
#include "scene/subdiv.h"
#include "io/ply.h"


void cdl_pbrt_shape_free(cdl_pbrt_shape *sh)
{
    cdl_mesh_free(&sh->mesh);
    memset(sh, 0, sizeof *sh);
}

static int oom(cdl_pbrt_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->file, c->line, "out of memory");
}

/* trianglemesh (quads = 0) or pbrt-v4 bilinearmesh (quads = 1, split
 * into two triangles (p00, p10, p11), (p00, p11, p01) that keep the
 * patch's normal cross(dp/du, dp/dv)). */
static int read_mesh(cdl_pbrt_ctx *c, int quads, const char *what, cdl_mesh *m)
{
    cdl_pbrt_params *ps = &c->ps;
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
    int rc = cdl_mesh_alloc(m, nv, (uint32_t)nt, N != NULL, UV != NULL, c->file, c->line, c->err);
    if (rc)
        return rc;
    const double *pv = cdl_pbrt_nums(ps, P);
    for (size_t i = 0; i < 3 * (size_t)nv; i++)
        m->pos[i] = (float)pv[i];
    if (N) {
        const double *nv3 = cdl_pbrt_nums(ps, N);
        for (size_t i = 0; i < 3 * (size_t)nv; i++)
            m->nrm[i] = (float)nv3[i];
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

static int read_ply(cdl_pbrt_ctx *c, cdl_mesh *m)
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
    if ((rc = cdl_ply_read(path, m, c->err)))
        return rc; /* names the PLY file and its problem; indices and numbers are checked */
    if (m->nverts == 0 || m->ntris == 0)
        return cdl_pbrt_error(c, c->line, "plymesh \"%s\" has no triangles", path);
    return 0;
}

/* swap_def: the handedness of the transform the sphere was defined
 * under. pbrt flips a sphere's normal by ReverseOrientation XOR it in
 * object space; an instance transform only carries that normal along. */
/* Whether a material looks anything up by (u, v). */
static int uv_textured(const cdl_material *m)
{
    const cdl_mat_maps *mm = &m->maps;
    return m->kd_tex >= 0 || (m->masked && m->opacity_tex >= 0) ||
           (mm->on && (mm->alpha_tex[0] >= 0 || mm->alpha_tex[1] >= 0 || mm->bump_tex >= 0 || mm->normal_tex >= 0));
}

/* pbrt's (u, v) of a mesh without them: (0,0), (1,0), (1,1) at a
 * triangle's corners; a bilinear patch's are its own (u, v), on its two
 * triangles (p00 p10 p11) and (p00 p11 p01). Corners are unshared. */
static int default_uv(cdl_pbrt_ctx *c, const cdl_mesh *in, int quads, cdl_mesh *out)
{
    static const float tri[2][6] = {{0, 0, 1, 0, 1, 1}, {0, 0, 1, 1, 0, 1}};
    int rc = cdl_mesh_alloc(out, 3 * in->ntris, in->ntris, in->nrm != NULL, 1, c->file, c->line, c->err);
    if (rc)
        return rc;
    for (uint32_t t = 0; t < in->ntris; t++)
        for (uint32_t k = 0; k < 3; k++) {
            uint32_t v = in->idx[3 * t + k], o = 3 * t + k;
            memcpy(out->pos + 3 * (size_t)o, in->pos + 3 * (size_t)v, 3 * sizeof(float));
            if (in->nrm)
                memcpy(out->nrm + 3 * (size_t)o, in->nrm + 3 * (size_t)v, 3 * sizeof(float));
            out->uv[2 * (size_t)o] = tri[quads && (t & 1)][2 * k];
            out->uv[2 * (size_t)o + 1] = tri[quads && (t & 1)][2 * k + 1];
            out->idx[o] = o;
        }
    return 0;
}

static int emit_shape(cdl_pbrt_ctx *c, const cdl_pbrt_shape *sh, const cdl_mat4 *ctm, int reverse,
                      int swap_def, uint32_t mat, int32_t emit)
{
    /* pbrt's vertex normals: a user's mesh with "N" (the sphere's
     * tessellation stands for pbrt's analytic sphere) */
    int rc = cdl_pbrt_shape_material(c, mat, !sh->sphere && sh->mesh.nrm != NULL, &mat);
    if (rc)
        return rc;
    if (!sh->sphere && !sh->mesh.uv && uv_textured(&c->s->mats[mat])) {
        cdl_mesh m;
        if ((rc = default_uv(c, &sh->mesh, sh->quads, &m)))
            return rc;
        rc = cdl_scene_add_mesh(c->s, &m, ctm, reverse, mat, emit, c->file, c->line, c->err);
        cdl_mesh_free(&m);
        return rc;
    }
    if (!sh->sphere)
        return cdl_scene_add_mesh(c->s, &sh->mesh, ctm, reverse, mat, emit, c->file, c->line, c->err);
    double scale;
    int inward = reverse ^ swap_def;
    /* the analytic sphere's (u, v) are Mitsuba's: a textured sphere is
     * tessellated, with pbrt's (u, v) */
    if (cdl_mat4_is_similarity(ctm, 1e-4, &scale) && !uv_textured(&c->s->mats[mat])) {
        cdl_vec3 ctr = cdl_mat4_point3(ctm, cdl_v3(0, 0, 0));
        return cdl_pbrt_scene_rc(c, cdl_scene_add_sphere(c->s, ctr, (float)(sh->radius * scale), mat, emit,
                                                         inward, c->err));
    }
    cdl_mesh m;
    memset(&m, 0, sizeof m);
    rc = cdl_mesh_sphere(&m, sh->radius, inward, c->file, c->line, c->err);
    if (!rc)
        rc = cdl_scene_add_mesh(c->s, &m, ctm, reverse, mat, emit, c->file, c->line, c->err);
    cdl_mesh_free(&m);
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

#define ROUND_SEGMENTS 128 /* segments of a disk's or cylinder's full turn */

/* phimax in degrees, as pbrt reads it: clamped to [0, 360] */
static int read_phimax(cdl_pbrt_ctx *c, double *phimax, int *nseg)
{
    int rc = cdl_pbrt_get_float(&c->ps, "phimax", 360.0, phimax, c->err);
    if (rc)
        return rc;
    if (!(*phimax > 0.0))
        return cdl_pbrt_error(c, c->line, "phimax %g must be > 0 degrees", *phimax);
    *phimax = *phimax > 360.0 ? 360.0 : *phimax;
    *nseg = (int)ceil(ROUND_SEGMENTS * *phimax / 360.0);
    *nseg = *nseg < 1 ? 1 : *nseg;
    *phimax *= 3.14159265358979323846 / 180.0;
    return 0;
}

static int read_disk(cdl_pbrt_ctx *c, cdl_mesh *m)
{
    double h, r, ri, phimax;
    int nseg = 1, rc;
    if ((rc = cdl_pbrt_get_float(&c->ps, "height", 0.0, &h, c->err)) ||
        (rc = cdl_pbrt_get_float(&c->ps, "radius", 1.0, &r, c->err)) ||
        (rc = cdl_pbrt_get_float(&c->ps, "innerradius", 0.0, &ri, c->err)) || (rc = read_phimax(c, &phimax, &nseg)))
        return rc;
    if (!(r > 0.0 && r <= CDL_MAX_COORD && ri >= 0.0 && ri < r && fabs(h) <= CDL_MAX_COORD))
        return cdl_pbrt_error(c, c->line, "disk radius %g, innerradius %g, height %g: need 0 <= innerradius < radius",
                              r, ri, h);
    return cdl_mesh_disk(m, h, r, ri, phimax, nseg, c->file, c->line, c->err);
}

static int read_cylinder(cdl_pbrt_ctx *c, cdl_mesh *m)
{
    double r, zmin, zmax, phimax;
    int nseg = 1, rc;
    if ((rc = cdl_pbrt_get_float(&c->ps, "radius", 1.0, &r, c->err)) ||
        (rc = cdl_pbrt_get_float(&c->ps, "zmin", -1.0, &zmin, c->err)) ||
        (rc = cdl_pbrt_get_float(&c->ps, "zmax", 1.0, &zmax, c->err)) || (rc = read_phimax(c, &phimax, &nseg)))
        return rc;
    if (zmin > zmax) { /* pbrt swaps them */
        double t = zmin;
        zmin = zmax;
        zmax = t;
    }
    if (!(r > 0.0 && r <= CDL_MAX_COORD && zmax > zmin && fabs(zmin) <= CDL_MAX_COORD && fabs(zmax) <= CDL_MAX_COORD))
        return cdl_pbrt_error(c, c->line, "cylinder radius %g, zmin %g, zmax %g: need radius > 0 and zmin != zmax", r,
                              zmin, zmax);
    return cdl_mesh_cylinder(m, r, zmin, zmax, phimax, nseg, c->file, c->line, c->err);
}

/* pbrt's loopsubdiv: a triangle mesh subdivided "levels" times (3 by
 * default) to its limit surface. */
static int read_loopsubdiv(cdl_pbrt_ctx *c, cdl_mesh *m)
{
    int levels;
    int rc = cdl_pbrt_get_int(&c->ps, "levels", 3, &levels, c->err);
    if (!rc && cdl_pbrt_find(&c->ps, "nlevels")) /* pbrt-v2's name */
        rc = cdl_pbrt_get_int(&c->ps, "nlevels", 3, &levels, c->err);
    if (rc)
        return rc;
    if (levels < 0 || levels > 12)
        return cdl_pbrt_error(c, c->line, "loopsubdiv: levels %d must be in 0..12", levels);
    if ((rc = read_mesh(c, 0, "loopsubdiv", m)))
        return rc;
    if (m->nrm || m->uv)
        cdl_pbrt_warn(c, c->line, "loopsubdiv: N and uv are not subdivided (the limit surface's normals are used)");
    return cdl_mesh_loop_subdivide(m, levels, c->file, c->line, c->err);
}

int cdl_pbrt_shape_directive(cdl_pbrt_ctx *c, const char *type)
{
    cdl_pbrt_shape sh;
    memset(&sh, 0, sizeof sh);
    int rc;
    if (!strcmp(type, "trianglemesh"))
        rc = read_mesh(c, 0, type, &sh.mesh);
    else if (!strcmp(type, "bilinearmesh"))
        rc = read_mesh(c, sh.quads = 1, type, &sh.mesh);
    else if (!strcmp(type, "loopsubdiv"))
        rc = read_loopsubdiv(c, &sh.mesh);
    else if (!strcmp(type, "plymesh"))
        rc = read_ply(c, &sh.mesh);
    else if (!strcmp(type, "sphere"))
        rc = read_sphere(c, &sh);
    else if (!strcmp(type, "disk"))
        rc = read_disk(c, &sh.mesh);
    else if (!strcmp(type, "cylinder"))
        rc = read_cylinder(c, &sh.mesh);
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
    int32_t mat;
    if (c->gs.mat == CDL_PBRT_MAT_NONE && !c->gs.area) {
        if (!c->warned_none)
            cdl_pbrt_warn(c, c->line, "shapes without a surface (material \"none\"/\"interface\") are skipped");
        c->warned_none = 1;
        cdl_pbrt_shape_free(&sh);
        return 0;
    }
    if (c->gs.mat == CDL_PBRT_MAT_NONE) {
        /* pbrt's light emits and lets rays through; candela's emits and absorbs */
        cdl_pbrt_warn(c, c->line, "an area light on material \"none\" emits from a black surface (pbrt's lets "
                                  "rays pass)");
        if (c->black_mat < 0) {
            cdl_material m = cdl_material_default(CDL_MAT_DIFFUSE);
            m.kd = cdl_v3(0, 0, 0);
            snprintf(m.name, sizeof m.name, "pbrt-none-emitter");
            uint32_t id;
            if ((rc = cdl_pbrt_scene_rc(c, cdl_scene_add_material(c->s, &m, &id, c->err)))) {
                cdl_pbrt_shape_free(&sh);
                return rc;
            }
            c->black_mat = (int32_t)id;
        }
        mat = c->black_mat;
    } else if ((rc = cdl_pbrt_current_material(c, &mat))) {
        cdl_pbrt_shape_free(&sh);
        return rc;
    }
    if (c->cur_obj >= 0 && c->gs.area && !c->warned_inst_light) {
        /* the shapes go to the object's shape group, which does not emit */
        cdl_pbrt_warn(c, c->line, "area lights inside ObjectBegin are not supported (as in pbrt-v3 and v4): "
                                  "the shapes do not emit");
        c->warned_inst_light = 1;
    }
    int32_t emit = -1;
    if (c->gs.area && c->cur_obj < 0)
        rc = cdl_pbrt_scene_rc(c, cdl_scene_add_emitter(c->s, c->gs.area_L, c->gs.area_twosided, &emit, c->err));
    if (!rc)
        rc = emit_shape(c, &sh, &c->gs.ctm, c->gs.reverse, cdl_mat4_swaps_handedness(&c->gs.ctm),
                        (uint32_t)mat, emit);
    c->nshapes++;
    cdl_pbrt_shape_free(&sh);
    return rc;
}

int cdl_pbrt_object_begin(cdl_pbrt_ctx *c, const char *name)
{
    if (c->nobjs == c->capobjs) {
        int cap = c->capobjs ? 2 * c->capobjs : 8;
        cdl_pbrt_object *p = realloc(c->objs, sizeof *p * (size_t)cap);
        if (!p)
            return oom(c);
        c->objs = p;
        c->capobjs = cap;
    }
    cdl_pbrt_object *o = &c->objs[c->nobjs];
    memset(o, 0, sizeof *o);
    int rc = cdl_pbrt_scene_rc(c, cdl_scene_group_begin(c->s, &o->group, c->err));
    if (rc)
        return rc;
    if (!(o->name = strdup(name)))
        return oom(c);
    c->cur_obj = c->nobjs++;
    return 0;
}

int cdl_pbrt_object_end(cdl_pbrt_ctx *c)
{
    c->cur_obj = -1;
    return cdl_pbrt_scene_rc(c, cdl_scene_group_end(c->s, c->err));
}

int cdl_pbrt_object_instance(cdl_pbrt_ctx *c, const char *name)
{
    int i = c->nobjs;
    while (i-- > 0 && strcmp(c->objs[i].name, name))
        ;
    if (i < 0)
        return cdl_pbrt_error(c, c->line, "ObjectInstance: object \"%s\" is not defined", name);
    c->nshapes++;
    return cdl_pbrt_scene_rc(c, cdl_scene_add_instance(c->s, c->objs[i].group, &c->gs.ctm, c->err));
}
