#include "film/film.h"

#include <stdlib.h>
#include <string.h>

int cdl_film_init(cdl_film *f, int width, int height, cdl_error *err)
{
    memset(f, 0, sizeof *f);
    size_t n = (size_t)width * (size_t)height;
    f->sum = calloc(3 * n, sizeof(double));
    f->count = calloc(n, sizeof(uint32_t));
    if (!f->sum || !f->count) {
        cdl_film_free(f);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for a %dx%d film", width, height);
    }
    f->width = width;
    f->height = height;
    return 0;
}

void cdl_film_free(cdl_film *f)
{
    free(f->sum);
    free(f->count);
    f->sum = NULL;
    f->count = NULL;
}

int cdl_film_resolve(const cdl_film *f, cdl_image *img, cdl_error *err)
{
    int rc = cdl_image_alloc(img, f->width, f->height, err);
    if (rc)
        return rc;
    size_t n = (size_t)f->width * (size_t)f->height;
    for (size_t i = 0; i < n; i++) {
        double w = f->count[i] ? 1.0 / f->count[i] : 0.0;
        for (int k = 0; k < 3; k++)
            img->rgb[3 * i + k] = (float)(f->sum[3 * i + k] * w);
    }
    return 0;
}
