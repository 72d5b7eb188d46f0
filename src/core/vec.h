/* Small 3-vector and frame math, all inline: used in every inner loop. */
#ifndef CDL_VEC_H
#define CDL_VEC_H

#include <math.h>

#define CDL_PI 3.14159265358979323846f
#define CDL_INV_PI 0.31830988618379067154f

typedef struct cdl_vec3 {
    float x, y, z;
} cdl_vec3;

static inline cdl_vec3 cdl_v3(float x, float y, float z) { return (cdl_vec3){x, y, z}; }
static inline cdl_vec3 cdl_add(cdl_vec3 a, cdl_vec3 b) { return cdl_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline cdl_vec3 cdl_sub(cdl_vec3 a, cdl_vec3 b) { return cdl_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline cdl_vec3 cdl_mul(cdl_vec3 a, cdl_vec3 b) { return cdl_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline cdl_vec3 cdl_scale(cdl_vec3 a, float s) { return cdl_v3(a.x * s, a.y * s, a.z * s); }
static inline cdl_vec3 cdl_neg(cdl_vec3 a) { return cdl_v3(-a.x, -a.y, -a.z); }
static inline cdl_vec3 cdl_madd(cdl_vec3 a, cdl_vec3 b, float s) { return cdl_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float cdl_dot(cdl_vec3 a, cdl_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline cdl_vec3 cdl_cross(cdl_vec3 a, cdl_vec3 b)
{
    return cdl_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float cdl_length(cdl_vec3 a) { return sqrtf(cdl_dot(a, a)); }
static inline cdl_vec3 cdl_normalize(cdl_vec3 a) { return cdl_scale(a, 1.0f / cdl_length(a)); }
/* Plain comparisons: fmaxf's NaN rules keep it from inlining. */
static inline float cdl_maxf(float a, float b) { return a > b ? a : b; }
static inline float cdl_minf(float a, float b) { return a < b ? a : b; }
static inline float cdl_max3(cdl_vec3 a) { return cdl_maxf(a.x, cdl_maxf(a.y, a.z)); }
static inline float cdl_luminance(cdl_vec3 a) { return 0.2126f * a.x + 0.7152f * a.y + 0.0722f * a.z; }
static inline int cdl_is_black(cdl_vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
static inline int cdl_is_finite3(cdl_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
static inline cdl_vec3 cdl_reflect(cdl_vec3 w, cdl_vec3 n) { return cdl_sub(cdl_scale(n, 2.0f * cdl_dot(w, n)), w); }

/* Orthonormal frame around a unit normal; Duff et al. 2017, branchless. */
typedef struct cdl_frame {
    cdl_vec3 t, b, n;
} cdl_frame;

static inline cdl_frame cdl_frame_from(cdl_vec3 n)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    cdl_frame f;
    f.t = cdl_v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.b = cdl_v3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}
static inline cdl_vec3 cdl_to_local(const cdl_frame *f, cdl_vec3 v)
{
    return cdl_v3(cdl_dot(v, f->t), cdl_dot(v, f->b), cdl_dot(v, f->n));
}
static inline cdl_vec3 cdl_to_world(const cdl_frame *f, cdl_vec3 v)
{
    return cdl_add(cdl_add(cdl_scale(f->t, v.x), cdl_scale(f->b, v.y)), cdl_scale(f->n, v.z));
}

#endif
