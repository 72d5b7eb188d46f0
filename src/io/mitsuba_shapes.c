/* Mitsuba shapes: meshes from OBJ, PLY and serialized files, the built-in
 * rectangle, cube, disk, sphere and cylinder, and the sdfgrid (polygonized),
 * each with its bsdf and area emitter (not the sdfgrid's, as in Mitsuba).
 * Orientation is Mitsuba's: a triangle faces its shading normals when the
 * mesh has them, else its counter-clockwise normal after the transform
 * (Mitsuba does not flip faces under mirroring transforms, unlike pbrt);
 * flip_normals turns both. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/attr.h"
#include "scene/instance.h"
#include "scene/mesh.h"
#include "io/mitsuba_internal.h"
#include "io/obj_loader.h"
#include "io/ply.h"
#include "io/serialized.h"
#include "io/vol.h"
#include "scene/sdfgrid.h"

#define PI 3.14159265358979323846
#define DISK_SEGMENTS 128
/* An sdfgrid's samples and triangles: a fuzzer's input (ASan, 20 s) must
 * neither allocate nor polygonize for long. */
#ifdef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION
#define SDF_MAX_SAMPLES (1u << 15)
#define SDF_MAX_TRIS (1u << 16)
#else
#define SDF_MAX_SAMPLES (1u << 27)
#define SDF_MAX_TRIS (1u << 28)
#endif

/* Mitsuba 3's rectangle: [-1, 1]^2 at z = 0, facing +z. */
static int rectangle(cdl_mts_ctx *c, int line, cdl_mesh *m)
{
    static const float p[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    /* Mitsuba's uv ((x + 1) / 2, (y + 1) / 2) in candela's convention (v flipped) */
    static const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    static const uint32_t idx[6] = {0, 1, 2, 2, 3, 0};
    int rc = cdl_mesh_alloc(m, 4, 2, 1, 1, c->file, line, c->err);
    if (rc)
        return rc;
    memcpy(m->pos, p, sizeof p);
    memcpy(m->uv, uv, sizeof uv);
    memcpy(m->idx, idx, sizeof idx);
    for (int i = 0; i < 4; i++)
        m->nrm[3 * i] = 0.0f, m->nrm[3 * i + 1] = 0.0f, m->nrm[3 * i + 2] = 1.0f;
    return 0;
}

/* Mitsuba 3's cube: [-1, 1]^3, four vertices per face (faces -y, +y, +x,
 * +z, -x, -z) with the face's outward normal and Mitsuba's uv corners (0,
 * 1), (1, 1), (1, 0), (0, 0) in order, v flipped to candela's convention;
 * its corner order decides where each face's uv square starts. */
static int cube(cdl_mts_ctx *c, int line, cdl_mesh *m)
{
    /* per face: the normal axis and sign, then the corners as (+-1) pairs on the other two axes (a = axis + 1, b = axis + 2) */
    static const signed char face[6][2] = {{1, -1}, {1, 1}, {0, 1}, {2, 1}, {0, -1}, {2, -1}};
    static const signed char corner[6][4][3] = {
        {{1, -1, -1}, {1, -1, 1}, {-1, -1, 1}, {-1, -1, -1}}, {{1, 1, -1}, {-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}},
        {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},     {{1, -1, 1}, {1, 1, 1}, {-1, 1, 1}, {-1, -1, 1}},
        {{-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, -1}}, {{1, 1, -1}, {1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}}};
    static const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}}; /* Mitsuba's (0,1) (1,1) (1,0) (0,0), v flipped */
    int rc = cdl_mesh_alloc(m, 24, 12, 1, 1, c->file, line, c->err);
    if (rc)
        return rc;
    for (int f = 0; f < 6; f++) {
        for (int k = 0; k < 4; k++) {
            int v = 4 * f + k;
            for (int a = 0; a < 3; a++) {
                m->pos[3 * v + a] = corner[f][k][a];
                m->nrm[3 * v + a] = a == face[f][0] ? face[f][1] : 0.0f;
            }
            m->uv[2 * v] = uv[k][0];
            m->uv[2 * v + 1] = uv[k][1];
        }
        uint32_t b = (uint32_t)(4 * f), *t = m->idx + 6 * f;
        t[0] = b, t[1] = b + 1, t[2] = b + 2, t[3] = b + 3, t[4] = b, t[5] = b + 2;
    }
    return 0;
}

/* Mitsuba's disk: the unit disk at z = 0 facing +z with uv (r, phi / 2 pi),
 * as a fan whose triangles each have their own centre vertex (at their
 * middle angle) and a seam vertex at 2 pi, so phi interpolates right. */
static int disk(cdl_mts_ctx *c, int line, cdl_mesh *m)
{
    const int n = DISK_SEGMENTS;
    int rc = cdl_mesh_alloc(m, (uint32_t)(2 * n + 1), (uint32_t)n, 1, 1, c->file, line, c->err);
    if (rc)
        return rc;
    for (int i = 0; i < 2 * n + 1; i++) {
        int rim = i <= n;
        double t = rim ? (double)i / n : (i - n - 0.5) / n; /* phi / 2 pi */
        float *pp = m->pos + 3 * i, *nn = m->nrm + 3 * i;
        pp[0] = rim ? (float)cos(2.0 * PI * t) : 0.0f;
        pp[1] = rim ? (float)sin(2.0 * PI * t) : 0.0f;
        pp[2] = 0.0f;
        nn[0] = nn[1] = 0.0f;
        nn[2] = 1.0f;
        m->uv[2 * i] = rim ? 1.0f : 0.0f;
        m->uv[2 * i + 1] = (float)(1.0 - t);
    }
    for (int i = 0; i < n; i++) {
        m->idx[3 * i] = (uint32_t)(n + 1 + i);
        m->idx[3 * i + 1] = (uint32_t)i;
        m->idx[3 * i + 2] = (uint32_t)(i + 1);
    }
    return 0;
}

/* Mitsuba's cylinder: radius about the segment p0 -> p1, open ends,
 * normals outwards; its frame goes before to_world (*xf). */
static int cylinder(cdl_mts_ctx *c, cdl_xml_node *n, cdl_mesh *m, cdl_mat4 *xf)
{
    cdl_vec3 p0, p1;
    double r;
    int rc;
    if ((rc = cdl_mts_vec(c, n, "p0", cdl_v3(0, 0, 0), &p0, NULL)) ||
        (rc = cdl_mts_vec(c, n, "p1", cdl_v3(0, 0, 1), &p1, NULL)) || (rc = cdl_mts_float(c, n, "radius", 1.0, &r)))
        return rc;
    cdl_vec3 d = cdl_sub(p1, p0);
    float len = cdl_length(d);
    if (!(r > 0.0 && r <= CDL_MAX_COORD) || !(len > 0.0f))
        return cdl_mts_error(c, n->line, "cylinder radius %g and p0 != p1 needed", r);
    cdl_frame f = cdl_frame_from(cdl_scale(d, 1.0f / len)); /* right-handed: t x b = n */
    const float col[4][3] = {{f.t.x, f.t.y, f.t.z}, {f.b.x, f.b.y, f.b.z}, {f.n.x, f.n.y, f.n.z}, {p0.x, p0.y, p0.z}};
    const double scale[4] = {r, r, len, 1.0};
    cdl_mat4 local = cdl_mat4_identity();
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 4; j++)
            local.m[k][j] = col[j][k] * scale[j];
    *xf = cdl_mat4_mul(xf, &local);
    int rc2 = cdl_mesh_cylinder(m, 1.0, 0.0, 1.0, 2.0 * PI, DISK_SEGMENTS, c->file, n->line, c->err);
    for (uint32_t i = 0; !rc2 && i < m->nverts; i++) /* Mitsuba's v is z: flipped to candela's convention */
        m->uv[2 * i + 1] = 1.0f - m->uv[2 * i + 1];
    return rc2;
}

static void flip_v(cdl_mesh *m)
{
    for (uint32_t i = 0; m->uv && i < m->nverts; i++)
        m->uv[2 * i + 1] = 1.0f - m->uv[2 * i + 1];
}

static int mesh_file(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, cdl_mesh *m)
{
    char fn[1024], path[1024];
    int rc = cdl_mts_string(c, n, "filename", NULL, fn, sizeof fn);
    if (rc)
        return rc;
    if (!fn[0])
        return cdl_mts_error(c, n->line, "shape \"%s\" needs a \"filename\"", type);
    if ((rc = cdl_mts_path(c, n->line, fn, path, sizeof path)))
        return rc;
    if (!strcmp(type, "obj")) {
        int flip_uv;
        /* Mitsuba flips an OBJ's v by default: that is candela's convention;
         * flip_tex_coords false keeps the file's v, so candela flips it */
        if ((rc = cdl_mts_bool(c, n, "flip_tex_coords", 1, &flip_uv)) || (rc = cdl_obj_read_mesh(path, m, c->err)))
            return rc;
        for (uint32_t i = 0; !flip_uv && m->uv && i < m->nverts; i++)
            m->uv[2 * i + 1] = 1.0f - m->uv[2 * i + 1];
    } else if (!strcmp(type, "ply")) {
        rc = cdl_ply_read(path, m, c->err);
        flip_v(m); /* Mitsuba reads a PLY's v as stored, candela's convention is flipped */
    } else {
        long index;
        if ((rc = cdl_mts_int(c, n, "shape_index", 0, &index)))
            return rc;
        if (index < 0 || index > 1000000000L)
            return cdl_mts_error(c, n->line, "shape_index %ld must be >= 0", index);
        /* Mitsuba reads a serialized mesh's v as stored, candela's convention is flipped */
        if (!(rc = cdl_serialized_read(path, (uint32_t)index, m, c->err)))
            flip_v(m);
    }
    if (rc)
        return rc;
    int face;
    if ((rc = cdl_mts_bool(c, n, "face_normals", 0, &face)))
        return rc;
    if (face && m->nrm) {
        free(m->nrm);
        m->nrm = NULL;
    }
    return 0;
}

/* Mitsuba 3's sdfgrid: a .vol file of signed distances over [0, 1]^3,
 * polygonized (scene/sdfgrid.h) with Mitsuba's shading normals; no uv. */
static int sdfgrid(cdl_mts_ctx *c, cdl_xml_node *n, cdl_mesh *m)
{
    char fn[1024], path[1024], how[32];
    int rc = cdl_mts_string(c, n, "filename", NULL, fn, sizeof fn);
    if (rc || (rc = cdl_mts_string(c, n, "normals", "smooth", how, sizeof how)))
        return rc;
    if (strcmp(how, "smooth") && strcmp(how, "analytic"))
        return cdl_mts_error(c, n->line, "sdfgrid normals \"%s\": \"smooth\" or \"analytic\"", how);
    if (!fn[0])
        return cdl_mts_error(c, n->line, "shape \"sdfgrid\" needs a \"filename\" (a grid tensor is Python-only)");
    if ((rc = cdl_mts_path(c, n->line, fn, path, sizeof path)))
        return rc;
    cdl_vol vol;
    if ((rc = cdl_vol_read(path, 1, 2, SDF_MAX_SAMPLES, &vol, c->err))) {
        char msg[sizeof c->err->msg];
        snprintf(msg, sizeof msg, "%s", c->err->msg);
        return rc == CDL_ERR_INPUT ? cdl_mts_error(c, n->line, "sdfgrid \"%s\": %s", path, msg) : rc;
    }
    cdl_sdfgrid g = {{vol.res[0], vol.res[1], vol.res[2]}, vol.data};
    int levels = cdl_sdfgrid_default_levels(&g);
    rc = cdl_sdfgrid_polygonize(&g, levels, strcmp(how, "smooth") ? CDL_SDF_ANALYTIC : CDL_SDF_SMOOTH, SDF_MAX_TRIS,
                                m, c->file, n->line, c->err);
    cdl_vol_free(&vol);
    if (!rc)
        cdl_mts_warn(c, n->line, "sdfgrid %d x %d x %d polygonized at %d subdivisions per voxel (%u triangles); "
                                 "Mitsuba intersects the trilinear surface exactly", g.n[0], g.n[1], g.n[2], levels,
                     m->ntris);
    return rc;
}

/* <shape type="shapegroup" id="...">: its shapes, in object space, become
 * a scene shape group that <shape type="instance"> places. */
static int shapegroup(cdl_mts_ctx *c, cdl_xml_node *n)
{
    int rc = 0;
    const char *a = cdl_mts_attr(c, n, "id", &rc);
    if (rc)
        return rc;
    if (!a || !*a)
        return cdl_mts_error(c, n->line, "a shapegroup needs an id for its instances to refer to");
    if (c->in_group)
        return cdl_mts_error(c, n->line, "shapegroups do not nest (as in Mitsuba)");
    char id[256];
    snprintf(id, sizeof id, "%s", a);
    uint32_t group;
    if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_group_begin(c->s, &group, c->err))))
        return rc;
    cdl_mts_id v = {id, CDL_MTS_SHAPEGROUP, -1, (int)group, cdl_v3(0, 0, 0)};
    c->in_group = 1;
    for (int i = 0; i < n->nkids && !rc; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (!strcmp(k->name, "shape")) {
            k->used = 1;
            rc = cdl_mts_shape(c, k);
        }
    }
    c->in_group = 0;
    if (rc)
        return rc;
    if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_group_end(c->s, c->err))))
        return rc;
    cdl_mts_warn_unused(c, n, "shape \"shapegroup\"");
    return cdl_mts_add_id(c, n, &v);
}

/* <shape type="instance">: a <ref> to a shapegroup and a to_world. */
static int instance(cdl_mts_ctx *c, cdl_xml_node *n)
{
    if (c->in_group)
        return cdl_mts_error(c, n->line, "an instance inside a shapegroup (Mitsuba does not nest instancing)");
    const cdl_mts_id *g = NULL;
    int rc = 0;
    for (int i = 0; i < n->nkids && !rc; i++) {
        cdl_xml_node *k = &n->kids[i];
        if (strcmp(k->name, "ref"))
            continue;
        k->used = 1;
        const char *id = cdl_mts_attr(c, k, "id", &rc);
        if (rc)
            return rc;
        if (g)
            return cdl_mts_error(c, k->line, "an instance refers to one shapegroup");
        if (!id || !(g = cdl_mts_find_id(c, id)) || g->kind != CDL_MTS_SHAPEGROUP)
            return cdl_mts_error(c, k->line, "instance: \"%s\" is not a shapegroup declared before", id ? id : "");
    }
    if (!g)
        return cdl_mts_error(c, n->line, "an instance needs a <ref id=\"...\"/> to a shapegroup");
    cdl_mat4 m;
    if ((rc = cdl_mts_transform(c, n, "to_world", &m)))
        return rc;
    cdl_mts_warn_unused(c, n, "shape \"instance\"");
    c->nshapes++;
    return cdl_mts_scene_rc(c, n->line, cdl_scene_add_instance(c->s, (uint32_t)g->tex, &m, c->err));
}

/* Whether material mat looks anything up by uv (or its frame by dp/du):
 * candela's analytic spheres have neither in Mitsuba's parameterization. */
static int reads_uv(const cdl_scene *s, int32_t mat, int depth)
{
    if (mat < 0 || (uint32_t)mat >= s->nmats || depth > 16)
        return 0;
    const cdl_material *x = &s->mats[mat];
    int t = x->kd_tex >= 0 || (x->masked && x->opacity_tex >= 0) || x->blend_tex >= 0 ||
            (x->maps.on && (x->maps.alpha_tex[0] >= 0 || x->maps.alpha_tex[1] >= 0 || x->maps.bump_tex >= 0 ||
                            x->maps.normal_tex >= 0));
    for (int k = 0; x->type == CDL_MAT_PRINCIPLED && k < CDL_PR_NPARAMS; k++)
        t |= x->pr.tex[k] >= 0;
    if (x->type == CDL_MAT_BLEND)
        t |= reads_uv(s, x->blend[0], depth + 1) || reads_uv(s, x->blend[1], depth + 1);
    return t;
}

/* A bsdf that reads a mesh attribute the shape lacks fails, as in Mitsuba. */
static int check_attrs(cdl_mts_ctx *c, cdl_xml_node *n, const char *type, int32_t mat, const cdl_mesh *m)
{
    int face = 0;
    const char *miss = cdl_material_missing_attr(c->s, (uint32_t)mat, m, &face);
    if (miss)
        return cdl_mts_error(c, n->line, "shape \"%s\": its bsdf reads mesh attribute \"%s\", which the shape does "
                                         "not have", type, miss);
    if (face && c->in_group)
        cdl_mts_warn(c, n->line, "shape \"%s\" in a shapegroup: its face attributes are not instanced (read as 0)",
                     type);
    return 0;
}

/* A <ref> in a shape to something other than its bsdf: a top-level area
 * emitter (Mitsuba 3 may declare one apart, before or after, and refer to
 * it) is read here; a reference to an element candela skips (a medium) is
 * skipped with a warning, as that element was. */
static int shape_ref(cdl_mts_ctx *c, cdl_xml_node *k, int32_t *emit)
{
    int rc = 0;
    const char *raw = cdl_mts_attr(c, k, "id", &rc);
    if (rc || !raw)
        return rc;
    char id[256];
    snprintf(id, sizeof id, "%s", raw);
    const cdl_mts_id *d = cdl_mts_find_id(c, id);
    cdl_xml_node *decl = d && d->kind != CDL_MTS_OTHER ? NULL : cdl_mts_find_decl(c, id);
    if (!decl || !strcmp(decl->name, "bsdf"))
        return 0; /* the shape's bsdf, or an undeclared id shape_bsdf reports */
    k->used = 1;
    if (strcmp(decl->name, "emitter")) {
        cdl_mts_warn(c, k->line, "<ref id=\"%s\"> names a <%s>, which is not supported (ignored)", id, decl->name);
        return 0;
    }
    if (*emit >= 0)
        return cdl_mts_error(c, k->line, "a shape has one area emitter");
    if (c->in_group) {
        cdl_mts_warn(c, k->line, "an emitter on a shape in a shapegroup is not instanced: the shape does not emit");
        return 0;
    }
    if (!d) { /* marks it referred to */
        cdl_mts_id v = {id, CDL_MTS_OTHER, -1, -1, cdl_v3(0, 0, 0)};
        if ((rc = cdl_mts_add_id(c, decl, &v)))
            return rc;
    }
    return cdl_mts_area(c, decl, emit);
}

/* The shape's surface: a nested <bsdf>, a <ref> to one, or Mitsuba's default. */
static int shape_bsdf(cdl_mts_ctx *c, cdl_xml_node *n, int32_t *mat)
{
    int found, rc = cdl_mts_child_bsdf(c, n, 1, mat, &found);
    return rc || found ? rc : cdl_mts_default_material(c, mat);
}

int cdl_mts_shape(cdl_mts_ctx *c, cdl_xml_node *n)
{
    char type[64];
    int rc = cdl_mts_type(c, n, type, sizeof type), flip;
    if (rc)
        return rc;
    n->used = 1;
    if (!strcmp(type, "shapegroup"))
        return shapegroup(c, n);
    if (!strcmp(type, "instance"))
        return instance(c, n);
    static const char *const known[] = {"obj", "ply", "serialized", "rectangle", "cube", "disk", "sphere", "cylinder",
                                         "sdfgrid"};
    size_t kind = 0;
    while (kind < sizeof known / sizeof known[0] && strcmp(type, known[kind]))
        kind++;
    if (kind == sizeof known / sizeof known[0]) {
        cdl_mts_warn(c, n->line, "shape \"%s\" is not supported (skipped)", type);
        for (int k = 0; k < n->nkids; k++)
            n->kids[k].used = 1;
        return 0;
    }
    cdl_mat4 m;
    int32_t mat, emit = -1;
    if ((rc = cdl_mts_transform(c, n, "to_world", &m)) || (rc = cdl_mts_bool(c, n, "flip_normals", 0, &flip)) ||
        (rc = shape_bsdf(c, n, &mat)))
        return rc;
    for (int i = 0; i < n->nkids && !rc; i++)
        if (!strcmp(n->kids[i].name, "emitter") && !strcmp(type, "sdfgrid")) {
            return cdl_mts_error(c, n->kids[i].line, "an sdfgrid cannot be an area emitter (as in Mitsuba)");
        } else if (!strcmp(n->kids[i].name, "emitter")) {
            if (emit >= 0)
                return cdl_mts_error(c, n->kids[i].line, "a shape has one area emitter");
            if (c->in_group) { /* Mitsuba refuses these; pbrt-v4 drops them with a warning, as here */
                cdl_mts_warn(c, n->kids[i].line, "an emitter on a shape in a shapegroup is not instanced: the shape "
                                                 "does not emit");
                n->kids[i].used = 1;
                for (int j = 0; j < n->kids[i].nkids; j++)
                    n->kids[i].kids[j].used = 1;
                continue;
            }
            rc = cdl_mts_area(c, &n->kids[i], &emit);
        } else if (!strcmp(n->kids[i].name, "ref")) {
            rc = shape_ref(c, &n->kids[i], &emit);
        }
    if (rc)
        return rc;
    if (mat < 0) { /* a null bsdf: only an emitter's surface is worth keeping */
        if (emit < 0) {
            cdl_mts_warn(c, n->line, "shape with a \"null\" bsdf and no emitter skipped");
            cdl_mts_warn_unused(c, n, type);
            return 0;
        }
        cdl_material black = cdl_material_default(CDL_MAT_DIFFUSE);
        black.kd = cdl_v3(0, 0, 0);
        snprintf(black.name, sizeof black.name, "null");
        uint32_t id;
        if ((rc = cdl_mts_scene_rc(c, n->line, cdl_scene_add_material(c->s, &black, &id, c->err))))
            return rc;
        mat = (int32_t)id;
    }
    c->nshapes++;
    if (!strcmp(type, "sphere")) {
        double r, scale;
        cdl_vec3 ctr;
        if ((rc = cdl_mts_float(c, n, "radius", 1.0, &r)) ||
            (rc = cdl_mts_vec(c, n, "center", cdl_v3(0, 0, 0), &ctr, NULL)))
            return rc;
        if (!(r > 0.0 && r <= CDL_MAX_COORD))
            return cdl_mts_error(c, n->line, "sphere radius %g must be > 0", r);
        cdl_mat4 t = cdl_mat4_translate(ctr.x, ctr.y, ctr.z), full = cdl_mat4_mul(&m, &t);
        cdl_mts_warn_unused(c, n, "shape \"sphere\"");
        /* a textured sphere is a mesh: its uv are then Mitsuba's, and turn with it */
        if (cdl_mat4_is_similarity(&full, 1e-4, &scale) && !reads_uv(c->s, mat, 0)) {
            cdl_vec3 w = cdl_mat4_point3(&full, cdl_v3(0, 0, 0));
            return cdl_mts_scene_rc(c, n->line, cdl_scene_add_sphere(c->s, w, (float)(r * scale), (uint32_t)mat, emit,
                                                                     flip, c->err));
        }
        if ((rc = check_attrs(c, n, type, mat, NULL)))
            return rc;
        cdl_mesh sm;
        if (!(rc = cdl_mesh_sphere(&sm, r, flip, c->file, n->line, c->err)))
            rc = cdl_scene_add_mesh(c->s, &sm, &full, 0, (uint32_t)mat, emit, c->file, n->line, c->err);
        cdl_mesh_free(&sm);
        return rc;
    }
    cdl_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    if (kind <= 2)
        rc = mesh_file(c, n, type, &mesh);
    else if (!strcmp(type, "rectangle"))
        rc = rectangle(c, n->line, &mesh);
    else if (!strcmp(type, "cube"))
        rc = cube(c, n->line, &mesh);
    else if (!strcmp(type, "disk"))
        rc = disk(c, n->line, &mesh);
    else if (!strcmp(type, "sdfgrid"))
        rc = sdfgrid(c, n, &mesh);
    else
        rc = cylinder(c, n, &mesh, &m);
    if (!rc) {
        if (flip && mesh.nrm)
            for (size_t i = 0; i < 3 * (size_t)mesh.nverts; i++)
                mesh.nrm[i] = -mesh.nrm[i];
        /* cdl_scene_add_mesh flips mirrored meshes without normals (pbrt's
         * rule); cancel that, Mitsuba keeps the transformed winding */
        int reverse = flip ^ cdl_mat4_swaps_handedness(&m);
        static const char *const quiet[] = {"filename", "shape_index", "face_normals"};
        for (size_t i = 0; i < sizeof quiet / sizeof quiet[0]; i++)
            cdl_mts_prop(c, n, quiet[i]);
        cdl_mts_warn_unused(c, n, type);
        if (!(rc = check_attrs(c, n, type, mat, &mesh)))
            rc = cdl_scene_add_mesh(c->s, &mesh, &m, reverse, (uint32_t)mat, emit, c->file, n->line, c->err);
    }
    cdl_mesh_free(&mesh);
    return rc;
}
