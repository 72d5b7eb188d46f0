#ifndef CDL_CORE_RADIX_H
#define CDL_CORE_RADIX_H

#include <stdint.h>

/* Sorts n 64-bit keys by their bits [lo, hi), 10 at a time, least
 * significant first. Each pass is stable, so keys that tie on those bits
 * keep their order. tmp must have room for n keys. Returns the array that
 * holds the result, key or tmp; the other is scratch. */
uint64_t *cdl_radix_sort_bits(uint64_t *key, uint64_t *tmp, uint32_t n, int lo, int hi);

#endif
