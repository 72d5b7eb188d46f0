/* Clearance of a surface point (clearance.h): an Embree point query whose
 * radius shrinks to the nearest geometry in front of the point's plane. */
#include "scene/clearance.h"

#include <math.h>

#include "scene/instance.h"

typedef struct query_ctx {
    const cdl_scene *s;
    cdl_vec3 x, n;
    float tol;
} query_ctx;

/* Closest point of triangle abc to p (Ericson, Real-Time Collision
 * Detection, 5.1.5): its squared distance. */
static float tri_dist2(cdl_vec3 p, cdl_vec3 a, cdl_vec3 b, cdl_vec3 c)
{
    cdl_vec3 ab = cdl_sub(b, a), ac = cdl_sub(c, a), ap = cdl_sub(p, a);
    float d1 = cdl_dot(ab, ap), d2 = cdl_dot(ac, ap);
    cdl_vec3 q;
    if (d1 <= 0.0f && d2 <= 0.0f) {
        q = a;
    } else {
        cdl_vec3 bp = cdl_sub(p, b);
        float d3 = cdl_dot(ab, bp), d4 = cdl_dot(ac, bp);
        cdl_vec3 cp = cdl_sub(p, c);
        float d5 = cdl_dot(ab, cp), d6 = cdl_dot(ac, cp);
        float vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d3 >= 0.0f && d4 <= d3)
            q = b;
        else if (d6 >= 0.0f && d5 <= d6)
            q = c;
        else if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f)
            q = cdl_madd(a, ab, d1 / (d1 - d3));
        else if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f)
            q = cdl_madd(a, ac, d2 / (d2 - d6));
        else if (va <= 0.0f && (d4 - d3) >= 0.0f && (d5 - d6) >= 0.0f)
            q = cdl_madd(b, cdl_sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
        else {
            float den = 1.0f / (va + vb + vc);
            q = cdl_add(a, cdl_add(cdl_scale(ab, vb * den), cdl_scale(ac, vc * den)));
        }
    }
    cdl_vec3 e = cdl_sub(p, q);
    return cdl_dot(e, e);
}

static cdl_vec3 to_world(const cdl_instance *in, const float *p)
{
    const float *m = in ? in->xf : NULL;
    if (!m)
        return cdl_v3(p[0], p[1], p[2]);
    return cdl_v3(m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3], m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7],
                  m[8] * p[0] + m[9] * p[1] + m[10] * p[2] + m[11]);
}

/* Distances are taken in world space (the query is a world-space one,
 * whatever the instance's transform). */
static bool visit(struct RTCPointQueryFunctionArguments *args)
{
    const query_ctx *c = args->userPtr;
    const cdl_scene *s = c->s;
    const cdl_instance *in = NULL;
    const uint32_t *idx = s->idx;
    const float *sph = s->sph;
    if (args->context->instStackSize > 0) {
        in = &s->insts[args->context->instID[0] - CDL_GEOM_INSTANCE0];
        idx = s->groups[in->group].idx;
        sph = s->groups[in->group].sph;
    }
    float d2;
    if (args->geomID == CDL_GEOM_TRIANGLES) {
        const uint32_t *t = &idx[3 * (size_t)args->primID];
        cdl_vec3 v[3];
        int front = 0;
        for (int k = 0; k < 3; k++) {
            v[k] = to_world(in, &s->pos[3 * (size_t)t[k]]);
            front |= cdl_dot(cdl_sub(v[k], c->x), c->n) > c->tol;
        }
        /* a triangle wholly on or behind the plane blocks no segment
         * through the front half-space (the point's own surface, the rest
         * of a convex object) */
        if (!front)
            return false;
        d2 = tri_dist2(c->x, v[0], v[1], v[2]);
    } else {
        const float *q = &sph[4 * (size_t)args->primID];
        cdl_vec3 cs = to_world(in, q);
        float r = q[3];
        if (in) { /* an ellipsoid in general: approximated by its bounding sphere */
            const float *m = in->xf;
            float l = 0.0f;
            for (int k = 0; k < 3; k++)
                l = cdl_maxf(l, sqrtf(m[k] * m[k] + m[4 + k] * m[4 + k] + m[8 + k] * m[8 + k]));
            r *= l;
        }
        if (cdl_dot(cdl_sub(cs, c->x), c->n) + r <= c->tol)
            return false;
        float d = fabsf(cdl_length(cdl_sub(c->x, cs)) - r);
        d2 = d * d;
    }
    if (d2 < args->query->radius * args->query->radius) {
        args->query->radius = sqrtf(d2); /* the query shrinks as nearer geometry turns up */
        return true;
    }
    return false;
}

float cdl_clearance(const cdl_scene *s, cdl_vec3 x, cdl_vec3 n, float rmax)
{
    if (!(rmax > 0.0f))
        return 0.0f;
    float m = cdl_maxf(fabsf(x.x), cdl_maxf(fabsf(x.y), fabsf(x.z)));
    query_ctx c = {s, x, n, 4.0f * (s->eps + m * 1e-5f)};
    struct RTCPointQuery q;
    q.x = x.x;
    q.y = x.y;
    q.z = x.z;
    q.time = 0.0f;
    q.radius = rmax;
    struct RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(s->rtc, &q, &ctx, visit, &c);
    return q.radius;
}
