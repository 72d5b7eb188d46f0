/* The options a user can set, with their defaults and one-line help (the
 * command's --help and the Python package's discovery read this table),
 * the integrators and the version. Each entry is parsed in settings.c. */
#include <stddef.h>
#include <string.h>

#include "api/settings.h"

#define STR2(x) #x
#define STR(x) STR2(x)

const char *cdl_version(void)
{
    return STR(CDL_VERSION_MAJOR) "." STR(CDL_VERSION_MINOR) "." STR(CDL_VERSION_PATCH);
}

static const cdl_option_info options[] = {
    {"integrator", "NAME", "", "path", "light transport method (path, bdpt, ir, rigi, pm, gkde, splat)", "General"},
    {"spp", "N", "", "64", "samples per pixel, one per pass (a pbrt scene's sampler may set it)", "General"},
    {"time", "SEC", "", "", "render whole passes until SEC seconds are spent (instead of --spp)", "General"},
    {"res", "WxH", "", "512x512", "image size (a pbrt scene's film may set it)", "General"},
    {"lookat", "ex,ey,ez,tx,ty,tz,ux,uy,uz", "", "", "camera position, target and up vector (default: the scene file's camera, else one that frames the scene's bounds)", "General"},
    {"fov", "DEG", "", "40", "vertical field of view; without --lookat the camera frames the scene's bounds", "General"},
    {"maxdepth", "N", "", "64", "maximum bounces (1 = direct light only)", "General"},
    {"seed", "N", "", "1", "random seed; same seed, same image", "General"},
    {"sampler", "NAME", "", "sobol", "sobol (Owen-scrambled) or independent", "General"},
    {"threads", "N", "", "", "worker threads (default: all cores)", "General"},
    {"point-light", "x,y,z,r,g,b", "", "", "add a point light of intensity (r,g,b) W/sr; repeatable", "General"},
    {"exposure", "EV", "", "0", "PNG exposure in stops", "General"},
    {"quiet", "", "", "off", "no warnings (and, in the command, no progress bar)", "General"},
    {"mis", "KIND", "bdpt", "power", "bdpt weights: balance, power, stratified, or light (light tracing alone: every path through t = 1)", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"threshold", "t", "rigi", "", "stratification threshold on G (default: the scene's diagonal d gives t = 1 / (0.15 d)^2); printed when used", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"light-paths", "K", "bdpt,ir,rigi", "", "K light paths per pass shared by all pixels, or 'sample': an independent one per pixel sample (bdpt default: sample; ir/rigi default 256 paths in 4 x 4 interleaved sets)", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"interleave", "N", "bdpt,ir,rigi", "1", "N x N interleaved sets of the K paths", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"clamp", "c", "ir", "", "ir: clamp G at c (default: 1 / (0.05 d)^2)", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"strata", "KIND", "rigi", "geometry", "rigi: geometry (threshold G) or distance", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"aov", "NAME", "rigi,splat", "", "extra EXR layers; rigi: pathlength (average eye path length, Fig. 4) or strata (the contribution of each eye path length as layers strata1..strata8, Fig. 5); splat: bandwidth (the kernel-weighted mean bandwidth of the photon rays of depth 2, 3 and any, as R, G, B) or, with --cache, records (R: 1 at the records, G: records a pixel gathered from, B: the irradiance gradient's magnitude)", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"shadow-rays", "KIND", "ir,rigi,gkde", "bundle", "bundle (one Embree ray stream per point light and tile, or per footprint) or single; pm: a number (below)", "Bidirectional and point-light methods (bdpt, ir, rigi)"},
    {"progressive", "on|off", "pm,gkde,splat", "on", "consistent: every bandwidth (pm's radii, gkde's h, splat's kernels) shrinks with the pass index i as r_i^2 = r_0^2 prod (j + alpha) / (j + 1) (Knaus & Zwicker 2011), so the bias falls with time; off: the fixed bandwidths of the reports", "Density estimation (pm, gkde, splat)"},
    {"alpha", "a", "pm,gkde,splat", "0.667", "radius reduction: r^2 falls about as i^(alpha - 1); in (0, 1), smaller shrinks faster with more noise", "Density estimation (pm, gkde, splat)"},
    {"photons", "N", "pm", "200000", "global photons stored per pass; paths are traced until the map holds N", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"knn", "K", "pm", "20", "photons per radiance estimate (their radius, scaled by the pass's factor with --progressive)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"max-radius", "R", "pm", "", "largest estimate radius (default 5 % of the diagonal)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"kernel", "KIND", "pm", "cone", "box, cone or epanechnikov", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"gather", "N", "pm", "8", "final gathering rays per pixel sample; 0 shows the global map directly", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"precompute", "M", "pm", "4", "gather rays landing on Lambertian surfaces read the irradiance precomputed at 1 in M photons from the others (Christensen 1999; 0 = a full estimate; M >= 2)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"visibility", "V", "pm", "all", "which estimates leave out photons no free path joins to the query point (a shadow ray each): all (no light in a room that no light path enters), gather (only those at final-gather hits, incl. the precomputed irradiance: --gather 0 and caustics at the camera's point may leak) or off (Jensen's: leaks through thin walls)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"caustic-ratio", "q", "pm", "1", "only a fraction q of the paths fills the global map, all fill the caustic map", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"caustic-select", "S", "pm", "prefix", "prefix (the first q N paths) or random (a test against q per photon)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"importance", "", "pm", "off", "store photons with probability p = min(1, f I(x)) from importons traced from the camera (power L / p)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"importons", "N", "pm", "131072", "importon paths", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"importance-eps", "e", "pm", "0.01", "lower bound of p, in (0, 1] (unbiased)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"importance-discard", "", "pm", "off", "drop photons with p < e instead (biased)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"direct", "KIND", "pm", "power", "power (lights in proportion to power), lcon (S rays to the lights of nearby primary photons, one to the rest), lcon-biased (none to the rest), photons (read from the photon map: its primary photons seen directly; needs --gather 0) or none (indirect light alone, for comparisons)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"shadow-rays", "S", "pm", "4", "direct-light shadow rays per shading point", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"lcon-radius", "R", "pm", "", "radius of the L_con query (default: --max-radius)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"photon-paths-max", "N", "pm", "", "give up when N paths per pass have not stored --photons photons (default 1000 per photon, at least 2^20)", "Photon mapping (pm; Jensen 1996 with Keller & Wald 2000)"},
    {"light-paths", "N", "gkde", "50000", "light paths per step", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"eye-paths", "N", "gkde", "1", "eye paths per pixel and step", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"links", "M", "gkde", "N/10000", "unoccluded links wanted per eye vertex (default: one per 10000 light paths, at least 1, so that the calibrated h does not grow as N shrinks)", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"bandwidth", "h", "gkde", "", "footprint bandwidth of eq. 7 (default: calibrated in the first step so that an eye vertex lies in about M first-bounce footprints)", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"overlaps", "K", "gkde", "2", "h_0 is calibrated so that an eye vertex in direct light lies in about K first-bounce footprints (>= 2; the report: K = M = 10)", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"footprint-cap", "F", "gkde", "2", "footprint radii at most F times the median first-bounce one (0: eq. 7 unbounded)", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"path-memory", "MiB", "gkde", "4096", "cap on the stored light and eye vertices", "Generalized kernel density estimation (gkde; Bekaert et al. 2003)"},
    {"photons", "M", "splat", "200000", "photon rays stored per pass, all budgets", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"fractions", "d,i,c", "splat", "0.3,0.6,0.1", "shares of direct, indirect and caustic rays", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"C", "c", "splat", "0.5", "bandwidth smoothness: mean kernel radius C * 0.2 * the mean photon ray length at 10^5 photons (the report: 1; half of it halves the kernels' bias in furnished interiors)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"S", "s", "splat", "0.4", "bandwidth sensitivity to the path density, 0..1 (0: one bandwidth for all rays)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"R", "r", "splat", "0.2", "bandwidth clamping, 0..1: radii within [r, 1/r] times the mean", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"mode", "KIND", "splat", "direct", "radiance maps: direct (BSDF per splat), histogram (20 strata) or sh (16 coefficients)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"direct", "KIND", "splat", "photons", "photons (direct light splatted), sample (light sampling at the eye samples) or none (indirect light alone)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"eye-samples", "N", "splat", "1", "eye samples per pixel and pass", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cull-nodes", "on|off", "splat", "on", "back-face-culling nodes in the eye-sample tree", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"filter", "N", "splat", "0", "image-space filtering of the radiance maps (§6.2): each pixel averaged over a box of its own surface segment, the smallest holding N photon splats (0: off)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"filter-normal", "DEG", "splat", "20", "segments: neighbours' normals within DEG", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"filter-depth", "T", "splat", "0.05", "segments: second difference of 1/depth within T of it", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"filter-max", "R", "splat", "25", "largest box: (2R+1)^2 pixels", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cache", "EPS", "splat", "0", "radiance caching (§6.3) with cache error EPS (0: off): the maps computed at records only, by splatting, and interpolated within radius EPS R (R: the harmonic mean distance of the rays, 2 to 50 pixels)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cache-min", "N", "splat", "5", "records each pixel gathers from, N_c", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cache-weight", "KIND", "splat", "report", "report (eq. 6.7) or ward (Ward 1988)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cache-spacing", "KIND", "splat", "gradient", "gradient (R shrunk where the splats' irradiance gradient is steep, eq. 6.12) or geometric", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"gather", "N", "splat", "0", "final gathering (§6.4): N rays per camera sample by BSDF sampling; photon rays splat to where they land (rows in bands of at most 2^20 eye samples), light sampled at the camera's point (0: off)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"visibility-mask", "on|off", "splat", "off", "eye samples hidden from a photon ray by other eye samples in its frustum get none of its light (§8.1; not with --cache)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"occlusion", "on|off", "splat", "on", "a photon ray feeds an eye sample only if nothing lies between them (a shadow ray where the sample's clearance does not settle it): no light through thin walls and door gaps; off: Algorithm 2's kernel alone", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"traversal", "KIND", "splat", "sphere", "how a photon ray finds its eye samples: sphere (each node's bounding sphere against the frustum) or slabs (the report's Algorithm 1: the same samples, about twice as many tested)", "Photon ray splatting (splat; Herzog et al. 2007)"},
    {"cap", "KIND", "splat", "plane", "eye samples beyond a photon ray's hit: plane (fed if the ray reached their tangent plane, out to 4 h: consistent) or hemisphere (the report's Algorithm 2: biased low at oblique incidence, whatever h)", "Photon ray splatting (splat; Herzog et al. 2007)"},
};

int cdl_option_count(void)
{
    return (int)(sizeof options / sizeof *options);
}

const cdl_option_info *cdl_option_get(int i)
{
    return i >= 0 && i < cdl_option_count() ? &options[i] : NULL;
}

const cdl_option_info *cdl_option_find(const char *name)
{
    for (int i = 0; i < cdl_option_count(); i++)
        if (!strcmp(options[i].name, name))
            return &options[i];
    return NULL;
}

int cdl_integrator_count(void)
{
    int n = 0;
    for (const cdl_integrator_vtbl *const *it = cdl_integrator_list(); *it; it++)
        n++;
    return n;
}

const char *cdl_integrator_name(int i)
{
    return i >= 0 && i < cdl_integrator_count() ? cdl_integrator_list()[i]->name : NULL;
}

const char *cdl_integrator_summary(int i)
{
    return i >= 0 && i < cdl_integrator_count() ? cdl_integrator_list()[i]->summary : NULL;
}
