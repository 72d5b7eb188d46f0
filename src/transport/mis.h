/* Multiple importance sampling weights of bidirectional strategies
 * (Veach 1997, ch. 10; pbrt-v3's MISWeight), and the stratification
 * heuristic of Kollig & Keller 2004 (§3.2).
 *
 * A full path is z_0 ... z_{L}: z_0 the camera, z_L on a light. Strategy
 * (s, t) takes t vertices from the eye subpath and s from the light
 * subpath. The caller fills one record per vertex of the full path, in
 * eye-to-light order, with densities already updated for the connection. */
#ifndef CDL_MIS_H
#define CDL_MIS_H

typedef enum cdl_mis_kind {
    CDL_MIS_BALANCE,
    CDL_MIS_POWER,
    CDL_MIS_STRATIFIED,
    CDL_MIS_LIGHT_TRACING /* only t = 1 (and lights seen directly): pure light tracing */
} cdl_mis_kind;

typedef struct cdl_mis_vertex {
    float pdf_eye;   /* area density of this vertex sampled from the eye side (from z_{k-1}) */
    float pdf_light; /* area density sampled from the light side (from z_{k+1}; z_L: light origin) */
    int delta;       /* cannot be connected to */
    float g_next;    /* stratification: G(z_k, z_{k+1}) */
    float pdf_s1;    /* z_L only: its area density when s = 1 samples it anew from
                        z_{L-1} (next-event style); 0: the same as pdf_light */
} cdl_mis_vertex;

/* Samples each strategy takes per eye sample: pure eye paths (s = 0),
 * light tracing (t = 1) and the connections in between. Independent
 * subpaths per pixel sample use 1 for all three. */
typedef struct cdl_mis_counts {
    float eye, light_trace, connect;
    float s1_infinite; /* s = 1 samples of a path whose light is at infinity: with shared
                        * light paths those are resampled once per eye vertex (bdpt sets
                        * 1); 0: as connect */
    float connect_s1;  /* the s = 1 count in effect for this path (connect.c sets it); 0: connect */
    float merge;       /* vertex merging's eta = pi r^2 N (N light paths searched per merge); 0: none */
} cdl_mis_counts;

/* Weight of strategy (s, t) for the full path v[0 .. s+t-1].
 * delta_light: z_L is a point or spot light (an eye path cannot hit it).
 * threshold: the stratification heuristic's t. */
float cdl_mis_weight(cdl_mis_kind kind, const cdl_mis_vertex *v, int s, int t, int delta_light,
                     const cdl_mis_counts *n, float threshold);

/* Weight of merging at vertex k (1 <= k <= s + t - 2) of the full path
 * v[0 .. n) (balance or power heuristic; n->merge > 0). v[k] is the merge
 * vertex: pdf_eye its density from the eye subpath, pdf_light from the
 * light subpath; records k - 1 and k + 1 hold the densities through the
 * merge (the eye vertex's BSDF sampling towards the light subpath's
 * previous vertex, and back). */
float cdl_mis_weight_merge(cdl_mis_kind kind, const cdl_mis_vertex *v, int n, int k, int delta_light,
                           const cdl_mis_counts *c);

/* The same weight in O(1) from partial sums of each subpath's walk
 * (SmallVCM's dVCM, dVC, dVM in this walk's terms; connect.h's
 * cdl_merge_partials_* compute them once per vertex): merging eye vertex
 * z_k with light vertex y_m,
 *   w = 1 / (1 + a1 + pe(y_{m-1})^b a2 + b1 + pl(z_{k-1})^b b2)
 * where (a1, a2) belong to y_m, (b1, b2) to z_k, b = 2 (power) or 1
 * (balance), and the two densities are those through the merge (area
 * measure: the eye vertex's BSDF sampling y_{m-1}, and z_{k-1} for light
 * arriving from y_{m-1}); zero densities count as 1, as in the walk. */
static inline float cdl_mis_merge_partials(cdl_mis_kind kind, float a1, float a2, float pe_light_prev, float b1,
                                           float b2, float pl_eye_prev)
{
    float x = pe_light_prev != 0.0f ? pe_light_prev : 1.0f, y = pl_eye_prev != 0.0f ? pl_eye_prev : 1.0f;
    if (kind == CDL_MIS_POWER) {
        x *= x;
        y *= y;
    }
    return 1.0f / (1.0f + a1 + x * a2 + b1 + y * b2);
}

#endif
