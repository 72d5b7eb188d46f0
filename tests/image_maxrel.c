/* image_maxrel A.exr B.exr: the largest relative difference between two
 * images' pixel values, |a - b| / max(|a|, |b|, 1e-6), printed; status 2
 * when they cannot be compared. (Distributed renders against one process.) */
#include <math.h>
#include <stdio.h>

#include <candela/candela.h>

int main(int argc, char **argv)
{
    cdl_image *a = NULL, *b = NULL;
    cdl_error err;
    if (argc != 3 || cdl_image_load(argv[1], &a, &err) || cdl_image_load(argv[2], &b, &err) ||
        cdl_image_width(a) != cdl_image_width(b) || cdl_image_height(a) != cdl_image_height(b)) {
        fprintf(stderr, "usage: image_maxrel A B (two images of one size)\n");
        return 2;
    }
    const float *pa = cdl_image_pixels(a), *pb = cdl_image_pixels(b);
    size_t n = 3 * (size_t)cdl_image_width(a) * (size_t)cdl_image_height(a);
    double worst = 0.0;
    for (size_t i = 0; i < n; i++) {
        double x = pa[i], y = pb[i], m = fmax(fmax(fabs(x), fabs(y)), 1e-6);
        double d = fabs(x - y) / m;
        if (!(d <= worst))
            worst = d; /* NaN counts as worst */
    }
    printf("%.3g\n", worst);
    cdl_image_release(a);
    cdl_image_release(b);
    return 0;
}
