/* Growing arrays: one doubling rule for the buffers that are filled an
 * element at a time (scene geometry, hit lists, held leaf batches). */
#ifndef CDL_CORE_GROW_H
#define CDL_CORE_GROW_H

#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

/* Grows *buf (elem bytes each, *cap of them) to hold at least need
 * elements, doubling from 64; 0, or -1 without memory (*buf is kept). */
static inline int cdl_grow(void **buf, uint32_t *cap, uint32_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    uint64_t c = *cap ? *cap : 64;
    while (c < need)
        c *= 2;
    if (c > UINT32_MAX / 2)
        return -1;
    void *p = realloc(*buf, (size_t)c * elem);
    if (!p)
        return -1;
    *buf = p;
    *cap = (uint32_t)c;
    return 0;
}

#endif
