#include "scene/light.h"

#include "core/sampling.h"

int cdl_light_sample_li(const cdl_light *l, cdl_vec3 ref, float u1, float u2,
                        cdl_light_sample *s)
{
    if (l->type == CDL_LIGHT_POINT) {
        cdl_vec3 d = cdl_sub(l->p, ref);
        float d2 = cdl_dot(d, d);
        if (!(d2 > 0.0f))
            return 0;
        s->dist = sqrtf(d2);
        s->wi = cdl_scale(d, 1.0f / s->dist);
        s->p = l->p;
        s->Li = cdl_scale(l->L, 1.0f / d2);
        s->pdf = 1.0f;
        s->delta = 1;
        return 1;
    }
    float b1, b2;
    cdl_sample_triangle(u1, u2, &b1, &b2);
    s->p = cdl_add(l->p, cdl_add(cdl_scale(l->e1, b1), cdl_scale(l->e2, b2)));
    cdl_vec3 d = cdl_sub(s->p, ref);
    float d2 = cdl_dot(d, d);
    if (!(d2 > 0.0f))
        return 0;
    s->dist = sqrtf(d2);
    s->wi = cdl_scale(d, 1.0f / s->dist);
    float cos_l = -cdl_dot(s->wi, l->n);
    if (cos_l <= 0.0f)
        return 0; /* receiver behind the emitting face */
    s->Li = l->L;
    s->pdf = d2 / (cos_l * l->area);
    s->delta = 0;
    return 1;
}

float cdl_light_pdf_li(const cdl_light *l, cdl_vec3 ref, cdl_vec3 p)
{
    if (l->type == CDL_LIGHT_POINT)
        return 0.0f;
    cdl_vec3 d = cdl_sub(p, ref);
    float d2 = cdl_dot(d, d);
    float cos_l = -cdl_dot(d, l->n) / sqrtf(d2);
    return cos_l > 0.0f ? d2 / (cos_l * l->area) : 0.0f;
}

int cdl_light_sample_le(const cdl_light *l, float u1, float u2, float u3, float u4,
                        cdl_light_emit *e)
{
    if (l->type == CDL_LIGHT_POINT) {
        e->p = l->p;
        e->n = cdl_v3(0.0f, 0.0f, 0.0f);
        e->d = cdl_sample_uniform_sphere(u3, u4);
        e->Le = l->L;
        e->pdf_pos = 1.0f;
        e->pdf_dir = 0.25f * CDL_INV_PI;
        return 1;
    }
    float b1, b2;
    cdl_sample_triangle(u1, u2, &b1, &b2);
    e->p = cdl_add(l->p, cdl_add(cdl_scale(l->e1, b1), cdl_scale(l->e2, b2)));
    e->n = l->n;
    cdl_frame f = cdl_frame_from(l->n);
    cdl_vec3 local = cdl_sample_cosine_hemisphere(u3, u4);
    if (local.z <= 0.0f)
        return 0;
    e->d = cdl_to_world(&f, local);
    e->Le = l->L;
    e->pdf_pos = 1.0f / l->area;
    e->pdf_dir = local.z * CDL_INV_PI;
    return 1;
}

cdl_vec3 cdl_light_power(const cdl_light *l)
{
    if (l->type == CDL_LIGHT_POINT)
        return cdl_scale(l->L, 4.0f * CDL_PI);
    return cdl_scale(l->L, CDL_PI * l->area);
}
