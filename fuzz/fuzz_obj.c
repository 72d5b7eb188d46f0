/* Wavefront OBJ + MTL: input "OBJ text\n#MTL\nMTL text"; the MTL is written
 * as m.mtl (seeds say mtllib m.mtl). */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    size_t n1, n2;
    const uint8_t *mtl = fuzz_split(data, n, "\n#MTL\n", &n1, &n2);
    fuzz_file(1, "m.mtl", mtl, n2);
    fuzz_scene(fuzz_file(0, "s.obj", data, n1));
    return 0;
}
