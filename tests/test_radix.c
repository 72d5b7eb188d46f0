/* core/radix.c: a sort by a range of bits is stable and agrees with a
 * comparison sort of (those bits, position) on keys with many ties, for
 * ranges of whole and partial 10-bit digits, and for 0 and 1 keys. */
#include <stdlib.h>

#include "core/radix.h"
#include "core/rng.h"
#include "test_util.h"

#define N 100000

static int lo_bit, hi_bit;

static uint64_t field(uint64_t k) { return k >> lo_bit & ((((uint64_t)1) << (hi_bit - lo_bit)) - 1u); }

static int cmp_ref(const void *a, const void *b)
{
    const uint64_t *x = a, *y = b; /* [0]: key, [1]: position */
    uint64_t fx = field(x[0]), fy = field(y[0]);
    if (fx != fy)
        return fx < fy ? -1 : 1;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

int main(void)
{
    static uint64_t key[N], tmp[N], ref[2 * N];
    const int ranges[4][2] = {{32, 62}, {0, 10}, {5, 27}, {40, 41}};
    cdl_rng rng;
    cdl_rng_seed(&rng, 7, 0);
    for (int r = 0; r < 4; r++) {
        lo_bit = ranges[r][0], hi_bit = ranges[r][1];
        for (uint32_t i = 0; i < N; i++) {
            /* few distinct values in the field (ties), noise elsewhere */
            uint64_t v = (uint64_t)(cdl_rng_u32(&rng) % 97u) << lo_bit;
            key[i] = ((uint64_t)cdl_rng_u32(&rng) << 32 | cdl_rng_u32(&rng)) & ~(((((uint64_t)1) << (hi_bit - lo_bit)) - 1u) << lo_bit);
            key[i] |= v & ((((uint64_t)1) << (hi_bit - lo_bit)) - 1u) << lo_bit;
            ref[2 * i] = key[i], ref[2 * i + 1] = i;
        }
        qsort(ref, N, 2 * sizeof(uint64_t), cmp_ref);
        const uint64_t *out = cdl_radix_sort_bits(key, tmp, N, lo_bit, hi_bit);
        uint32_t bad = 0;
        for (uint32_t i = 0; i < N; i++)
            bad += out[i] != ref[2 * i];
        CHECK(bad == 0, "bits [%d, %d): %u of %u keys out of place (stable order by the field)", lo_bit, hi_bit, bad, N);
    }
    uint64_t one = 42, scratch;
    CHECK(*cdl_radix_sort_bits(&one, &scratch, 1, 0, 30) == 42, "one key stays");
    return test_failures ? 1 : 0;
}
