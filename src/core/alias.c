#include "core/alias.h"

#include <math.h>
#include <stdlib.h>

int cdl_alias_build(cdl_alias *a, const float *w, uint32_t n)
{
    a->n = 0;
    a->prob = NULL;
    a->alias = NULL;
    a->pmf = NULL;
    double sum = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        if (!isfinite(w[i]) || w[i] < 0.0f)
            return -1;
        sum += w[i];
    }
    if (n == 0 || !(sum > 0.0))
        return -1;
    a->prob = malloc(sizeof(float) * n);
    a->alias = malloc(sizeof(uint32_t) * n);
    a->pmf = malloc(sizeof(float) * n);
    double *scaled = malloc(sizeof(double) * n);
    uint32_t *small = malloc(sizeof(uint32_t) * n), *large = malloc(sizeof(uint32_t) * n);
    int ok = a->prob && a->alias && a->pmf && scaled && small && large;
    if (ok) {
        uint32_t ns = 0, nl = 0;
        for (uint32_t i = 0; i < n; i++) {
            a->pmf[i] = (float)(w[i] / sum);
            scaled[i] = w[i] / sum * n;
            a->alias[i] = i;
            if (scaled[i] < 1.0)
                small[ns++] = i;
            else
                large[nl++] = i;
        }
        while (ns && nl) {
            uint32_t s = small[--ns], l = large[nl - 1];
            a->prob[s] = (float)scaled[s];
            a->alias[s] = l;
            scaled[l] -= 1.0 - scaled[s];
            if (scaled[l] < 1.0) {
                nl--;
                small[ns++] = l;
            }
        }
        /* Leftovers are 1 up to rounding. */
        while (nl)
            a->prob[large[--nl]] = 1.0f;
        while (ns)
            a->prob[small[--ns]] = 1.0f;
        a->n = n;
    }
    free(scaled);
    free(small);
    free(large);
    if (!ok) {
        cdl_alias_free(a);
        return -1;
    }
    return 0;
}

void cdl_alias_free(cdl_alias *a)
{
    free(a->prob);
    free(a->alias);
    free(a->pmf);
    a->prob = NULL;
    a->alias = NULL;
    a->pmf = NULL;
    a->n = 0;
}
