#include "film/film.h"

#include <math.h>
#include <stdio.h>
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
    free(f->splat);
    for (int i = 0; i < f->naovs; i++)
        free(f->aovs[i].sum);
    free(f->aovs);
    f->sum = NULL;
    f->count = NULL;
    f->splat = NULL;
    f->aovs = NULL;
    f->naovs = 0;
}

int cdl_film_add_aov(cdl_film *f, const char *name, int channels, cdl_error *err)
{
    if (f->naovs >= CDL_MAX_AOVS || (channels != 1 && channels != 3)) {
        cdl_error_set(err, CDL_ERR_USAGE, "aov", 0, "too many output layers");
        return -1;
    }
    if (!f->aovs && !(f->aovs = calloc(CDL_MAX_AOVS, sizeof(cdl_aov)))) {
        cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
        return -1;
    }
    cdl_aov *a = &f->aovs[f->naovs];
    snprintf(a->name, sizeof a->name, "%s", name);
    a->channels = channels;
    a->sum = calloc((size_t)channels * (size_t)f->width * (size_t)f->height, sizeof(double));
    if (!a->sum) {
        cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory for layer %s", name);
        return -1;
    }
    return f->naovs++;
}

int cdl_film_find_aov(const cdl_film *f, const char *name)
{
    for (int i = 0; i < f->naovs; i++)
        if (!strcmp(f->aovs[i].name, name))
            return i;
    return -1;
}

int cdl_film_resolve_aov(const cdl_film *f, int a, cdl_image *img, cdl_error *err)
{
    int rc = cdl_image_alloc(img, f->width, f->height, err);
    if (rc)
        return rc;
    const cdl_aov *av = &f->aovs[a];
    size_t n = (size_t)f->width * (size_t)f->height;
    for (size_t i = 0; i < n; i++) {
        double w = f->count[i] ? 1.0 / f->count[i] : 0.0;
        for (int k = 0; k < 3; k++)
            img->rgb[3 * i + k] = (float)(av->sum[(size_t)av->channels * i + (av->channels == 3 ? k : 0)] * w);
    }
    return 0;
}

int cdl_splats_add(cdl_splats *sp, uint32_t pixel, cdl_vec3 L)
{
    if (sp->n == sp->cap) {
        uint32_t cap = sp->cap ? 2 * sp->cap : 1024;
        uint32_t *p = realloc(sp->pixel, sizeof(uint32_t) * cap);
        if (p)
            sp->pixel = p;
        float *c = realloc(sp->rgb, sizeof(float) * 3 * cap);
        if (c)
            sp->rgb = c;
        if (!p || !c)
            return -1;
        sp->cap = cap;
    }
    sp->pixel[sp->n] = pixel;
    sp->rgb[3 * sp->n] = L.x;
    sp->rgb[3 * sp->n + 1] = L.y;
    sp->rgb[3 * sp->n + 2] = L.z;
    sp->n++;
    return 0;
}

int cdl_splats_add_filtered(cdl_splats *sp, const cdl_filter *f, int w, int h, float x, float y, cdl_vec3 L)
{
    int pix[CDL_FILTER_MAX_TAPS];
    float wt[CDL_FILTER_MAX_TAPS];
    int n = cdl_filter_spread(f, x, y, w, h, pix, wt);
    for (int i = 0; i < n; i++)
        if (cdl_splats_add(sp, (uint32_t)pix[i], cdl_scale(L, wt[i])))
            return -1;
    return 0;
}

void cdl_splats_free(cdl_splats *sp)
{
    free(sp->pixel);
    free(sp->rgb);
    sp->pixel = NULL;
    sp->rgb = NULL;
    sp->n = sp->cap = 0;
}

uint64_t cdl_film_merge_splats(cdl_film *f, cdl_splats *sp)
{
    uint64_t bad = 0;
    if (!f->splat && sp->n) {
        f->splat = calloc(3 * (size_t)f->width * (size_t)f->height, sizeof(double));
        if (!f->splat) {
            sp->n = 0;
            return 0;
        }
    }
    for (uint32_t i = 0; i < sp->n; i++) {
        const float *c = sp->rgb + 3 * (size_t)i;
        if (!isfinite(c[0]) || !isfinite(c[1]) || !isfinite(c[2])) {
            bad++;
            continue;
        }
        double *d = f->splat + 3 * (size_t)sp->pixel[i];
        d[0] += c[0];
        d[1] += c[1];
        d[2] += c[2];
    }
    sp->n = 0;
    return bad;
}

int cdl_film_resolve(const cdl_film *f, cdl_image *img, cdl_error *err)
{
    int rc = cdl_image_alloc(img, f->width, f->height, err);
    if (rc)
        return rc;
    size_t n = (size_t)f->width * (size_t)f->height;
    double ws = f->splat_passes ? 1.0 / f->splat_passes : 0.0;
    for (size_t i = 0; i < n; i++) {
        double w = f->count[i] ? 1.0 / f->count[i] : 0.0;
        for (int k = 0; k < 3; k++)
            img->rgb[3 * i + k] =
                (float)(f->sum[3 * i + k] * w + (f->splat ? f->splat[3 * i + k] * ws : 0.0));
    }
    return 0;
}

/* Layout: sum (3n), count (n), splat (3n, zeros without splats),
 * splat_passes, rays, nonfinite, then each AOV's sums. */
size_t cdl_film_accum_size(const cdl_film *f)
{
    size_t n = (size_t)f->width * (size_t)f->height, k = 7 * n + 3;
    for (int a = 0; a < f->naovs; a++)
        k += (size_t)f->aovs[a].channels * n;
    return k;
}

void cdl_film_accum_get(const cdl_film *f, double *out)
{
    size_t n = (size_t)f->width * (size_t)f->height;
    memcpy(out, f->sum, sizeof(double) * 3 * n);
    out += 3 * n;
    for (size_t i = 0; i < n; i++)
        out[i] = (double)f->count[i];
    out += n;
    if (f->splat)
        memcpy(out, f->splat, sizeof(double) * 3 * n);
    else
        memset(out, 0, sizeof(double) * 3 * n);
    out += 3 * n;
    out[0] = (double)f->splat_passes;
    out[1] = (double)f->rays;
    out[2] = (double)f->nonfinite;
    out += 3;
    for (int a = 0; a < f->naovs; a++) {
        size_t m = (size_t)f->aovs[a].channels * n;
        memcpy(out, f->aovs[a].sum, sizeof(double) * m);
        out += m;
    }
}

int cdl_film_accum_set(cdl_film *f, const double *in, cdl_error *err)
{
    size_t n = (size_t)f->width * (size_t)f->height;
    const double *c = in + 3 * n, *sp = in + 4 * n, *tail = in + 7 * n;
    for (size_t i = 0; i < n; i++)
        if (!(c[i] >= 0.0 && c[i] <= (double)UINT32_MAX && c[i] == floor(c[i])))
            return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "film accumulators: sample count %g is not a count", c[i]);
    for (int k = 0; k < 3; k++)
        if (!(tail[k] >= 0.0 && tail[k] <= 1.8e19 && tail[k] == floor(tail[k])))
            return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "film accumulators: counter %g is not a count", tail[k]);
    int any_splat = 0;
    for (size_t i = 0; i < 3 * n && !any_splat; i++)
        any_splat = sp[i] != 0.0;
    if (any_splat && !f->splat && !(f->splat = calloc(3 * n, sizeof(double))))
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    memcpy(f->sum, in, sizeof(double) * 3 * n);
    for (size_t i = 0; i < n; i++)
        f->count[i] = (uint32_t)c[i];
    if (f->splat)
        memcpy(f->splat, sp, sizeof(double) * 3 * n);
    f->splat_passes = (uint32_t)fmin(tail[0], (double)UINT32_MAX);
    f->rays = (uint64_t)tail[1];
    f->nonfinite = (uint64_t)tail[2];
    in = tail + 3;
    for (int a = 0; a < f->naovs; a++) {
        size_t m = (size_t)f->aovs[a].channels * n;
        memcpy(f->aovs[a].sum, in, sizeof(double) * m);
        in += m;
    }
    return 0;
}
