#include "core/radix.h"

uint64_t *cdl_radix_sort_bits(uint64_t *key, uint64_t *tmp, uint32_t n, int lo, int hi)
{
    for (int shift = lo; shift < hi; shift += 10) {
        const uint64_t m = hi - shift < 10 ? ((uint64_t)1 << (hi - shift)) - 1u : 1023u;
        uint32_t count[1025] = {0};
        for (uint32_t k = 0; k < n; k++)
            count[(key[k] >> shift & m) + 1]++;
        for (int b = 0; b < 1024; b++)
            count[b + 1] += count[b];
        for (uint32_t k = 0; k < n; k++)
            tmp[count[key[k] >> shift & m]++] = key[k];
        uint64_t *sw = key;
        key = tmp;
        tmp = sw;
    }
    return key;
}
