/* pbrt-v3/v4 scene files (Include of i.pbrt: input "main\n#INCLUDE\nincluded");
 * sky.exr (8x4) and square.exr (8x8) are there for environment maps. */
#include "fuzz_util.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fuzz_init_dir();
    for (int sq = 0; sq < 2; sq++) {
        cdl_image *img = NULL;
        cdl_error err;
        char path[512];
        if (cdl_image_create(8, sq ? 8 : 4, &img, &err))
            abort();
        float *px = cdl_image_pixels(img);
        for (int i = 0; i < 8 * (sq ? 8 : 4) * 3; i++)
            px[i] = (float)(i % 7) * 0.25f;
        snprintf(path, sizeof path, "%s/%s", fuzz_dir, sq ? "square.exr" : "sky.exr");
        if (cdl_image_save(img, path, 0.0f, &err))
            abort();
        cdl_image_release(img);
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    size_t n1, n2;
    const uint8_t *inc = fuzz_split(data, n, "\n#INCLUDE\n", &n1, &n2);
    fuzz_file(1, "i.pbrt", inc, n2);
    fuzz_scene(fuzz_file(0, "s.pbrt", data, n1));
    return 0;
}
