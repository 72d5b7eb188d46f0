/* Images: EXR, PFM and PNG through cdl_image_load (by magic bytes), and the
 * same bytes as an OBJ material's texture (map_Kd, read by stb_image). */
#include "fuzz_util.h"

static const char obj[] = "mtllib m.mtl\nv -1 -1 0\nv 1 -1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                          "usemtl t\nf 1/1 2/2 3/3\n";
static const char mtl[] = "newmtl t\nKd 1 1 1\nKe 1 1 1\nmap_Kd t.img\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t n)
{
    const char *path = fuzz_file(2, "t.img", data, n);
    cdl_image *img = NULL;
    cdl_error err;
    if (!cdl_image_load(path, &img, &err)) {
        /* what loads must be usable: its size and every pixel readable */
        int w = cdl_image_width(img), h = cdl_image_height(img);
        const float *px = cdl_image_pixels(img);
        volatile float sum = 0.0f;
        for (size_t i = 0; i < (size_t)w * (size_t)h * 3; i++)
            sum += px[i];
        cdl_image_release(img);
    }
    fuzz_file(1, "m.mtl", (const uint8_t *)mtl, sizeof mtl - 1);
    fuzz_scene(fuzz_file(0, "s.obj", (const uint8_t *)obj, sizeof obj - 1));
    return 0;
}
