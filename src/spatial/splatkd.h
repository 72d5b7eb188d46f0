/* The eye-sample kd-tree of photon ray splatting (Herzog et al. 2007, §5):
 * eye samples (points with the normal of the side the camera sees) under
 * a kd-tree that a photon ray traverses with its conical frustum
 * (Algorithm 1), every eye sample inside it tested for feasibility and
 * weighted by the ray-space Epanechnikov kernel (Algorithm 2, eq. 4.5).
 *
 * Layout (§5.1): 8-byte nodes in depth-first order, the left child next
 * to its parent; interior nodes split at the spatial median of their cell
 * (at the sample nearest to it when a side would be empty); leaves of at
 * most 16 samples or a cell too small to split; empty nodes; and
 * back-face-culling nodes holding a mean normal and C_max = sin(D_theta)
 * over a subtree whose normals deviate by less than 15 degrees. The
 * samples are kept in tree order (structure of arrays); the tree splits
 * into parts (subtrees, a fixed number whatever the threads) that a thread
 * owns, each with a contiguous range of samples. */
#ifndef CDL_SPLATKD_H
#define CDL_SPLATKD_H

#include <stdint.h>

#include "core/error.h"
#include "core/vec.h"

typedef struct cdl_skd_node {
    uint32_t a, b;
} cdl_skd_node;

enum { CDL_SKD_TWO_SIDED = 1 }; /* a sample that receives light from both sides (transmission) */

typedef struct cdl_skd_range {
    uint32_t lo, hi;
} cdl_skd_range;

typedef struct cdl_skd_part {
    uint32_t node, lo, hi; /* root node; samples [lo, hi) */
    float bmin[3], bmax[3];
} cdl_skd_part;

/* The wide tree over the binary one (splatkd_wide.c): each wide node
 * holds up to CDL_SKD_WIDTH children, the frontier of a few collapsed
 * binary levels, their bounding spheres side by side so that one SIMD
 * step tests them all. A child (ref, n): n == 0 a wide node; n ==
 * CDL_SKD_WCULL a culling node (wcull[ref]); otherwise the samples
 * [ref, ref + n), a subtree small enough to test without descending. */
#define CDL_SKD_WIDTH 8
#define CDL_SKD_WCULL UINT32_MAX
#define CDL_SKD_WEMPTY (UINT32_MAX - 1)
typedef struct cdl_skd_wnode {
    float c[4][CDL_SKD_WIDTH]; /* centre x, y, z, radius (-inf: no child) */
    uint32_t ref[CDL_SKD_WIDTH], n[CDL_SKD_WIDTH];
} cdl_skd_wnode;
typedef struct cdl_skd_went {
    uint32_t ref, n;
} cdl_skd_went;
typedef struct cdl_skd_wcull {
    float n[3], c2;    /* the culling node's mean normal (not unit) and C_max^2 |n|^2 */
    cdl_skd_went next; /* what follows when it does not cull */
} cdl_skd_wcull;

typedef struct cdl_skd {
    cdl_skd_node *nodes;
    uint32_t nnodes, cap;
    uint32_t n;
    uint32_t *order; /* caller's index of the sample at each tree position */
    float *p[3], *nrm[3];
    float *two; /* 1 for a two-sided sample, else 0 (the leaf test's arithmetic) */
    float *lsph;          /* per node: its samples' bounding sphere (centre, radius; -1 if none) */
    cdl_skd_range *range; /* per node: its samples [lo, hi) (a subtree's are contiguous) */
    float bmin[3], bmax[3];
    cdl_skd_part *parts;
    uint32_t nparts;
    uint32_t leaves, culls, empties, depth;
    cdl_skd_wnode *wide;
    cdl_skd_wcull *wcull;
    uint32_t nwide, nwcull, capwide, capwcull;
    cdl_skd_went *wpart; /* per part: its root (n == CDL_SKD_WEMPTY: no sample) */
    cdl_skd_went wroot;  /* the whole tree's */
} cdl_skd;

/* Builds the wide tree over a built binary one (spheres and ranges
 * done); 0 or -1 out of memory. */
int cdl_skd_build_wide(cdl_skd *t);

typedef struct cdl_skd_params {
    uint32_t leaf_size;     /* 16 */
    float min_diag;         /* cells with a smaller diagonal become leaves (scene units) */
    float cull_deg;         /* 15; a negative value: no culling nodes */
    uint32_t part_depth;    /* parts are the subtrees this many levels down (6) */
} cdl_skd_params;

void cdl_skd_params_default(cdl_skd_params *p, float scene_diag);

/* Builds over n samples (position, unit normal of the seen side, flags).
 * Non-finite input is an error. */
int cdl_skd_build(cdl_skd *t, const cdl_vec3 *p, const cdl_vec3 *n, const uint8_t *flags, uint32_t n_samples,
                  const cdl_skd_params *prm, cdl_error *err);
void cdl_skd_free(cdl_skd *t);
size_t cdl_skd_bytes(const cdl_skd *t);

/* A photon ray x_{i-1} -> x_i with its bandwidth (§4.2): radius h0 + dh t
 * at distance t along it up to the hit, h(len) beyond it. on: the normal
 * at the origin's front (samples behind the origin surface get nothing);
 * zero for a point light. Beyond the hit (cap):
 *   0    the report's hemisphere (Algorithm 2): a sample beyond x_i is fed
 *        within the sphere of radius h(len) around x_i, the kernel
 *        renormalized over that sphere's cross-section. Light at angle
 *        theta onto a plane then reads 1/2 + cos(theta) 8/(3 pi) int_0^1
 *        (1 - s^2)^(3/2) / (1 - s^2 sin^2(theta))^2 ds of the truth (0.97 at
 *        34 degrees, 0.89 at 57) whatever h: a bias that never vanishes;
 *   c>0  a sample is fed if the ray reached its tangent plane before
 *        ending (so a plane's own samples all are, and a blocker's shadow
 *        stays dark) or ended within h of it (a neighbouring surface of a
 *        concave corner: the rays that would have landed in the part of the
 *        kernel beyond the corner), out to c h(len) beyond x_i, with the
 *        plain kernel: the irradiance on a plane is exact up to incidence
 *        atan(c), and the estimate consistent. */
/* A sample whose normal is within about 25 degrees of the opposite of the
 * ray origin's and which lies within zmin of its tangent plane is on the
 * other side of the origin's surface (see zmin). */
#define CDL_SKD_SHEET_COS -0.9f

typedef struct cdl_splat_ray {
    cdl_vec3 o, d, on;
    float len, h0, dh;
    float cap;
    float zmin; /* least height over the origin's tangent plane of a sample
                 * facing back into it (its other side, if the origin's
                 * surface is a thin two-sided sheet): a little above 0 */
    float otol; /* > 0: the ray's origin must lie in front of a one-sided
                 * sample's tangent plane (or within otol behind it). A ray
                 * in the room on the far side of a thin wall passes close
                 * to the wall's samples on this side, which face it, and
                 * (beyond its hit, in a concave corner) feeds them through
                 * the wall; a ray that lands near a sample of a convex
                 * surface starts in front of its plane unless it grazes. */
} cdl_splat_ray;

/* A feasible eye sample: its tree position, kernel times cosine (per unit
 * flux: the irradiance it receives) and one over its distance along the
 * ray (0 at 0). */
typedef struct cdl_splat_hit {
    uint32_t s;
    float w, iz;
} cdl_splat_hit;

typedef struct cdl_splat_hits {
    cdl_splat_hit *h;
    uint32_t n, cap;
    uint64_t tested; /* samples tested (feasible or not) */
    uint64_t nodes;  /* nodes visited */
    int fail;        /* out of memory */
} cdl_splat_hits;

/* Weight of the sample at p (normal n, flags) for ray r (Algorithm 2):
 * 0 when infeasible: facing away, behind the origin surface, beyond the
 * frustum or the hemispherical cap. With grad, also the weight's gradient
 * with respect to the sample's position, the cosine held fixed (Herzog et
 * al. 2007, eq. 6.9-6.11): -(4 / pi) cos / h^4 times the vector from the
 * ray to the sample. */
static inline float cdl_splat_weight_grad(const cdl_splat_ray *r, cdl_vec3 p, cdl_vec3 n, uint8_t flags,
                                          float *z_out, cdl_vec3 *grad)
{
    float dn = cdl_dot(r->d, n), c = dn;
    if (flags & CDL_SKD_TWO_SIDED)
        c = -fabsf(c);
    if (!(c < 0.0f))
        return 0.0f;
    cdl_vec3 D = cdl_sub(p, r->o);
    float z = cdl_dot(D, r->d);
    float zn = cdl_dot(D, r->on);
    if (!(z >= 0.0f) || zn < 0.0f || (zn < r->zmin && cdl_dot(n, r->on) < CDL_SKD_SHEET_COS))
        return 0.0f;
    if (r->otol > 0.0f && !(flags & CDL_SKD_TWO_SIDED) && cdl_dot(D, n) > r->otol)
        return 0.0f;
    float h = r->h0 + r->dh * (z < r->len ? z : r->len);
    float h2 = h * h;
    cdl_vec3 e = cdl_sub(D, cdl_scale(r->d, z)); /* not |D|^2 - z^2: cancellation */
    float r2 = cdl_dot(e, e);
    if (z > r->len) {
        if (r->cap > 0.0f) {
            /* the ray must have crossed the sample's tangent plane by its end */
            float tp = cdl_dot(D, n) / dn;
            float b = z - r->len;
            if (z > r->len + r->cap * h || (tp > r->len * 1.0001f + 1e-3f * h && !(r2 + b * b < h2)))
                return 0.0f;
        } else {
            h2 -= (z - r->len) * (z - r->len);
        }
    }
    if (!(h2 > 0.0f) || r2 >= h2)
        return 0.0f;
    *z_out = z;
    if (grad)
        *grad = cdl_scale(e, (float)(-4.0 / CDL_PI) * -c / (h2 * h2));
    return (float)(2.0 / CDL_PI) / h2 * (1.0f - (r2 > 0.0f ? r2 : 0.0f) / h2) * -c;
}

static inline float cdl_splat_weight(const cdl_splat_ray *r, cdl_vec3 p, cdl_vec3 n, uint8_t flags, float *z_out)
{
    return cdl_splat_weight_grad(r, p, n, flags, z_out, NULL);
}

/* Traversal flags: culling nodes honoured; Algorithm 1's 1D slabs (the
 * report's traversal) instead of the default bounding-sphere test per
 * node (the same samples, fewer tested). */
enum { CDL_SKD_CULL = 1, CDL_SKD_SLABS = 2, CDL_SKD_NOIZ = 8, CDL_SKD_ANY = 16 };
/* CDL_SKD_NOIZ: a range visit's iz is not wanted (left unwritten);
 * CDL_SKD_ANY: a both visit wants the frustum's lanes only (feasible 0). */

/* The feasible samples of part `part` (UINT32_MAX: the whole tree) found
 * by traversing with the frustum, in batches: samples [first, first + m)
 * (m <= 16) of which those in `mask` (bit i: sample first + i; never
 * past m) are feasible with weight w[i] >= 0 (kernel times cosine; 0
 * elsewhere) and iz[i] one over their distance along the ray (0 at 0). */
typedef void (*cdl_skd_visit)(void *ctx, uint32_t first, uint32_t m, uint32_t mask, const float *w, const float *iz);
typedef struct cdl_skd_count {
    uint64_t tested, nodes;
    uint64_t weighed; /* of the tested, those given the leaf test (the both visit: not culled) */
} cdl_skd_count;
int cdl_skd_splat_visit(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, cdl_skd_visit fn,
                        void *ctx, cdl_skd_count *cnt);
/* One traversal of the whole tree for a visibility mask and the splats
 * it filters: per batch, `any` holds every sample inside the frustum
 * (within h of the ray, 0 <= z <= the cap's reach) whatever its facing,
 * with z[i] its distance along the ray, as a mask's occluders; `feasible`,
 * w and iz what cdl_skd_splat_visit gives the batch (the same leaf test,
 * bit for bit, and the same culling nodes: their subtrees are still
 * visited for `any`, not weighed). Called where either mask is non-zero;
 * batches come in tree order (parts in order, so a part's batches are
 * contiguous): the bounding spheres, CDL_SKD_SLABS ignored (they feed the
 * same samples). w and iz are only meaningful on feasible lanes. The
 * frustum test is the leaf test's first step, so feasible lanes are a
 * subset of any up to rounding at the cap's end (which nothing relies
 * on: a feasible lane outside `any` is just no occluder). */
typedef void (*cdl_skd_visit_both)(void *ctx, uint32_t first, uint32_t m, uint32_t any, const float *z,
                                   uint32_t feasible, const float *w, const float *iz);
int cdl_skd_splat_visit_both(const cdl_skd *t, const cdl_splat_ray *r, int flags, cdl_skd_visit_both fn, void *ctx,
                             cdl_skd_count *cnt);
/* The same a range at a time: samples [first, first + n), n <=
 * CDL_SKD_CHUNK, in 16-lane blocks; mask[j] holds the feasible lanes of
 * block j (samples first + 16 j + i), and w, iz hold 16 entries a block,
 * written only for blocks with a nonzero mask. One call per leaf range
 * instead of one per 16 lanes: the leaf test runs without calls. */
#define CDL_SKD_CHUNK 128
typedef void (*cdl_skd_visit_range)(void *ctx, uint32_t first, uint32_t n, const uint16_t *mask, const float *w,
                                    const float *iz);
int cdl_skd_splat_visit_range(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags,
                              cdl_skd_visit_range fn, void *ctx, cdl_skd_count *cnt);
/* The leaf test alone (Algorithm 2) for samples [b, b + m), m <= 16, of
 * any arrays laid out as the tree's p, nrm and two (16 floats of padding
 * past the last): w and iz as a visit gets them; returns the mask of
 * feasible lanes. */
uint32_t cdl_skd_weigh16(const cdl_skd *t, uint32_t b, uint32_t m, const cdl_splat_ray *r, float *w, float *iz);

/* Whether some sample the frustum feeds (the leaf test: facing it,
 * culling nodes honoured with CDL_SKD_CULL) lies behind one of np planes:
 * p . n + pw[sample] < c. With early exit; for the visibility mask's
 * question whether its occluders can hide anything at all. */
typedef struct cdl_skd_plane {
    float n[3], c;
} cdl_skd_plane;
int cdl_skd_any_behind(const cdl_skd *t, const cdl_splat_ray *r, int flags, const cdl_skd_plane *pl, int np,
                       const float *pw, cdl_skd_count *cnt);

/* Regions: the top-most subtrees of each part holding at most max_n
 * samples (a leaf of more counts as one), every sample in exactly one, in
 * tree order (Herzog et al. 2007, §6.3: where radiance cache records are
 * taken from). *out is allocated; 0 or an error. */
typedef struct cdl_skd_region {
    uint32_t node, lo, hi, part;
} cdl_skd_region;
int cdl_skd_regions(const cdl_skd *t, uint32_t max_n, cdl_skd_region **out, uint32_t *n, cdl_error *err);

/* Traverses part `part` like cdl_skd_splat_visit (bounding spheres) but
 * does not descend below a node with stop[node] >= 0: fn(ctx, stop[node])
 * for each such node whose sphere the frustum reaches. */
typedef void (*cdl_skd_visit_stop)(void *ctx, int32_t id);
void cdl_skd_stop_visit(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, const int32_t *stop,
                        cdl_skd_visit_stop fn, void *ctx, cdl_skd_count *cnt);

/* The same appended to out. Returns 0, or -1 out of memory. */
int cdl_skd_splat(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, int flags, cdl_splat_hits *out);
/* The same by testing every sample of the part one by one with
 * cdl_splat_weight (for tests: the traversal's leaves test 16 at a time). */
int cdl_skd_splat_brute(const cdl_skd *t, uint32_t part, const cdl_splat_ray *r, cdl_splat_hits *out);

#endif
