/* PLY meshes (ASCII and binary), reached as a pbrt plymesh. */
#include "fuzz_util.h"

static const char scene[] = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                            "LightSource \"point\" \"rgb I\" [10 10 10] \"point from\" [0 0 4]\n"
                            "Shape \"plymesh\" \"string filename\" \"m.ply\"\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    fuzz_file(1, "m.ply", data, n);
    fuzz_scene(fuzz_file(0, "s.pbrt", (const uint8_t *)scene, sizeof scene - 1));
    return 0;
}
