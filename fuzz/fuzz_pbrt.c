/* pbrt-v3/v4 scene files (Include of i.pbrt: input "main\n#INCLUDE\nincluded"). */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    size_t n1, n2;
    const uint8_t *inc = fuzz_split(data, n, "\n#INCLUDE\n", &n1, &n2);
    fuzz_file(1, "i.pbrt", inc, n2);
    fuzz_scene(fuzz_file(0, "s.pbrt", data, n1));
    return 0;
}
