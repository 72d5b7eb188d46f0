/* Walker/Vose alias table: O(1) sampling of a discrete distribution
 * (light selection proportional to power). */
#ifndef CDL_ALIAS_H
#define CDL_ALIAS_H

#include <stdint.h>

typedef struct cdl_alias {
    uint32_t n;
    float *prob;     /* acceptance probability of each slot */
    uint32_t *alias; /* fallback index of each slot */
    float *pmf;      /* normalized weights */
} cdl_alias;

/* Weights must be finite and >= 0 with a positive sum; returns 0 on success,
 * -1 otherwise (bad weights or out of memory). */
int cdl_alias_build(cdl_alias *a, const float *w, uint32_t n);
void cdl_alias_free(cdl_alias *a);

/* u_slot picks one of the n slots, u_accept the slot's entry or its
 * alias. One float cannot serve both: u * n leaves only 24 - log2(n) bits
 * for the acceptance test, which skews the pmf when n is large. */
static inline uint32_t cdl_alias_sample(const cdl_alias *a, float u_slot, float u_accept, float *pmf)
{
    uint32_t i = (uint32_t)((double)u_slot * a->n);
    if (i >= a->n)
        i = a->n - 1;
    uint32_t k = u_accept < a->prob[i] ? i : a->alias[i];
    if (pmf)
        *pmf = a->pmf[k];
    return k;
}

/* cdl_alias_sample in two steps, the second number read only where it
 * matters: a slot of probability 1 (weights all equal, as the triangles
 * of a quad light) is taken whatever it is (u_accept < 1). */
static inline uint32_t cdl_alias_slot(const cdl_alias *a, float u_slot)
{
    uint32_t i = (uint32_t)((double)u_slot * a->n);
    return i >= a->n ? a->n - 1 : i;
}

static inline int cdl_alias_certain(const cdl_alias *a, uint32_t slot) { return a->prob[slot] >= 1.0f; }

static inline uint32_t cdl_alias_take(const cdl_alias *a, uint32_t slot, float u_accept)
{
    return u_accept < a->prob[slot] ? slot : a->alias[slot];
}

#endif
