/* The parameter tables: every default parses and is what the options hold
 * by default, ranges and choices are enforced at their ends, no method
 * reads two rows of one name, rows sharing a field share a default, and a
 * parameter the method does not read is refused. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "api/settings.h"
#include "core/common_params.h"

static int failures;

#define CHECK(c, ...)                                                                                             \
    do {                                                                                                          \
        if (!(c)) {                                                                                               \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                                           \
            printf(__VA_ARGS__);                                                                                  \
            printf("\n");                                                                                         \
            failures++;                                                                                           \
        }                                                                                                         \
    } while (0)

/* A number just outside [min, max] (or min/max itself when open). */
static void range_ends(const cdl_param *p, void *base)
{
    char lo[64], hi[64], below[64], above[64];
    double step = p->type == CDL_PARAM_INT ? 1.0 : fmax(fabs(p->min), 1.0) * 1e-3;
    snprintf(lo, sizeof lo, "%.17g", p->min);
    snprintf(hi, sizeof hi, "%.17g", p->max);
    double up = p->type == CDL_PARAM_INT ? 1.0 : fmax(fabs(p->max), 1.0) * 1e-3;
    snprintf(below, sizeof below, "%.17g", p->min - step);
    snprintf(above, sizeof above, "%.17g", p->max + up);
    cdl_error err;
    int open_lo = p->flags & CDL_PARAM_OPEN_MIN, open_hi = p->flags & CDL_PARAM_OPEN_MAX;
    CHECK((cdl_param_set(p, lo, base, &err) == 0) == !open_lo, "%s: min %s %s", p->name, lo,
          open_lo ? "accepted (open)" : "refused");
    CHECK((cdl_param_set(p, hi, base, &err) == 0) == !open_hi, "%s: max %s %s", p->name, hi,
          open_hi ? "accepted (open)" : "refused");
    CHECK(cdl_param_set(p, below, base, &err) == CDL_ERR_USAGE && !strcmp(err.file, p->name), "%s: %s accepted",
          p->name, below);
    CHECK(cdl_param_set(p, above, base, &err) == CDL_ERR_USAGE, "%s: %s accepted", p->name, above);
    CHECK(cdl_param_set(p, "x", base, &err) == CDL_ERR_USAGE, "%s: 'x' accepted", p->name);
}

/* Every row of t: its default parses and equals what base holds after the
 * defaults; its range or choices hold at their ends. */
static void check_table(const cdl_param_table *t, const void *defaults, void *scratch, size_t size)
{
    cdl_error err;
    for (int i = 0; i < t->count; i++) {
        const cdl_param *p = &t->rows[i];
        CHECK(p->name[0] && p->help && p->help[0] && p->meta, "%s: incomplete row", p->name);
        CHECK(!strchr(p->name, '-'), "%s: library names use '_'", p->name);
        for (int j = 0; j < i; j++)
            CHECK(strcmp(t->rows[j].name, p->name), "%s twice in %s", p->name, t->title);
        if (p->def[0] && !(p->flags & CDL_PARAM_REPEAT)) {
            memcpy(scratch, defaults, size);
            CHECK(!cdl_param_set(p, p->def, scratch, &err), "%s: default '%s': %s", p->name, p->def, err.msg);
            CHECK(!memcmp(scratch, defaults, size), "%s: the default '%s' is not what the options hold", p->name,
                  p->def);
        }
        memcpy(scratch, defaults, size);
        if (p->type == CDL_PARAM_INT || p->type == CDL_PARAM_FLOAT)
            range_ends(p, scratch);
        if (p->type == CDL_PARAM_CHOICE) {
            const char *c;
            int n, k = 0;
            char buf[64];
            for (; (n = cdl_param_choice(p, k, &c)) > 0; k++) {
                snprintf(buf, sizeof buf, "%.*s", n, c);
                CHECK(!cdl_param_set(p, buf, scratch, &err), "%s: choice %s refused", p->name, buf);
            }
            CHECK(k >= 2, "%s: %d choices", p->name, k);
            CHECK(cdl_param_set(p, "bogus", scratch, &err) == CDL_ERR_USAGE && strstr(err.msg, "bogus"),
                  "%s: bogus choice", p->name);
        }
        if (p->type == CDL_PARAM_BOOL)
            CHECK(!cdl_param_set(p, "on", scratch, &err) && !cdl_param_set(p, "off", scratch, &err) &&
                      cdl_param_set(p, "maybe", scratch, &err) == CDL_ERR_USAGE,
                  "%s: on/off", p->name);
    }
}

int main(void)
{
    cdl_options o, scratch;
    cdl_options_default(&o);
    cdl_common_params c, cs;
    cdl_common_default(&c);
    check_table(&cdl_common_table, &c, &cs, sizeof c);

    const cdl_integrator_vtbl *const *all = cdl_integrator_list();
    for (int m = 0; all[m]; m++) {
        for (const cdl_param_table *const *t = all[m]->params; t && *t; t++) {
            check_table(*t, &o, &scratch, sizeof o);
            for (int i = 0; i < (*t)->count; i++) {
                const cdl_param *p = &(*t)->rows[i];
                CHECK(!cdl_param_find(&cdl_common_table, p->name), "%s: a common name in %s", p->name, all[m]->name);
                /* one row per name and method */
                for (const cdl_param_table *const *u = all[m]->params; u < t; u++)
                    CHECK(!cdl_param_find(*u, p->name), "%s: read twice by %s", p->name, all[m]->name);
                /* rows of other methods that land on the same field agree on its default */
                for (int e = 0; all[e]; e++)
                    for (const cdl_param_table *const *u = all[e]->params; u && *u; u++)
                        for (int j = 0; j < (*u)->count; j++) {
                            const cdl_param *q = &(*u)->rows[j];
                            if (q != p && q->at == p->at)
                                CHECK(!strcmp(q->def, p->def), "%s (%s) and %s (%s) share a field, not a default",
                                      p->name, p->def, q->name, q->def);
                        }
            }
        }
    }

    /* named values: "sample" light paths, "2/3", a cap's stored value */
    cdl_error err;
    const cdl_param *lp = cdl_method_param(cdl_integrator_find("bdpt"), "light_paths");
    scratch = o;
    CHECK(lp && !cdl_param_set(lp, "sample", &scratch, &err) && scratch.light_paths == CDL_LIGHT_PATHS_PER_SAMPLE,
          "light_paths sample");
    CHECK(fabsf(o.alpha - 2.0f / 3.0f) == 0.0f, "alpha default %.9g", o.alpha);
    const cdl_param *cap = cdl_method_param(cdl_integrator_find("splat"), "cap");
    CHECK(cap && !cdl_param_set(cap, "hemisphere", &scratch, &err) && scratch.splat.cap == 0.0f &&
              !cdl_param_set(cap, "plane", &scratch, &err) && scratch.splat.cap == 4.0f,
          "cap values");
    const cdl_param *aov = cdl_method_param(cdl_integrator_find("rigi"), "aov");
    scratch.aov = 0;
    CHECK(aov && !cdl_param_set(aov, "strata", &scratch, &err) && !cdl_param_set(aov, "pathlength", &scratch, &err) &&
              scratch.aov == (CDL_AOV_STRATA | CDL_AOV_PATHLENGTH),
          "aov bits OR: %u", scratch.aov);

    /* settings: the method's parameters read through its tables only */
    cdl_settings *s = cdl_settings_create();
    CHECK(!cdl_settings_set(s, "--max-radius", "0.25", &err) && !cdl_settings_set(s, "gather", "3", &err) &&
              !cdl_settings_set(s, "photons", "1234", &err),
          "pm's settings: %s", err.msg);
    scratch = o;
    CHECK(!cdl_settings_apply(s, cdl_integrator_find("pm"), &scratch, &err) && scratch.pm.max_radius == 0.25f &&
              scratch.pm.gather == 3 && scratch.photons == 1234 && scratch.splat.gather == o.splat.gather,
          "pm applied: %s", err.msg);
    scratch = o;
    CHECK(cdl_settings_apply(s, cdl_integrator_find("splat"), &scratch, &err) == CDL_ERR_USAGE &&
              !strcmp(err.file, "max_radius") && strstr(err.msg, "splat"),
          "splat read max_radius: %s", err.msg);
    CHECK(cdl_settings_set(s, "gather", "-1", &err) == CDL_ERR_USAGE, "gather -1 accepted before the method");
    cdl_settings_release(s);

    if (failures)
        printf("%d failures\n", failures);
    else
        printf("parameter tables: all checks passed\n");
    return failures != 0;
}
