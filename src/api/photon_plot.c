/* The stored photons (and, with importance, the importons) seen from
 * above, as in Keller & Wald's Figures 1, 2 and 4 (`candela photons`).
 * Pass 0's maps are traced exactly as pm's first pass traces them; walls
 * (faces parallel to the up axis) are drawn grey so that rooms without
 * photons stay visible. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <stdlib.h>

#include "api/resolve.h"
#include "core/log.h"
#include "film/image.h"
#include "integrators/pm.h"

typedef struct view {
    int up, u, v; /* axes */
    float u0, v0, scale;
    cdl_image img;
} view;

static void view_init(view *w, const cdl_scene *s, const cdl_camera *cam, int size, cdl_error *err, int *rc)
{
    float c[3] = {fabsf(cam->up.x), fabsf(cam->up.y), fabsf(cam->up.z)};
    w->up = c[1] >= c[0] && c[1] >= c[2] ? 1 : (c[2] >= c[0] ? 2 : 0);
    /* y up: x to the right, z down the image (a plan seen from above) */
    w->u = w->up == 0 ? 1 : 0;
    w->v = w->up == 2 ? 1 : 2;
    float mn[3] = {s->bmin.x, s->bmin.y, s->bmin.z}, mx[3] = {s->bmax.x, s->bmax.y, s->bmax.z};
    float eu = mx[w->u] - mn[w->u], ev = mx[w->v] - mn[w->v];
    float e = eu > ev ? eu : ev;
    w->scale = e > 0.0f ? (float)(size - 1) / e : 1.0f;
    w->u0 = mn[w->u];
    w->v0 = mn[w->v];
    int iw = (int)(eu * w->scale) + 1, ih = (int)(ev * w->scale) + 1;
    *rc = cdl_image_alloc(&w->img, iw < 1 ? 1 : iw, ih < 1 ? 1 : ih, err);
}

static void plot(view *w, const float *p, const float col[3])
{
    int x = (int)((p[w->u] - w->u0) * w->scale), y = (int)((p[w->v] - w->v0) * w->scale);
    if (x < 0 || y < 0 || x >= w->img.width || y >= w->img.height)
        return;
    float *px = w->img.rgb + 3 * ((size_t)y * (size_t)w->img.width + (size_t)x);
    for (int k = 0; k < 3; k++)
        px[k] = fminf(1.0f, px[k] + col[k]);
}

static void walls(view *w, const cdl_scene *s)
{
    static const float grey[3] = {0.12f, 0.12f, 0.12f};
    for (uint32_t t = 0; t < s->ntris; t++) {
        const float *n = &s->face_n[t].x;
        if (fabsf(n[w->up]) > 0.1f)
            continue;
        for (int e = 0; e < 3; e++) {
            const float *a = s->pos + 3 * (size_t)s->idx[3 * t + (uint32_t)e];
            const float *b = s->pos + 3 * (size_t)s->idx[3 * t + (uint32_t)(e + 1) % 3];
            float len = hypotf(b[w->u] - a[w->u], b[w->v] - a[w->v]) * w->scale;
            int steps = (int)len + 1;
            for (int i = 0; i <= steps; i++) {
                float f = (float)i / (float)steps, q[3];
                for (int k = 0; k < 3; k++)
                    q[k] = a[k] + f * (b[k] - a[k]);
                view *ww = w;
                int x = (int)((q[ww->u] - ww->u0) * ww->scale), y = (int)((q[ww->v] - ww->v0) * ww->scale);
                if (x >= 0 && y >= 0 && x < ww->img.width && y < ww->img.height) {
                    float *px = ww->img.rgb + 3 * ((size_t)y * (size_t)ww->img.width + (size_t)x);
                    for (int k = 0; k < 3; k++)
                        px[k] = fmaxf(px[k], grey[k]);
                }
            }
        }
    }
}

/* A heap copy of the view's image for the caller. */
static int hand_over(view *w, cdl_image **out, cdl_error *err)
{
    *out = malloc(sizeof **out);
    if (!*out)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    **out = w->img;
    w->img = (cdl_image){0};
    return 0;
}

int cdl_photon_plot(cdl_scene *scene, const cdl_settings *settings, int size, cdl_image **photons,
                    cdl_image **importons, char *summary, size_t nsummary, cdl_error *err)
{
    if (!photons || !scene)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "cdl_photon_plot: no scene or no place for the image");
    *photons = NULL;
    if (importons)
        *importons = NULL;
    if (summary && nsummary)
        summary[0] = 0;
    if (size < 16 || size > 16384)
        return cdl_error_set(err, CDL_ERR_USAGE, "", 0, "plot size %d out of range [16, 16384]", size);
    /* pm's photons, whatever method the settings name */
    cdl_settings *pm = cdl_settings_create(), *set = malloc(sizeof *set);
    if (!pm || !set) {
        cdl_settings_release(pm);
        free(set);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "", 0, "out of memory");
    }
    if (settings)
        *pm = *settings;
    cdl_options opt;
    int rc = cdl_settings_set(pm, "integrator", "pm", err);
    if (!rc)
        rc = cdl_settings_resolve(pm, scene, set, &opt, err);
    cdl_settings_release(pm);
    if (rc) {
        free(set);
        return rc;
    }
    const cdl_log_sink *prev = cdl_log_push(&set->sink);
    cdl_importance imp;
    cdl_photon_map g, c;
    cdl_pmap_init(&g);
    cdl_pmap_init(&c);
    view pv = {0}, iv = {0};
    cdl_walk walk = {opt.maxdepth, opt.rr_depth, 0};
    float r = 0.0f;
    cdl_photon_params pp = {0};
    rc = cdl_pm_max_radius(scene, &opt.pm, &r, err);
    if (!rc)
        rc = cdl_pm_photon_setup(scene, &opt, &walk, r, &pp, &imp, err);
    int has_imp = !rc && pp.imp != NULL;
    cdl_photon_stats ps;
    if (!rc)
        rc = cdl_photons_trace(scene, &walk, &pp, opt.sampler, opt.seed, 0, &g, &c, &ps, err);
    if (!rc)
        view_init(&pv, scene, &opt.camera, size, err, &rc);
    if (!rc && has_imp && importons)
        view_init(&iv, scene, &opt.camera, size, err, &rc);
    if (!rc) {
        /* dots bright enough to see single photons, saturating in dense regions */
        static const float gcol[3] = {0.5f, 0.42f, 0.2f}, ccol[3] = {0.15f, 0.3f, 0.5f},
                           icol[3] = {0.5f, 0.15f, 0.15f};
        walls(&pv, scene);
        for (uint32_t i = 0; i < g.n; i++)
            plot(&pv, g.ph[i].p, gcol);
        for (uint32_t i = 0; i < c.n; i++)
            plot(&pv, c.ph[i].p, ccol);
        if (has_imp && importons) {
            walls(&iv, scene);
            for (uint32_t i = 0; i < imp.n; i++)
                plot(&iv, imp.pts + 4 * (size_t)i, icol);
        }
        rc = hand_over(&pv, photons, err);
        if (!rc && has_imp && importons && (rc = hand_over(&iv, importons, err))) {
            cdl_image_release(*photons);
            *photons = NULL;
        }
    }
    if (!rc && summary && nsummary) {
        size_t len = (size_t)snprintf(summary, nsummary,
                                      "%llu photon paths (%llu for the global map), %u global + %u caustic photons "
                                      "stored of %llu hits, %.2f MiB",
                                      (unsigned long long)ps.paths, (unsigned long long)ps.paths_global, g.n, c.n,
                                      (unsigned long long)ps.candidates,
                                      (double)(cdl_pmap_bytes(&g) + cdl_pmap_bytes(&c)) / (1024.0 * 1024.0));
        if (has_imp && len < nsummary)
            snprintf(summary + len, nsummary - len, "; %u importons from %llu paths, f = %.4g", imp.n,
                     (unsigned long long)imp.paths, imp.f);
    }
    cdl_image_free(&pv.img);
    cdl_image_free(&iv.img);
    cdl_pmap_free(&g);
    cdl_pmap_free(&c);
    if (has_imp)
        cdl_importance_free(&imp);
    cdl_log_pop(prev);
    free(set);
    return rc;
}
