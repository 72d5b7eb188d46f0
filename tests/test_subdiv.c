/* Loop subdivision (pbrt's loopsubdiv): counts, a vertex's limit position
 * that does not move with more levels, symmetry, planarity of a flat
 * patch with boundary, and outward normals of a closed mesh. */
#include <math.h>
#include <string.h>

#include "scene/subdiv.h"
#include "test_util.h"

static void tetra(cdl_mesh *m)
{
    static const float P[12] = {1, 1, 1, -1, -1, 1, -1, 1, -1, 1, -1, -1};
    static const uint32_t I[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}; /* outwards */
    cdl_error err;
    die_on(cdl_mesh_alloc(m, 4, 4, 0, 0, "t", 0, &err), &err);
    memcpy(m->pos, P, sizeof P);
    memcpy(m->idx, I, sizeof I);
}

int main(void)
{
    cdl_error err;
    float first[3][3];
    for (int level = 1; level <= 3; level++) {
        cdl_mesh m = {0};
        tetra(&m);
        die_on(cdl_mesh_loop_subdivide(&m, level, "t", 0, &err), &err);
        uint32_t f = 4u << (2 * level);
        CHECK(m.ntris == f && m.nverts == 2 + f / 2, "tetrahedron, %d levels: %u triangles, %u vertices (%u, %u)",
              level, m.ntris, m.nverts, f, 2 + f / 2);
        /* the original vertices keep their indices; their limit positions
         * do not depend on the level, and symmetry puts them on the
         * diagonals at one distance */
        float r0 = sqrtf(m.pos[0] * m.pos[0] + m.pos[1] * m.pos[1] + m.pos[2] * m.pos[2]);
        int same = 1, sym = 1;
        for (int v = 0; v < 3; v++) {
            float *p = m.pos + 3 * v;
            if (level == 1)
                memcpy(first[v], p, sizeof first[v]);
            for (int c = 0; c < 3; c++)
                same &= fabsf(p[c] - first[v][c]) < 1e-5f;
            float r = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
            sym &= fabsf(r - r0) < 1e-5f && fabsf(fabsf(p[0]) - fabsf(p[1])) < 1e-5f;
        }
        CHECK(same && sym && r0 > 0.2f && r0 < 1.0f,
              "%d levels: corner limit positions unchanged, symmetric, inside the hull (|p| %.5f)", level,
              (double)r0);
        int out = 1;
        for (uint32_t v = 0; v < m.nverts; v++)
            out &= m.nrm[3 * v] * m.pos[3 * v] + m.nrm[3 * v + 1] * m.pos[3 * v + 1] +
                       m.nrm[3 * v + 2] * m.pos[3 * v + 2] > 0.0f;
        CHECK(out, "%d levels: every normal points outwards", level);
        cdl_mesh_free(&m);
    }
    /* a flat square of two triangles (all boundary): stays in z = 0 with
     * normals +z (its boundary is smoothed as pbrt's is: 1/8 and, at the
     * limit, 1/5 of each boundary neighbour) */
    cdl_mesh q = {0};
    die_on(cdl_mesh_alloc(&q, 4, 2, 0, 0, "q", 0, &err), &err);
    static const float Q[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const uint32_t QI[6] = {0, 1, 2, 0, 2, 3};
    memcpy(q.pos, Q, sizeof Q);
    memcpy(q.idx, QI, sizeof QI);
    die_on(cdl_mesh_loop_subdivide(&q, 2, "q", 0, &err), &err);
    int flat = 1;
    for (uint32_t v = 0; v < q.nverts; v++)
        flat &= q.pos[3 * v + 2] == 0.0f && q.nrm[3 * v + 2] > 0.999f;
    CHECK(flat && q.ntris == 32, "flat square, 2 levels: %u triangles in z = 0 facing +z", q.ntris);
    cdl_mesh_free(&q);
    printf("%s\n", test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
