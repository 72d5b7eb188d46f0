#define _POSIX_C_SOURCE 200809L
#include "io/obj_loader.h"

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/ObjMaterial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "io/obj_check.h"

static cdl_vec3 mat_color(const struct aiMaterial *m, const char *key, unsigned type,
                          unsigned idx, cdl_vec3 dflt)
{
    struct aiColor4D c;
    if (aiGetMaterialColor(m, key, type, idx, &c) != aiReturn_SUCCESS)
        return dflt;
    return cdl_v3(c.r, c.g, c.b);
}

static float mat_float(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx,
                       float dflt)
{
    ai_real v;
    unsigned n = 1;
    if (aiGetMaterialFloatArray(m, key, type, idx, &v, &n) != aiReturn_SUCCESS || n < 1)
        return dflt;
    return (float)v;
}

typedef struct tex_cache {
    char **paths;
    int *ids;
    int n;
} tex_cache;

static int texture_id(cdl_scene *s, tex_cache *tc, const char *full, int *id, cdl_error *err)
{
    for (int i = 0; i < tc->n; i++)
        if (!strcmp(tc->paths[i], full)) {
            *id = tc->ids[i];
            return 0;
        }
    int rc = cdl_scene_add_texture(s, full, id, err);
    if (rc)
        return rc;
    char **p = realloc(tc->paths, sizeof(char *) * (size_t)(tc->n + 1));
    if (p)
        tc->paths = p;
    int *q = realloc(tc->ids, sizeof(int) * (size_t)(tc->n + 1));
    if (q)
        tc->ids = q;
    if (!p || !q || !(tc->paths[tc->n] = strdup(full)))
        return cdl_error_set(err, CDL_ERR_SYSTEM, s->path, 0, "out of memory");
    tc->ids[tc->n++] = *id;
    return 0;
}

/* MTL conventions (illum models of the Wavefront spec) to candela's models. */
static int convert_material(cdl_scene *s, const char *path, const struct aiMaterial *am,
                            tex_cache *tc, cdl_material *m, int32_t *emit, cdl_error *err)
{
    *m = cdl_material_default(CDL_MAT_DIFFUSE);
    struct aiString name;
    if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == aiReturn_SUCCESS)
        snprintf(m->name, sizeof m->name, "%.63s", name.data);
    m->kd = mat_color(am, AI_MATKEY_COLOR_DIFFUSE, cdl_v3(0.5f, 0.5f, 0.5f));
    m->ks = mat_color(am, AI_MATKEY_COLOR_SPECULAR, cdl_v3(0.0f, 0.0f, 0.0f));
    cdl_vec3 ke = mat_color(am, AI_MATKEY_COLOR_EMISSIVE, cdl_v3(0.0f, 0.0f, 0.0f));
    *emit = -1;
    if (!cdl_is_black(ke)) {
        /* MTL Ke: radiance from the front (counter-clockwise) face */
        int rc = cdl_scene_add_emitter(s, ke, 0, emit, err);
        if (rc)
            return rc;
    }
    m->ns = mat_float(am, AI_MATKEY_SHININESS, 0.0f);
    m->eta = mat_float(am, AI_MATKEY_REFRACTI, 1.0f);
    float d = mat_float(am, AI_MATKEY_OPACITY, 1.0f);
    int illum = 2;
    unsigned n = 1;
    aiGetMaterialIntegerArray(am, AI_MATKEY_OBJ_ILLUM, &illum, &n);
    m->kd_tex = -1;

    struct aiString tex;
    if (aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL, NULL,
                             NULL) == aiReturn_SUCCESS &&
        tex.length > 0) {
        char full[2048];
        cdl_path_join_dir(path, tex.data, full, sizeof full);
        int rc = texture_id(s, tc, full, &m->kd_tex, err);
        if (rc)
            return rc;
    }
    if (illum == 5) {
        m->type = CDL_MAT_MIRROR;
    } else if (illum == 7 || (d < 1.0f && m->eta != 1.0f)) {
        m->type = CDL_MAT_DIELECTRIC;
        m->ks = m->kt = cdl_v3(1.0f, 1.0f, 1.0f); /* MTL's Ks/Tf are not glass colours */
        if (!(m->eta > 0.0f))
            m->eta = 1.5f;
    } else if (cdl_max3(m->ks) > 0.0f) {
        m->type = CDL_MAT_PHONG;
        float sc = cdl_phong_energy_scale(m);
        if (sc < 1.0f) {
            cdl_warn(path, 0, "material '%s': Kd + Ks reflect more than all light; scaled by %.3f",
                     m->name, (double)sc);
            m->kd = cdl_scale(m->kd, sc);
            m->ks = cdl_scale(m->ks, sc);
        }
    } else {
        m->type = CDL_MAT_DIFFUSE;
    }
    return 0;
}

int cdl_load_obj(cdl_scene *s, const char *path, cdl_error *err)
{
    int rc = cdl_obj_check(path, err);
    if (rc)
        return rc;
    const struct aiScene *as =
        aiImportFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                               aiProcess_SortByPType);
    if (!as || !as->mRootNode) {
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "import failed: %s", aiGetErrorString());
        aiReleaseImport(as);
        return rc;
    }

    tex_cache tc = {NULL, NULL, 0};
    uint32_t mat_base = s->nmats;
    float *buf = NULL;
    int32_t *emit = calloc(as->mNumMaterials + 1, sizeof(int32_t));
    if (!emit)
        rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    for (unsigned i = 0; i < as->mNumMaterials && !rc; i++) {
        cdl_material m;
        uint32_t id;
        rc = convert_material(s, path, as->mMaterials[i], &tc, &m, &emit[i], err);
        if (!rc)
            rc = cdl_scene_add_material(s, &m, &id, err);
    }
    for (unsigned mi = 0; mi < as->mNumMeshes && !rc; mi++) {
        const struct aiMesh *am = as->mMeshes[mi];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumVertices == 0)
            continue;
        if (am->mMaterialIndex >= as->mNumMaterials) {
            rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "mesh refers to a missing material");
            break;
        }
        uint32_t nv = am->mNumVertices;
        float *nb = realloc(buf, sizeof(float) * 8 * (size_t)nv);
        if (!nb) {
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
            break;
        }
        buf = nb;
        float *p = buf, *nrm = buf + 3 * (size_t)nv, *uv = buf + 6 * (size_t)nv;
        for (uint32_t v = 0; v < nv; v++) {
            p[3 * v] = am->mVertices[v].x;
            p[3 * v + 1] = am->mVertices[v].y;
            p[3 * v + 2] = am->mVertices[v].z;
            if (am->mNormals) {
                nrm[3 * v] = am->mNormals[v].x;
                nrm[3 * v + 1] = am->mNormals[v].y;
                nrm[3 * v + 2] = am->mNormals[v].z;
            }
            if (am->mTextureCoords[0]) {
                uv[2 * v] = am->mTextureCoords[0][v].x;
                uv[2 * v + 1] = am->mTextureCoords[0][v].y;
            }
        }
        uint32_t first;
        rc = cdl_scene_add_vertices(s, nv, p, am->mNormals ? nrm : NULL,
                                    am->mTextureCoords[0] ? uv : NULL, &first, err);
        uint8_t flags = (uint8_t)((am->mNormals ? CDL_TRI_HAS_N : 0) |
                                  (am->mTextureCoords[0] ? CDL_TRI_HAS_UV : 0));
        for (unsigned f = 0; f < am->mNumFaces && !rc; f++) {
            const struct aiFace *face = &am->mFaces[f];
            if (face->mNumIndices != 3)
                continue; /* points and lines are not surfaces */
            if (face->mIndices[0] >= nv || face->mIndices[1] >= nv || face->mIndices[2] >= nv) {
                rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "face index out of range");
                break;
            }
            rc = cdl_scene_add_triangle(s, first + face->mIndices[0], first + face->mIndices[1],
                                        first + face->mIndices[2], mat_base + am->mMaterialIndex,
                                        emit[am->mMaterialIndex], flags, err);
        }
    }
    free(buf);
    free(emit);
    for (int i = 0; i < tc.n; i++)
        free(tc.paths[i]);
    free(tc.paths);
    free(tc.ids);
    aiReleaseImport(as);
    return rc;
}

int cdl_obj_read_mesh(const char *path, cdl_mesh *m, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    int rc = cdl_obj_check(path, err);
    if (rc)
        return rc;
    const struct aiScene *as = aiImportFile(path, aiProcess_Triangulate | aiProcess_PreTransformVertices |
                                                      aiProcess_SortByPType);
    if (!as || !as->mRootNode) {
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "import failed: %s", aiGetErrorString());
        aiReleaseImport(as);
        return rc;
    }
    uint64_t nv = 0, nt = 0;
    int has_n = 1, has_uv = 1;
    for (unsigned mi = 0; mi < as->mNumMeshes; mi++) {
        const struct aiMesh *am = as->mMeshes[mi];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        nv += am->mNumVertices;
        nt += am->mNumFaces;
        has_n &= am->mNormals != NULL;
        has_uv &= am->mTextureCoords[0] != NULL;
    }
    if (nt == 0 || nv >= UINT32_MAX / 4 || nt >= UINT32_MAX / 4)
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, nt ? "too many vertices or faces" : "no triangles");
    if (!rc)
        rc = cdl_mesh_alloc(m, (uint32_t)nv, (uint32_t)nt, has_n, has_uv, path, 0, err);
    uint32_t v0 = 0, t = 0;
    for (unsigned mi = 0; mi < as->mNumMeshes && !rc; mi++) {
        const struct aiMesh *am = as->mMeshes[mi];
        if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
            continue;
        for (uint32_t v = 0; v < am->mNumVertices; v++) {
            float *p = m->pos + 3 * (size_t)(v0 + v);
            p[0] = am->mVertices[v].x, p[1] = am->mVertices[v].y, p[2] = am->mVertices[v].z;
            if (has_n) {
                float *n = m->nrm + 3 * (size_t)(v0 + v);
                n[0] = am->mNormals[v].x, n[1] = am->mNormals[v].y, n[2] = am->mNormals[v].z;
            }
            if (has_uv) {
                m->uv[2 * (size_t)(v0 + v)] = am->mTextureCoords[0][v].x;
                m->uv[2 * (size_t)(v0 + v) + 1] = am->mTextureCoords[0][v].y;
            }
        }
        for (unsigned f = 0; f < am->mNumFaces; f++) {
            const struct aiFace *face = &am->mFaces[f];
            if (face->mNumIndices != 3)
                continue; /* points and lines are not surfaces */
            for (int k = 0; k < 3; k++) {
                if (face->mIndices[k] >= am->mNumVertices) {
                    rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "face index out of range");
                    break;
                }
                m->idx[3 * (size_t)t + k] = v0 + face->mIndices[k];
            }
            t++;
        }
        v0 += am->mNumVertices;
    }
    m->ntris = t;
    aiReleaseImport(as);
    if (rc)
        cdl_mesh_free(m);
    return rc;
}
