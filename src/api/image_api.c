/* Public image handles over film/image: files, crops and the metrics of
 * `candela diff`. */
#include <stdlib.h>
#include <string.h>

#include "film/flip.h"
#include "film/image.h"
#include "film/metrics.h"

static int new_image(cdl_image **out, cdl_error *err)
{
    *out = calloc(1, sizeof **out);
    return *out ? 0 : cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
}

int cdl_image_create(int width, int height, cdl_image **out, cdl_error *err)
{
    if (!out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_create: no place for the image");
    if (width < 1 || height < 1 || width > 65536 || height > 65536)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "image size %dx%d out of range [1, 65536]", width, height);
    int rc = new_image(out, err);
    if (!rc && (rc = cdl_image_alloc(*out, width, height, err))) {
        free(*out);
        *out = NULL;
    }
    return rc;
}

int cdl_image_load(const char *path, cdl_image **out, cdl_error *err)
{
    if (!out || !path)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_load: no path or no place for the image");
    int rc = new_image(out, err);
    if (!rc && (rc = cdl_image_read(path, *out, err))) {
        free(*out);
        *out = NULL;
    }
    return rc;
}

void cdl_image_release(cdl_image *img)
{
    if (!img)
        return;
    cdl_image_free(img);
    free(img);
}

int cdl_image_width(const cdl_image *img)
{
    return img ? img->width : 0;
}

int cdl_image_height(const cdl_image *img)
{
    return img ? img->height : 0;
}

float *cdl_image_pixels(cdl_image *img)
{
    return img ? img->rgb : NULL;
}

int cdl_image_save(const cdl_image *img, const char *path, float exposure, cdl_error *err)
{
    if (!img || !path)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_save: no image or no path");
    return cdl_image_write(path, img, NULL, 0, exposure, err);
}

int cdl_image_crop(const cdl_image *img, int x0, int y0, int x1, int y1, cdl_image **out, cdl_error *err)
{
    if (!out || !img)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_crop: no image or no place for the crop");
    *out = NULL;
    if (x0 < 0 || y0 < 0 || x1 <= x0 || y1 <= y0 || x1 > img->width || y1 > img->height)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "crop %d,%d,%d,%d is empty or reaches outside the %dx%d image",
                             x0, y0, x1, y1, img->width, img->height);
    int rc = cdl_image_create(x1 - x0, y1 - y0, out, err);
    for (int y = 0; !rc && y < y1 - y0; y++)
        memcpy((*out)->rgb + (size_t)3 * (size_t)(*out)->width * (size_t)y,
               img->rgb + 3 * ((size_t)img->width * (size_t)(y + y0) + (size_t)x0),
               sizeof(float) * 3 * (size_t)(*out)->width);
    return rc;
}

int cdl_image_diff(const cdl_image *test, const cdl_image *ref, cdl_diff *out, cdl_error *err)
{
    if (!test || !ref || !out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_diff: no image or no result");
    cdl_metrics m;
    int rc = cdl_image_compare(test, ref, &m, err);
    if (rc)
        return rc;
    *out = (cdl_diff){m.rmse,
                      m.relmse,
                      m.mae,
                      m.mean_ratio,
                      m.relmse_trimmed,
                      cdl_image_block_median_ratio(test, ref, 16),
                      cdl_image_block_rms_dev(test, ref, 32),
                      m.mean_test,
                      m.mean_ref};
    return 0;
}

int cdl_image_diff_heatmap(const cdl_image *test, const cdl_image *ref, cdl_image **out, cdl_error *err)
{
    if (!test || !ref || !out)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_diff_heatmap: no image or no result");
    int rc = new_image(out, err);
    if (!rc && (rc = cdl_image_heatmap(test, ref, *out, err))) {
        free(*out);
        *out = NULL;
    }
    return rc;
}

int cdl_image_flip(const cdl_image *test, const cdl_image *ref, int hdr, double ppd, double *mean,
                   cdl_image **map, cdl_error *err)
{
    if (map)
        *map = NULL;
    if (!test || !ref || !mean)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_flip: no image or no place for the mean");
    if (hdr != 0 && hdr != 1)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_image_flip: hdr must be 0 or 1, got %d", hdr);
    cdl_image *m = NULL;
    float *values = NULL;
    int rc = 0;
    if (map) {
        size_t n = (size_t)test->width * (size_t)test->height;
        if (!(rc = new_image(&m, err)) && !(rc = cdl_image_alloc(m, test->width, test->height, err)) &&
            !(values = malloc(n * sizeof *values)))
            rc = cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    }
    if (!rc)
        rc = cdl_flip(test, ref, hdr, ppd, values, mean, NULL, err);
    if (!rc && m) {
        size_t n = (size_t)test->width * (size_t)test->height;
        for (size_t p = 0; p < n; p++)
            cdl_flip_magma(values[p], m->rgb + 3 * p);
        *map = m;
    } else if (m) {
        cdl_image_free(m);
        free(m);
    }
    free(values);
    return rc;
}
