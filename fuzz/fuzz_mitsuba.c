/* Mitsuba XML scene files, with an included file and a serialized mesh:
 * input "main\n#INCLUDE\nincluded\n#MESH\nbytes" (i.xml, m.serialized). */
#include "fuzz_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    size_t n1, n2, n3, n4;
    const uint8_t *inc = fuzz_split(data, n, "\n#INCLUDE\n", &n1, &n2);
    const uint8_t *mesh = fuzz_split(inc, n2, "\n#MESH\n", &n3, &n4);
    fuzz_file(1, "i.xml", inc, n3);
    fuzz_file(2, "m.serialized", mesh, n4);
    fuzz_scene(fuzz_file(0, "s.xml", data, n1));
    return 0;
}
