/* splat: global illumination by photon ray splatting (Herzog et al. 2007).
 *
 * Each pass (§3):
 *  1. eye pass: eye_samples jittered camera rays per pixel follow
 *     specular surfaces (transport/visible.c) to an eye sample: position,
 *     the normal of the side seen, BSDF, direction to the camera, pixel,
 *     weight; emission met on the way (and, with direct sample, light
 *     sampled at the sample) goes straight to the pixel; so does the
 *     direct light of lights at infinity, always by light sampling (their
 *     photon paths start on a disk outside the scene, and that first ray
 *     is not splatted);
 *  2. the eye-sample kd-tree (spatial/splatkd.c, §5.1);
 *  3. light pass: photon rays with path-density bandwidths
 *     (transport/photon_rays.c, §4.2), every kernel scaled by the pass's
 *     factor of the progressive schedule (cdl_progressive_r2: about
 *     pass^(-1/6) at alpha 2/3, what eq. 4.9's M^(-1/6) gives when M grows
 *     with the passes), so the average converges; progressive off keeps
 *     the report's bandwidths in every pass;
 *  4. every photon ray splats to the eye samples in its frustum
 *     (Algorithms 1, 2) into the radiance maps (maps.c, §6.1);
 *  5. the BSDF applied to each sample's map gives the pass's image.
 * Passes average progressively. Deterministic for a seed on any number of
 * threads. */
#include "integrators/splat/state.h"
#include "integrators/splat/maps.h"
#include "integrators/splat/cache.h"
#include "integrators/splat/mask.h"
#include "integrators/splat/occlusion.h"
#include "integrators/splat/filter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/log.h"
#include "core/morton.h"
#include "core/radix.h"
#include "transport/light_select.h"
#include "transport/visible.h"

#define PILOT_PATHS 20000

static int splat_prepare(void *self, const cdl_scene *scene, const cdl_options *opt, cdl_error *err)
{
    splat_state *s = self;
    s->scene = scene;
    s->opt = *opt;
    s->walk.maxdepth = opt->maxdepth;
    s->walk.rr_depth = opt->rr_depth;
    s->opt.splat.direct_sample = opt->splat.direct == CDL_SPLAT_DIRECT_SAMPLE;
    s->opt.splat.direct_none = opt->splat.direct == CDL_SPLAT_DIRECT_NONE;
    const cdl_splat_options *o = &s->opt.splat;
    if (o->visibility_mask && o->cache > 0.0f)
        return cdl_error_set(err, CDL_ERR_USAGE, "visibility_mask", 0,
                             "works without cache (records are splatted without masks)");
    if (o->visibility_mask && splat_mask_alloc(s, err))
        return err->code;
    if (!scene->nlights)
        return cdl_error_set(err, CDL_ERR_INPUT, scene->path, 0, "the scene has no lights: nothing to render");
    /* direct none without gathering: no direct photons, their share
     * goes to the others (gather rays' hits always need them) */
    float fd = o->direct_none && !o->gather ? 0.0f : o->fractions[0];
    float fsum = fd + o->fractions[1] + o->fractions[2];
    if (!(fsum > 0.0f))
        return cdl_error_set(err, CDL_ERR_USAGE, "fractions", 0, "at least one share must be positive");
    /* a scene without specular surfaces has no caustic rays: that share
     * goes to the indirect budget instead of tracing paths in vain */
    int specular = 0;
    for (uint32_t m = 0; m < scene->nmats; m++)
        specular |= cdl_mat_is_delta(scene->mats[m].type);
    /* lights at infinity emit no direct photons (their first ray starts on
     * the disk outside the scene): with no other light the direct share
     * stays unused, as with direct sample */
    int finite = 0;
    for (uint32_t i = 0; i < scene->nlights; i++) {
        if (cdl_light_at_infinity(&scene->lights[i]))
            s->at_infinity = 1;
        else if (scene->light_select.pmf[i] > 0.0f)
            finite = 1;
    }
    s->no_photons = !finite && opt->maxdepth <= 1;
    float share[CDL_PRAY_CATS] = {fd, o->fractions[1], o->fractions[2]};
    if (!specular) {
        share[CDL_PRAY_INDIRECT] += share[CDL_PRAY_CAUSTIC];
        share[CDL_PRAY_CAUSTIC] = 0.0f;
    }
    for (int c = 0; c < CDL_PRAY_CATS; c++) {
        float f = share[c] / fsum;
        /* with light sampling the direct share stays unused (gather
         * rays' hits need direct photons all the same) */
        if (c == CDL_PRAY_DIRECT && ((o->direct_sample && !o->gather) || !finite))
            f = 0.0f;
        s->pp.target[c] = s->no_photons ? 0 : (uint32_t)lrint((double)f * opt->photons);
    }
    if (!s->pp.target[0] && !s->pp.target[1] && !s->pp.target[2] && !s->no_photons)
        return cdl_error_set(err, CDL_ERR_USAGE, "fractions", 0,
                             "no photon budget left (with direct sample, or only lights at infinity, the direct "
                             "share is unused)");
    s->pp.C = o->C;
    s->pp.S = o->S;
    s->pp.R = o->R;
    float diag = cdl_length(cdl_sub(scene->bmax, scene->bmin));
    float dt = 0.01f * diag; /* D~: 1 % of the scene's diagonal */
    s->pp.d2_clamp = dt * dt;
    s->pp.max_paths = (uint64_t)opt->photons * 100u > (1u << 20) ? (uint64_t)opt->photons * 100u : (1u << 20);
    cdl_skd_params_default(&s->kp, diag);
    s->kp.part_depth = 4;
    if (!o->cull)
        s->kp.cull_deg = -1.0f;
    if (o->gather && (o->cache > 0.0f || o->filter > 0.0f || o->mode != CDL_SPLAT_DIRECT))
        return cdl_error_set(err, CDL_ERR_USAGE, "gather", 0,
                             "final gathering splats to the gather rays' hits directly: no cache, filter "
                             "or mode histogram|sh");
    size_t npix = (size_t)opt->camera.width * (size_t)opt->camera.height;
    /* final gathering: G eye samples per camera sample, in bands of rows
     * holding at most SPLAT_BAND_SLOTS (the report renders tiles) */
    s->G = o->gather ? o->gather : 1;
    size_t row = (size_t)opt->camera.width * o->eye_samples * s->G;
    s->band_rows = o->gather ? (int)(SPLAT_BAND_SLOTS / row) : opt->camera.height;
    if (s->band_rows < 1)
        s->band_rows = 1;
    if (s->band_rows > opt->camera.height)
        s->band_rows = opt->camera.height;
    if (row * (size_t)s->band_rows > UINT32_MAX / 2)
        return cdl_error_set(err, CDL_ERR_USAGE, "res", 0, "too many eye samples per pass");
    s->nslots = (uint32_t)(row * (size_t)s->band_rows);
    s->base = calloc(npix, sizeof *s->base);
    s->dz = calloc(npix, sizeof *s->dz);
    s->dn = calloc(npix, sizeof *s->dn);
    s->pix = calloc(npix, sizeof *s->pix);
    s->slot = malloc(sizeof *s->slot * s->nslots);
    s->sb = malloc(sizeof *s->sb * s->nslots);
    s->sp = malloc(sizeof *s->sp * s->nslots);
    s->sn = malloc(sizeof *s->sn * s->nslots);
    s->sflags = malloc(s->nslots);
    s->svalid = malloc(s->nslots);
    if (!s->base || !s->dz || !s->dn || !s->pix || !s->slot || !s->sb || !s->sp || !s->sn || !s->sflags || !s->svalid)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for %u eye samples", s->nslots);
    return splat_maps_init(s, err);
}

/* An eye sample at v into slot k: its pixel, weight and footprint pw. */
static void fill_slot(splat_state *s, uint32_t k, const cdl_visible *v, cdl_vec3 weight, uint32_t p, float pw)
{
    splat_eye *e = &s->slot[k];
    e->kd = v->b.kd;
    e->bsdf = v->b.type == CDL_MAT_DIFFUSE ? SPLAT_LAMBERT : k;
    if (e->bsdf != SPLAT_LAMBERT)
        s->sb[k] = v->b;
    e->weight = weight;
    e->wo = v->wo;
    e->pixel = p;
    e->mat = v->sf.mat;
    e->pw = pw;
    cdl_vec3 ng = cdl_dot(v->sf.ng, v->wo) < 0.0f ? cdl_neg(v->sf.ng) : v->sf.ng;
    cdl_vec3 n = v->b.frame.n;
    if (cdl_dot(n, v->wo) < 0.0f)
        n = cdl_neg(n);
    cdl_vec3 t = cdl_sub(v->wo, cdl_scale(n, cdl_dot(v->wo, n)));
    float tl = cdl_length(t);
    cdl_frame f = cdl_frame_from(n);
    if (tl > 1e-6f) {
        f.t = cdl_scale(t, 1.0f / tl);
        f.b = cdl_cross(n, f.t);
    }
    e->f = f;
    s->sp[k] = v->sf.p;
    s->sn[k] = ng;
    s->sflags[k] = v->b.type == CDL_MAT_ROUGH_DIELECTRIC ? CDL_SKD_TWO_SIDED : 0;
    s->svalid[k] = 1;
}

/* Final gathering from the camera's point v (§6.4): G rays by BSDF
 * sampling, each an eye sample where it lands (after specular surfaces)
 * weighing what the photon rays bring there; emission a gather ray meets
 * after a specular bounce is a caustic path no photon estimate holds, so
 * it goes to the pixel; emission it meets first is the light sampled at v. */
static cdl_vec3 gather(splat_state *s, const cdl_visible *v, cdl_vec3 w, uint32_t k0, uint32_t p, cdl_sampler *smp,
                       uint64_t *rays)
{
    const cdl_scene *sc = s->scene;
    uint32_t G = s->opt.splat.gather;
    cdl_vec3 L = cdl_v3(0.0f, 0.0f, 0.0f);
    /* a gather ray's share of the hemisphere, as a footprint (for masks) */
    float spread = sqrtf(2.0f * (float)CDL_PI / (float)G);
    for (uint32_t g = 0; g < G; g++) {
        cdl_scatter sct;
        float u0 = cdl_sampler_1d(smp), u1, u2;
        cdl_sampler_2d(smp, &u1, &u2);
        if (!cdl_bsdf_sample(&v->b, v->wo, u0, u1, u2, 0, &sct) || cdl_is_black(sct.weight))
            continue;
        cdl_vec3 wg = cdl_scale(cdl_mul(w, sct.weight), 1.0f / (float)G);
        cdl_visible vg;
        int hit = cdl_find_visible(sc, cdl_offset(sc, v->sf.p, v->sf.ng, sct.wi), sct.wi, s->opt.maxdepth - 1, smp,
                                   rays, &vg);
        if (vg.depth > 0)
            L = cdl_add(L, cdl_mul(wg, vg.L));
        if (!hit)
            continue;
        cdl_vec3 wh = cdl_mul(wg, vg.beta);
        fill_slot(s, k0 + g, &vg, wh, p, vg.dist * spread);
        /* no photon brings the lights at infinity's direct light there */
        if (s->at_infinity && v->depth + vg.depth + 2 <= s->opt.maxdepth)
            L = cdl_add(L, cdl_mul(wh, cdl_direct_light_infinite(sc, &vg.sf, &vg.b, vg.wo, smp, rays)));
    }
    return L;
}

/* Step 1 for pixel row y: its eye samples into their slots (slots count
 * from the band's first row y0; s->G per camera sample: gather rays or 1). */
static void eye_row(splat_state *s, int y, int y0, uint32_t pass, const cdl_direct_cfg *dc, cdl_lcon_scratch *lc,
                    uint64_t *rays)
{
    const cdl_camera *cam = &s->opt.camera;
    const cdl_scene *sc = s->scene;
    uint32_t E = s->opt.splat.eye_samples, G = s->G;
    int direct = (s->opt.splat.direct_sample || s->opt.splat.gather) && !s->opt.splat.direct_none;
    for (int x = 0; x < cam->width; x++) {
        uint32_t p = (uint32_t)y * (uint32_t)cam->width + (uint32_t)x;
        uint32_t pb = p - (uint32_t)y0 * (uint32_t)cam->width;
        cdl_vec3 base = cdl_v3(0.0f, 0.0f, 0.0f);
        s->dz[p] = 0.0f;
        for (uint32_t j = 0; j < E; j++) {
            uint32_t k = p * E + j, k0 = (pb * E + j) * G;
            memset(s->svalid + k0, 0, G);
            cdl_sampler smp;
            float jx, jy;
            cdl_sampler_start(&smp, s->opt.sampler, s->opt.seed, k, pass);
            cdl_sampler_2d(&smp, &jx, &jy);
            cdl_visible v;
            cdl_vec3 dir = cdl_camera_ray(cam, (float)x + jx, (float)y + jy);
            int hit = cdl_find_visible(sc, cam->eye, dir, s->opt.maxdepth, &smp, rays, &v);
            base = cdl_add(base, v.L);
            if (!hit)
                continue;
            if (direct) {
                uint32_t nl = 0;
                cdl_vec3 Ld = cdl_direct_light(sc, dc, lc, &v.sf, &v.b, v.wo, &smp, rays, &nl);
                base = cdl_add(base, cdl_mul(v.beta, Ld));
            } else if (s->at_infinity && !s->opt.splat.direct_none) {
                /* direct photons come from the other lights only */
                cdl_vec3 Ld = cdl_direct_light_infinite(sc, &v.sf, &v.b, v.wo, &smp, rays);
                base = cdl_add(base, cdl_mul(v.beta, Ld));
            }
            cdl_vec3 w = cdl_scale(v.beta, 1.0f / (float)E);
            if (s->opt.splat.gather) {
                if (v.depth + 1 < s->opt.maxdepth)
                    base = cdl_add(base, cdl_scale(gather(s, &v, w, k0, p, &smp, rays), (float)E));
                continue;
            }
            fill_slot(s, k0, &v, w, p, v.dist * 2.0f * cam->tan_half / (float)cam->height);
            if (s->dz[p] == 0.0f) { /* the discontinuity buffer: the pixel's first sample */
                s->dz[p] = v.dist * cdl_dot(dir, cam->fwd);
                s->dn[p] = s->slot[k0].f.n;
            }
        }
        s->base[p] = cdl_scale(base, 1.0f / (float)E);
    }
}

static int eye_pass(splat_state *s, uint32_t pass, int y0, int y1, uint64_t *rays, cdl_error *err)
{
    uint64_t r = 0;
    int fail = 0;
#pragma omp parallel reduction(+ : r)
    {
        cdl_lcon_scratch lc;
        int ok = cdl_lcon_scratch_init(&lc, s->scene->nlights) == 0;
        cdl_direct_cfg dc = {CDL_DIRECT_POWER, 1, NULL, 0.0f};
#pragma omp for schedule(dynamic, 4)
        for (int y = y0; y < y1; y++)
            if (ok)
                eye_row(s, y, y0, pass, &dc, &lc, &r);
        if (!ok) {
#pragma omp atomic write
            fail = 1;
        }
        if (ok)
            cdl_lcon_scratch_free(&lc);
    }
    *rays += r;
    if (fail)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory");
    /* the valid slots, in slot order, become the eye samples */
    uint32_t n = 0, nk = (uint32_t)(y1 - y0) * (uint32_t)s->opt.camera.width * s->opt.splat.eye_samples * s->G;
    for (uint32_t k = 0; k < nk; k++)
        if (s->svalid[k] && n == k) { /* in place until the first invalid one */
            n++;
        } else if (s->svalid[k]) {
            s->slot[n] = s->slot[k];
            s->sp[n] = s->sp[k];
            s->sn[n] = s->sn[k];
            s->sflags[n] = s->sflags[k];
            n++;
        }
    s->neye = n;
    return 0;
}

/* Step 2: the tree, the samples moved into its order, the maps sized. */
static int build(splat_state *s, cdl_error *err)
{
    cdl_skd_free(&s->tree);
    if (cdl_skd_build(&s->tree, s->sp, s->sn, s->sflags, s->neye, &s->kp, err))
        return err->code;
    if (!s->eye && !(s->eye = malloc(sizeof *s->eye * (s->nslots ? s->nslots : 1))))
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the eye samples");
    /* records gathered from all over: in parallel */
#pragma omp parallel for schedule(static)
    for (uint32_t q = 0; q < s->neye; q++)
        s->eye[q] = s->slot[s->tree.order[q]];
    return splat_maps_alloc(s, err);
}

/* The rays put in Morton order of their ends (the report's presorting of
 * photon rays): consecutive rays meet the same nodes and eye samples, so
 * the traversal's branches repeat and the samples stay in cache. Keys are
 * 30-bit Morton codes over the ray index, sorted by three stable radix
 * passes of 10 bits (the order of a sort on (code, index)); the rays are
 * then gathered in parallel into a new array (a cycle-by-cycle walk in
 * place, a chain of dependent cache misses, is the fallback without the
 * memory for one). */
static int sort_rays(splat_state *s, cdl_error *err)
{
    uint32_t n = s->rays.n;
    uint64_t *key = malloc(sizeof *key * (n ? n : 1)), *tmp = malloc(sizeof *tmp * (n ? n : 1));
    if (!key || !tmp) {
        free(key);
        free(tmp);
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for %u photon rays", n);
    }
    const float *lo = &s->scene->bmin.x, *hi = &s->scene->bmax.x;
    float ext = cdl_maxf(hi[0] - lo[0], cdl_maxf(hi[1] - lo[1], hi[2] - lo[2]));
    float sc = ext > 0.0f ? 1023.0f / ext : 0.0f;
    cdl_photon_ray *r = s->rays.r;
#pragma omp parallel for schedule(static)
    for (uint32_t k = 0; k < n; k++) {
        cdl_vec3 e = cdl_add(r[k].o, cdl_scale(r[k].d, r[k].len));
        key[k] = cdl_morton3(&e.x, lo, sc) << 32 | k;
    }
    uint64_t *sorted = cdl_radix_sort_bits(key, tmp, n, 32, 62);
    free(sorted == key ? tmp : key);
    key = sorted;
    cdl_photon_ray *out = malloc(sizeof *out * (s->rays.cap ? s->rays.cap : 1));
    if (out) {
#pragma omp parallel for schedule(static)
        for (uint32_t k = 0; k < n; k++)
            out[k] = r[(uint32_t)key[k]];
        free(r);
        s->rays.r = out;
        free(key);
        return 0;
    }
    /* position k takes ray key[k]; a done position is marked by its key's
     * index set to k */
    for (uint32_t k = 0; k < n; k++) {
        uint32_t src = (uint32_t)key[k];
        if (src == k)
            continue;
        cdl_photon_ray t = r[k];
        uint32_t j = k;
        while (src != k) {
            r[j] = r[src];
            key[j] = (key[j] & ~(uint64_t)UINT32_MAX) | j;
            j = src;
            src = (uint32_t)key[j];
        }
        r[j] = t;
        key[j] = (key[j] & ~(uint64_t)UINT32_MAX) | j;
    }
    free(key);
    return 0;
}

static size_t bytes(const splat_state *s)
{
    /* sb: the pages of the non-Lambertian samples' slots (about gcap) */
    return (size_t)s->nslots * (2 * sizeof(splat_eye) + 2 * sizeof(cdl_vec3) + 2) + (size_t)s->gcap * sizeof(cdl_bsdf) +
           splat_maps_bytes(s) +
           cdl_skd_bytes(&s->tree) + (size_t)s->rays.cap * sizeof(cdl_photon_ray) +
           splat_mask_bytes(s) + splat_occl_bytes(s) +
           (size_t)s->opt.camera.width * s->opt.camera.height * 2 * sizeof(cdl_vec3);
}

/* Step 3: this pass's photon rays, sorted (the same for every band). */
static int photon_rays(splat_state *s, cdl_film *film, uint32_t pass, cdl_error *err)
{
    double t0 = cdl_time_now();
    int rc;
    if (s->no_photons) { /* light sampling gives all there is */
        s->rays.n = 0;
        return 0;
    }
    if (!s->have_pilot) {
        rc = cdl_pray_pilot(s->scene, &s->walk, s->opt.sampler, s->opt.seed, PILOT_PATHS, s->pp.S, s->pp.d2_clamp,
                            &s->pp.w, &s->pp.mu, err);
        if (rc)
            return rc;
        s->have_pilot = 1;
    }
    s->pp.bw_scale = sqrt((double)cdl_progressive_r2(&s->opt, pass));
    rc = cdl_pray_trace(s->scene, &s->walk, &s->pp, s->opt.sampler, s->opt.seed, pass, &s->rays, err);
    if (!rc)
        rc = sort_rays(s, err);
    if (rc)
        return rc;
    film->rays += s->rays.rays;
    s->st.rays_stored += s->rays.n;
    s->st.t_light += cdl_time_now() - t0;
    return 0;
}

/* aov bandwidth: per pixel the mean bandwidth of the rays that splatted
 * it, by the rays' depth (2, 3, any), weighted by their kernels. */
static int bandwidth_aov(splat_state *s, cdl_film *film, int a_bw, cdl_error *err)
{
    size_t npix = (size_t)s->opt.camera.width * (size_t)s->opt.camera.height;
    double *acc = calloc(npix * 6, sizeof(double));
    if (!acc)
        return cdl_error_set(err, CDL_ERR_SYSTEM, "splat", 0, "out of memory for the bandwidth picture");
    for (uint32_t q = 0; q < s->neye; q++)
        for (int k = 0; k < 6; k++)
            acc[6 * (size_t)s->eye[q].pixel + k] += s->bw[(size_t)q * SPLAT_BW + k];
    for (size_t p = 0; p < npix; p++)
        for (int c = 0; c < 3; c++) {
            double w = acc[6 * p + 2 * c + 1];
            film->aovs[a_bw].sum[3 * p + c] += w > 0.0 ? acc[6 * p + 2 * c] / w : 0.0;
        }
    free(acc);
    return 0;
}

/* One band of rows [y0, y1) (the whole image unless final gathering makes
 * too many eye samples): eye pass, tree, splats, radiance into s->pix. */
static int band(splat_state *s, cdl_film *film, uint32_t pass, int y0, int y1, cdl_error *err)
{
    double t0 = cdl_time_now();
    int rc = eye_pass(s, pass, y0, y1, &film->rays, err);
    double t1 = cdl_time_now();
    s->st.t_ray += t1 - t0;
    if (!rc)
        rc = build(s, err);
    double t2 = cdl_time_now();
    s->st.t_build += t2 - t1;
    if (!rc && s->opt.splat.occlusion) {
        rc = splat_occl_prepare(s, err);
        s->st.t_occl += cdl_time_now() - t2;
        t2 = cdl_time_now();
    }
    if (rc || cdl_cancelled(s->cancel))
        return rc;
    if (s->opt.splat.cache > 0.0f) {
        rc = splat_cache_solve(s, err); /* counts its own T_solve and T_cache */
        if (rc)
            return rc;
    } else {
        rc = splat_maps_splat(s);
        s->st.t_solve += cdl_time_now() - t2;
        if (rc)
            return cdl_error_set(err, rc, "splat", 0, "out of memory for the visibility masks");
    }
    double t3 = cdl_time_now();
    if (cdl_cancelled(s->cancel))
        return 0;
    rc = splat_filter(s, err);
    if (rc)
        return rc;
    s->st.t_filter += cdl_time_now() - t3;
    int a_rec = cdl_film_find_aov(film, "records");
    if (a_rec >= 0) /* before the maps become radiance */
        for (uint32_t q = 0; q < s->neye; q++) {
            float v[3];
            if (splat_cache_aov(s, q, v))
                for (int c = 0; c < 3; c++)
                    film->aovs[a_rec].sum[3 * (size_t)s->eye[q].pixel + c] +=
                        v[c] / (float)s->opt.splat.eye_samples;
        }
    splat_maps_resolve(s);
    s->st.samples += s->neye;
    s->st.t_brdf += cdl_time_now() - t3;
    return 0;
}

static int splat_render_pass(void *self, cdl_film *film, uint32_t pass, cdl_error *err)
{
    splat_state *s = self;
    s->cancel = film->cancel;
    double t0 = cdl_time_now();
    int a_bw = cdl_film_find_aov(film, "bandwidth");
    if (a_bw >= 0 && s->opt.splat.gather)
        return cdl_error_set(err, CDL_ERR_USAGE, "aov", 0, "bandwidth is not available with gather");
    s->want_bw = a_bw >= 0;
    int rc = photon_rays(s, film, pass, err);
    if (rc)
        return rc;
    const cdl_camera *cam = &s->opt.camera;
    size_t npix = (size_t)cam->width * (size_t)cam->height;
    memset(s->pix, 0, sizeof *s->pix * npix);
    for (int y0 = 0; y0 < cam->height && !rc && !cdl_cancelled(s->cancel); y0 += s->band_rows)
        rc = band(s, film, pass, y0, y0 + s->band_rows < cam->height ? y0 + s->band_rows : cam->height, err);
    if (rc || cdl_cancelled(s->cancel))
        return rc; /* an interrupted pass adds nothing */
    double t4 = cdl_time_now();
    uint64_t bad = 0;
    for (size_t p = 0; p < npix; p++)
        bad += (uint64_t)cdl_film_add(film, (int)(p % (size_t)cam->width), (int)(p / (size_t)cam->width),
                                      cdl_add(s->base[p], s->pix[p]));
    film->nonfinite += bad;
    if (a_bw >= 0 && (rc = bandwidth_aov(s, film, a_bw, err)))
        return rc;
    double t5 = cdl_time_now();
    s->st.t_brdf += t5 - t4;
    s->st.passes++;
    s->st.t_total += t5 - t0;
    size_t b = bytes(s);
    if (b > s->st.peak_bytes)
        s->st.peak_bytes = b;
    return 0;
}

static const char *mode_name(int m)
{
    return m == CDL_SPLAT_HISTOGRAM ? "histogram" : m == CDL_SPLAT_SH ? "sh" : "direct";
}

static void splat_report(const void *self, cdl_stats *out)
{
    const splat_state *s = self;
    const splat_stats *t = &s->st;
    if (!t->passes)
        return;
    double P = (double)t->passes;
    cdl_stats_printf(out, "splat: mode %s, %.0f photon rays per pass (budgets %u/%u/%u, paths %llu/%llu/%llu in the last), "
           "C %.2g S %.2g R %.2g, mean bandwidth scale mu_C %.4g; %.0f eye samples per pass, %.1f splats per "
           "photon ray, %.2f samples tested per splat, %.0f nodes visited per ray; memory %.1f MiB (peak)\n",
           mode_name(s->opt.splat.mode), (double)t->rays_stored / P, s->pp.target[0], s->pp.target[1],
           s->pp.target[2], (unsigned long long)s->rays.paths[0], (unsigned long long)s->rays.paths[1],
           (unsigned long long)s->rays.paths[2], (double)s->pp.C, (double)s->pp.S, (double)s->pp.R, (double)s->pp.mu,
           (double)t->samples / P, t->rays_stored ? (double)t->splats / (double)t->rays_stored : 0.0,
           t->splats ? (double)t->tested / (double)t->splats : 0.0,
           t->rays_stored ? (double)t->nodes / (double)t->rays_stored : 0.0, (double)t->peak_bytes / 1048576.0);
    cdl_stats_printf(out, "splat: time over %u passes %.2f s: T_ray %.2f, T_light %.2f, T_build %.2f, T_solve %.2f, T_cache %.2f, T_brdf %.2f "
           "(eye-sample tree: %u nodes, %u leaves, %u culling, %u empty, depth %u)\n",
           (unsigned)t->passes, t->t_total, t->t_ray, t->t_light, t->t_build, t->t_solve, t->t_cache, t->t_brdf,
           s->tree.nnodes, s->tree.leaves, s->tree.culls, s->tree.empties, s->tree.depth);
    cdl_stats_add(out, "rays_per_pass", (double)t->rays_stored / P);
    cdl_stats_add(out, "splats_per_ray", t->rays_stored ? (double)t->splats / (double)t->rays_stored : 0.0);
    cdl_stats_add(out, "memory_mib", (double)t->peak_bytes / 1048576.0);
    cdl_stats_add(out, "t_ray", t->t_ray);
    cdl_stats_add(out, "t_light", t->t_light);
    cdl_stats_add(out, "t_build", t->t_build);
    cdl_stats_add(out, "t_solve", t->t_solve);
    cdl_stats_add(out, "t_cache", t->t_cache);
    cdl_stats_add(out, "t_brdf", t->t_brdf);
    splat_cache_report(s, out);
    if (s->mask)
        cdl_stats_printf(out, "splat: visibility mask: %.1f %% of the eye samples may hide others, %.1f %% of the "
               "photon rays met one and got a buffer (%.1f %% of those with planes); %.1f occluders tested and %.1f "
               "rasterized per photon ray, %.1f %% of the feasible splats masked\n",
               t->samples ? 100.0 * (double)t->mask_occ / (double)t->samples : 0.0,
               t->rays_stored ? 100.0 * (double)t->mask_buffers / (double)t->rays_stored : 0.0,
               t->mask_buffers ? 100.0 * (double)t->mask_planar / (double)t->mask_buffers : 0.0,
               t->rays_stored ? (double)t->mask_tested / (double)t->rays_stored : 0.0,
               t->rays_stored ? (double)t->rasterized / (double)t->rays_stored : 0.0,
               t->splats + t->masked ? 100.0 * (double)t->masked / (double)(t->splats + t->masked) : 0.0);
    if (s->occl) {
        uint64_t all = t->splats + t->masked + t->occluded;
        cdl_stats_printf(out, "splat: occlusion test: clearances %.2f s; %.1f %% of the splats needed a "
                         "shadow ray, %.2f %% were occluded\n",
                         t->t_occl, all ? 100.0 * (double)t->occl_rays / (double)all : 0.0,
                         all ? 100.0 * (double)t->occluded / (double)all : 0.0);
        cdl_stats_add(out, "t_occlusion", t->t_occl);
        cdl_stats_add(out, "occlusion_rays", (double)t->occl_rays);
    }
    if (s->opt.splat.filter > 0.0f)
        cdl_stats_printf(out, "splat: filter (in T_brdf) %.2f s, %.0f segments per pass\n", t->t_filter,
               (double)t->segments / P);
}

static void splat_destroy(void *self)
{
    splat_state *s = self;
    cdl_pray_free(&s->rays);
    cdl_skd_free(&s->tree);
    free(s->sp);
    free(s->sn);
    free(s->sflags);
    free(s->svalid);
    free(s->slot);
    free(s->eye);
    free(s->sb);
    free(s->gb);
    free(s->base);
    free(s->dz);
    free(s->dn);
    free(s->pix);
    for (int c = 0; c < 3; c++)
        free(s->E[c]);
    free(s->izsum);
    free(s->gbits);
    free(s->nsum);
    free(s->gloss);
    free(s->gmap);
    free(s->bw);
    splat_cache_free(s);
    splat_mask_free(s);
    splat_occl_free(s);
    free(s->tables);
}

static const char *some_share(const double *v, int n)
{
    return n == 3 && !(v[0] + v[1] + v[2] > 0.0) ? "expected three shares d,i,c, none negative, not all zero" : NULL;
}

#define AT(f) CDL_PARAM_AT(cdl_options, splat.f)
static const double cap_kinds[] = {4.0, 0.0}, aov_bits[] = {CDL_AOV_BANDWIDTH, CDL_AOV_RECORDS};
static const cdl_param rows[] = {
    {"fractions", CDL_PARAM_FLOATS, "d,i,c", "0.3,0.6,0.1", "shares of direct, indirect and caustic rays", 0, 1e20,
     .check = some_share, .count = 3, AT(fractions)},
    {"C", CDL_PARAM_FLOAT, "c", "0.5", "bandwidth smoothness: mean kernel radius C * 0.2 * the mean photon ray length "
     "at 10^5 photons (the report: 1; half of it halves the kernels' bias in furnished interiors)", 1e-4, 1e3, AT(C)},
    {"S", CDL_PARAM_FLOAT, "s", "0.4", "bandwidth sensitivity to the path density, 0..1 (0: one bandwidth for all "
     "rays)", 0, 1, AT(S)},
    {"R", CDL_PARAM_FLOAT, "r", "0.2", "bandwidth clamping, 0..1: radii within [r, 1/r] times the mean", 1e-3, 1,
     AT(R)},
    {"mode", CDL_PARAM_CHOICE, "KIND", "direct", "radiance maps: direct (BSDF per splat), histogram (20 strata) or sh "
     "(16 coefficients)", .choices = "direct|histogram|sh", AT(mode)},
    {"direct", CDL_PARAM_CHOICE, "KIND", "photons", "photons (direct light splatted), sample (light sampling at the "
     "eye samples) or none (indirect light alone)", .choices = "photons|sample|none", AT(direct)},
    {"eye_samples", CDL_PARAM_INT, "N", "1", "eye samples per pixel and pass", 1, 1024, AT(eye_samples)},
    {"cull_nodes", CDL_PARAM_BOOL, "on|off", "on", "back-face-culling nodes in the eye-sample tree", AT(cull)},
    {"filter", CDL_PARAM_FLOAT, "N", "0", "image-space filtering of the radiance maps (§6.2): each pixel averaged over "
     "a box of its own surface segment, the smallest holding N photon splats (0: off)", 0, 1e12, AT(filter)},
    {"filter_normal", CDL_PARAM_FLOAT, "DEG", "20", "segments: neighbours' normals within DEG", 0, 180, .unit = "deg",
     AT(filter_normal)},
    {"filter_depth", CDL_PARAM_FLOAT, "T", "0.05", "segments: second difference of 1/depth within T of it", 0, 1e3,
     AT(filter_depth)},
    {"filter_max", CDL_PARAM_INT, "R", "25", "largest box: (2R+1)^2 pixels", 0, 255, AT(filter_max)},
    {"cache", CDL_PARAM_FLOAT, "EPS", "0", "radiance caching (§6.3) with cache error EPS (0: off): the maps computed at "
     "records only, by splatting, and interpolated within radius EPS R (R: the harmonic mean distance of the rays, 2 "
     "to 50 pixels)", 0, 100, AT(cache)},
    {"cache_min", CDL_PARAM_INT, "N", "5", "records each pixel gathers from, N_c", 1, 1000, AT(cache_min)},
    {"cache_weight", CDL_PARAM_CHOICE, "KIND", "report", "report (eq. 6.7) or ward (Ward 1988)",
     .choices = "report|ward", AT(cache_ward)},
    {"cache_spacing", CDL_PARAM_CHOICE, "KIND", "gradient", "gradient (R shrunk where the splats' irradiance gradient "
     "is steep, eq. 6.12) or geometric", .choices = "gradient|geometric", AT(cache_geometric)},
    {"gather", CDL_PARAM_INT, "N", "0", "final gathering (§6.4): N rays per camera sample by BSDF sampling; photon "
     "rays splat to where they land (rows in bands of at most 2^20 eye samples), light sampled at the camera's point "
     "(0: off)", 0, 65536, AT(gather)},
    {"visibility_mask", CDL_PARAM_BOOL, "on|off", "off", "eye samples hidden from a photon ray by other eye samples "
     "in its frustum get none of its light (§8.1; not with cache)", AT(visibility_mask)},
    {"occlusion", CDL_PARAM_BOOL, "on|off", "on", "a photon ray feeds an eye sample only if nothing lies between them "
     "(a shadow ray where the sample's clearance does not settle it): no light through thin walls and door gaps; "
     "off: Algorithm 2's kernel alone", AT(occlusion)},
    {"traversal", CDL_PARAM_CHOICE, "KIND", "sphere", "how a photon ray finds its eye samples: sphere (each node's "
     "bounding sphere against the frustum) or slabs (the report's Algorithm 1: the same samples, about twice as many "
     "tested)", .choices = "sphere|slabs", AT(slabs)},
    {"cap", CDL_PARAM_CHOICE, "KIND", "plane", "eye samples beyond a photon ray's hit: plane (fed if the ray reached "
     "their tangent plane, out to 4 h: consistent) or hemisphere (the report's Algorithm 2: biased low at oblique "
     "incidence, whatever h)", .choices = "plane|hemisphere", .values = cap_kinds, AT(cap)},
    {"aov", CDL_PARAM_CHOICE, "NAME", "", "extra EXR layers, repeatable: bandwidth (the kernel-weighted mean bandwidth "
     "of the photon rays of depth 2, 3 and any, as R, G, B) or, with cache, records (R: 1 at the records, G: "
     "records a pixel gathered from, B: the irradiance gradient's magnitude)", .choices = "bandwidth|records",
     .values = aov_bits, .flags = CDL_PARAM_BITS, CDL_PARAM_AT(cdl_options, aov)},
};
#undef AT
static const cdl_param_table table = CDL_PARAM_TABLE("Photon ray splatting (splat; Herzog et al. 2007)", rows);
static const cdl_param_table *const tables[] = {&cdl_density_table, &cdl_photon_table, &table, NULL};

const cdl_integrator_vtbl cdl_splat_integrator = {
    .params = tables,
    .name = "splat",
    .summary = "photon ray splatting (Herzog et al. 2007): photon rays with path-density bandwidths splatted to "
               "eye samples through a kd-tree, radiance maps direct | histogram | SH",
    .prepare = splat_prepare,
    .render_pass = splat_render_pass,
    .destroy = splat_destroy,
    .report = splat_report,
    .self_size = sizeof(splat_state),
};
