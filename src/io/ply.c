#define _POSIX_C_SOURCE 200809L
#include "io/ply.h"

#include "core/file.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "scene/scene.h"

#include "io/ply_format.h"

void cdl_ply_free(cdl_ply_mesh *m)
{
    if (m)
        cdl_mesh_free(m);
}

/* ---- file ---------------------------------------------------------------------------------- */

/* ---- messages ------------------------------------------------------------------------------ */

/* "vertices", "faces", "'edge' elements" (singular for a count of 1). */
static const char *elem_noun(const ply_elem *e, char *buf, size_t n)
{
    int one = e->count == 1;
    if (!strcmp(e->name, "vertex"))
        return one ? "vertex" : "vertices";
    if (!strcmp(e->name, "face"))
        return one ? "face" : "faces";
    snprintf(buf, n, "'%.64s' element%s", e->name, one ? "" : "s");
    return buf;
}

static int truncated(ply_ctx *c)
{
    char buf[96];
    return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0,
                         "truncated: expected %" PRIu64 " %s, file ends after %" PRIu64,
                         c->cur->count, elem_noun(c->cur, buf, sizeof buf), c->cur_i);
}

/* "face 17: ..." at the current text line (ASCII) or line 0 (binary). */
__attribute__((format(printf, 2, 3))) static int elem_error(ply_ctx *c, const char *fmt, ...)
{
    char msg[384];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, c->fmt == FMT_ASCII ? c->line : 0,
                         "%.64s %" PRIu64 ": %s", c->cur->name, c->cur_i, msg);
}

/* Copies a token for a message, replacing bytes that could break the one-line error. */
static void printable(char *dst, size_t n, const unsigned char *s, size_t len)
{
    size_t k = 0;
    for (; k < len && k + 4 < n; k++)
        dst[k] = (s[k] < 0x20 || s[k] >= 0x7f) ? '?' : (char)s[k];
    if (k < len && n >= 4) {
        memcpy(dst + k, "...", 3);
        k += 3;
    }
    dst[k] = 0;
}

/* ---- body values --------------------------------------------------------------------------- */

static inline uint64_t load_bytes(const unsigned char *p, unsigned n, int big)
{
    uint64_t v = 0;
    if (big)
        for (unsigned i = 0; i < n; i++)
            v = v << 8 | p[i];
    else
        for (unsigned i = n; i-- > 0;)
            v = v << 8 | p[i];
    return v;
}

/* One binary value of type t as a double, and exactly as an integer for
 * integer types. */
static inline void decode(const unsigned char *p, int t, int big, double *d, int64_t *iv)
{
    uint64_t u;
    switch (t) {
    case T_INT8:
        *iv = p[0] < 0x80 ? p[0] : (int64_t)p[0] - 0x100;
        break;
    case T_UINT8:
        *iv = p[0];
        break;
    case T_INT16:
        u = load_bytes(p, 2, big);
        *iv = u < 0x8000 ? (int64_t)u : (int64_t)u - 0x10000;
        break;
    case T_UINT16:
        *iv = (int64_t)load_bytes(p, 2, big);
        break;
    case T_INT32:
        u = load_bytes(p, 4, big);
        *iv = u < 0x80000000u ? (int64_t)u : (int64_t)u - 0x100000000;
        break;
    case T_UINT32:
        *iv = (int64_t)load_bytes(p, 4, big);
        break;
    case T_FLOAT32: {
        uint32_t w = (uint32_t)load_bytes(p, 4, big);
        float f;
        memcpy(&f, &w, 4);
        *d = f;
        *iv = 0;
        return;
    }
    default: {
        u = load_bytes(p, 8, big);
        double x;
        memcpy(&x, &u, 8);
        *d = x;
        *iv = 0;
        return;
    }
    }
    *d = (double)*iv;
}

static inline int is_space(unsigned char ch)
{
    return ch == ' ' || ch == '\t' || ch == '\r' || ch == '\v' || ch == '\f';
}

/* ASCII: moves to the next non-blank line; 0 at the end of the file. */
static int ascii_next_line(ply_ctx *c)
{
    for (;;) {
        while (c->p < c->end && is_space(*c->p))
            c->p++;
        if (c->p >= c->end)
            return 0;
        if (*c->p != '\n')
            return 1;
        c->p++;
        c->line++;
    }
}

/* ASCII: the next word on the current line, or NULL when the line is done. */
static const unsigned char *ascii_word(ply_ctx *c, size_t *len)
{
    while (c->p < c->end && is_space(*c->p))
        c->p++;
    if (c->p >= c->end || *c->p == '\n')
        return NULL;
    const unsigned char *w = c->p;
    while (c->p < c->end && !is_space(*c->p) && *c->p != '\n')
        c->p++;
    *len = (size_t)(c->p - w);
    return w;
}

static int ascii_value(ply_ctx *c, int t, double *d, int64_t *iv)
{
    size_t n;
    const unsigned char *w = ascii_word(c, &n);
    if (!w)
        return elem_error(c, "too few values on the line");
    char buf[64], show[40];
    if (n >= sizeof buf) {
        printable(show, sizeof show, w, n);
        return elem_error(c, "'%s' is not a number", show);
    }
    memcpy(buf, w, n);
    buf[n] = 0;
    if (IS_INT_TYPE(t)) {
        int rc = parse_int(buf, iv);
        if (rc) {
            printable(show, sizeof show, w, n);
            if (rc == -2)
                return elem_error(c, "integer '%s' is too large", show);
            return elem_error(c, "'%s' is not an integer (the property is %s)", show,
                              cdl_ply_types[t].name);
        }
        *d = (double)*iv;
    } else {
        char *e;
        *d = strtod(buf, &e);
        if (e != buf + n) {
            printable(show, sizeof show, w, n);
            return elem_error(c, "'%s' is not a number", show);
        }
        *iv = 0;
    }
    return 0;
}

static inline int read_value(ply_ctx *c, int t, double *d, int64_t *iv)
{
    if (c->fmt == FMT_ASCII)
        return ascii_value(c, t, d, iv);
    unsigned sz = cdl_ply_types[t].size;
    if ((size_t)(c->end - c->p) < sz)
        return truncated(c);
    decode(c->p, t, c->fmt == FMT_BE, d, iv);
    c->p += sz;
    return 0;
}

/* Reads a list count: a non-negative integer. */
static int read_count(ply_ctx *c, const ply_prop *pr, int64_t *n)
{
    double d;
    int rc = read_value(c, pr->count_type, &d, n);
    if (rc)
        return rc;
    if (*n < 0)
        return elem_error(c, "list '%.64s' has negative length %" PRId64, pr->name, *n);
    return 0;
}

/* Reads and drops one property (scalar or list). */
static int skip_prop(ply_ctx *c, const ply_prop *pr)
{
    double d;
    int64_t iv, n;
    if (!pr->list)
        return read_value(c, pr->type, &d, &iv);
    int rc = read_count(c, pr, &n);
    if (rc)
        return rc;
    if (c->fmt != FMT_ASCII) {
        /* The length is checked against the bytes left before it is used. */
        uint64_t bytes = (uint64_t)n * cdl_ply_types[pr->type].size;
        if (bytes > (uint64_t)(c->end - c->p))
            return truncated(c);
        c->p += bytes;
        return 0;
    }
    for (int64_t k = 0; k < n; k++)
        if ((rc = read_value(c, pr->type, &d, &iv)))
            return rc;
    return 0;
}

static int begin_instance(ply_ctx *c)
{
    if (c->fmt == FMT_ASCII && !ascii_next_line(c))
        return truncated(c);
    return 0;
}

static int end_instance(ply_ctx *c)
{
    size_t n;
    if (c->fmt == FMT_ASCII && ascii_word(c, &n))
        return elem_error(c, "too many values on the line");
    return 0;
}

/* Fewest bytes one instance of e can take, so that counts can be checked
 * against the bytes left before anything is allocated. ASCII: a character
 * and a separator per value. */
static uint64_t min_instance_bytes(const ply_ctx *c, const ply_elem *e, int *fixed)
{
    uint64_t b = 0;
    *fixed = 1;
    for (int i = 0; i < e->nprops; i++) {
        const ply_prop *p = &e->props[i];
        uint64_t items = p->role == R_INDICES ? 3 : 0;
        if (c->fmt == FMT_ASCII)
            b += 2 * (1 + (p->list ? items : 0));
        else if (p->list)
            b += cdl_ply_types[p->count_type].size + items * cdl_ply_types[p->type].size;
        else
            b += cdl_ply_types[p->type].size;
        if (p->list)
            *fixed = 0;
    }
    if (c->fmt == FMT_ASCII)
        *fixed = 0;
    return b ? b : 1;
}

/* How many instances the rest of the file can hold at most. */
static uint64_t max_instances(const ply_ctx *c, uint64_t minb)
{
    uint64_t left = (uint64_t)(c->end - c->p) + (c->fmt == FMT_ASCII); /* last value needs no separator */
    return left / minb;
}

/* ---- elements ------------------------------------------------------------------------------ */

static int skip_element(ply_ctx *c, const ply_elem *e)
{
    if (e->nprops == 0 || e->count == 0)
        return 0;
    int fixed;
    uint64_t minb = min_instance_bytes(c, e, &fixed);
    if (fixed) { /* binary without lists: one jump */
        uint64_t left = (uint64_t)(c->end - c->p);
        if (e->count > left / minb) {
            c->cur_i = left / minb;
            return truncated(c);
        }
        c->p += e->count * minb;
        return 0;
    }
    for (uint64_t i = 0; i < e->count; i++) {
        c->cur_i = i;
        int rc = begin_instance(c);
        for (int k = 0; !rc && k < e->nprops; k++)
            rc = skip_prop(c, &e->props[k]);
        if (rc || (rc = end_instance(c)))
            return rc;
    }
    return 0;
}

static int oom(ply_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, 0, "out of memory");
}

/* Grows element e's attribute arrays to cap values each. */
static int grow_attrs(ply_ctx *c, ply_elem *e, uint64_t cap)
{
    for (int k = 0; k < e->nattrs; k++) {
        float *p = realloc(e->attrs[k].data, (size_t)cap * (size_t)e->attrs[k].dim * sizeof(float));
        if (!p)
            return oom(c);
        e->attrs[k].data = p;
    }
    return 0;
}

/* An attribute value: integers are normalized to [0, 1] (or [-1, 1]) and
 * decoded from sRGB, as Mitsuba's struct conversion does. */
static float attr_value(int type, double d)
{
    static const double range[] = {127.0, 255.0, 32767.0, 65535.0, 2147483647.0, 4294967295.0};
    if (!IS_INT_TYPE(type))
        return (float)d;
    double x = d / range[type];
    double m = fabs(x), lin = m <= 0.04045 ? m / 12.92 : pow((m + 0.055) / 1.055, 2.4);
    return (float)(x < 0.0 ? -lin : lin);
}

static int grow_verts(ply_ctx *c, uint64_t cap, int has_n, int has_uv)
{
    if (grow_attrs(c, &c->elems[c->vert], cap))
        return CDL_ERR_SYSTEM;
    float *p = realloc(c->out.pos, (size_t)cap * 3 * sizeof(float));
    if (!p)
        return oom(c);
    c->out.pos = p;
    if (has_n) {
        if (!(p = realloc(c->out.nrm, (size_t)cap * 3 * sizeof(float))))
            return oom(c);
        c->out.nrm = p;
    }
    if (has_uv) {
        if (!(p = realloc(c->out.uv, (size_t)cap * 2 * sizeof(float))))
            return oom(c);
        c->out.uv = p;
    }
    c->vcap = cap;
    return 0;
}

static int read_vertices(ply_ctx *c, const ply_elem *e)
{
    static const char *role_name[] = {"", "x", "y", "z", "nx", "ny", "nz", "u", "v"};
    int has_n = 0, has_uv = 0;
    for (int k = 0; k < e->nprops; k++) {
        has_n |= e->props[k].role == R_NX;
        has_uv |= e->props[k].role == R_U;
    }
    int fixed;
    uint64_t minb = min_instance_bytes(c, e, &fixed), most = max_instances(c, minb);
    if (fixed && e->count > most) { /* certainly short: say so before allocating */
        c->cur_i = most;
        return truncated(c);
    }
    /* Never reserve more than the bytes left can describe. */
    uint64_t cap = e->count < most ? e->count : most;
    if (cap && grow_verts(c, cap, has_n, has_uv))
        return CDL_ERR_SYSTEM;
    for (uint64_t i = 0; i < e->count; i++) {
        c->cur_i = i;
        int rc = begin_instance(c);
        if (rc)
            return rc;
        /* cap is an upper bound for any file that parses, so this only runs
         * on the way to an error; it keeps that error the first in the file. */
        if (i == c->vcap) {
            uint64_t nc = c->vcap * 2 > 64 ? c->vcap * 2 : 64;
            if (grow_verts(c, nc < e->count ? nc : e->count, has_n, has_uv))
                return CDL_ERR_SYSTEM;
        }
        for (int k = 0; k < e->nprops; k++) {
            const ply_prop *pr = &e->props[k];
            if (pr->role == R_SKIP) {
                if ((rc = skip_prop(c, pr)))
                    return rc;
                continue;
            }
            double d;
            int64_t iv;
            if ((rc = read_value(c, pr->type, &d, &iv)))
                return rc;
            if (pr->role == R_ATTR) {
                const ply_attr *a = &e->attrs[pr->attr];
                if (!isfinite(d))
                    return elem_error(c, "%s is not finite (%g)", pr->name, d);
                if (pr->chan >= 0)
                    a->data[(size_t)a->dim * i + (unsigned)pr->chan] = attr_value(pr->type, d);
                continue;
            }
            if (!isfinite(d))
                return elem_error(c, "%s is not finite (%g)", role_name[pr->role], d);
            if (fabs(d) > CDL_MAX_COORD)
                return elem_error(c, "%s = %g is out of range (|x| > 1e20)", role_name[pr->role], d);
            float f = (float)d;
            if (pr->role <= R_Z)
                c->out.pos[3 * i + (unsigned)(pr->role - R_X)] = f;
            else if (pr->role <= R_NZ)
                c->out.nrm[3 * i + (unsigned)(pr->role - R_NX)] = f;
            else
                c->out.uv[2 * i + (unsigned)(pr->role - R_U)] = f;
        }
        if ((rc = end_instance(c)))
            return rc;
    }
    return 0;
}

static int grow_tris(ply_ctx *c)
{
    if (c->out.ntris >= PLY_MAX_TRIS)
        return elem_error(c, "too many triangles (max %u)", PLY_MAX_TRIS);
    uint64_t nc = c->tcap * 2 > 256 ? c->tcap * 2 : 256;
    if (nc > PLY_MAX_TRIS)
        nc = PLY_MAX_TRIS;
    uint32_t *p = realloc(c->out.idx, (size_t)nc * 3 * sizeof(uint32_t));
    if (!p)
        return oom(c);
    c->out.idx = p;
    c->tcap = nc;
    return grow_attrs(c, &c->elems[c->face], nc);
}

/* The index list of one face, fan-triangulated around its first vertex. */
static int read_face_indices(ply_ctx *c, const ply_prop *pr)
{
    int64_t n;
    int rc = read_count(c, pr, &n);
    if (rc)
        return rc;
    if (n < 3)
        return elem_error(c, "%" PRId64 " vertices (a face needs at least 3)", n);
    if (c->fmt != FMT_ASCII &&
        (uint64_t)n * cdl_ply_types[pr->type].size > (uint64_t)(c->end - c->p))
        return truncated(c);
    uint32_t first = 0, prev = 0;
    for (int64_t k = 0; k < n; k++) {
        double d;
        int64_t v;
        if ((rc = read_value(c, pr->type, &d, &v)))
            return rc;
        if (v < 0 || v >= (int64_t)c->nverts)
            return elem_error(c, "vertex index %" PRId64 " out of range (%" PRIu32 " vertices)", v,
                              c->nverts);
        if (k >= 2) {
            if (c->out.ntris == c->tcap && (rc = grow_tris(c)))
                return rc;
            uint32_t *t = c->out.idx + 3 * (size_t)c->out.ntris++;
            t[0] = first;
            t[1] = prev;
            t[2] = (uint32_t)v;
        } else if (k == 0) {
            first = (uint32_t)v;
        }
        prev = (uint32_t)v;
    }
    return 0;
}

static int read_faces(ply_ctx *c, const ply_elem *e)
{
    int fixed;
    uint64_t minb = min_instance_bytes(c, e, &fixed), most = max_instances(c, minb);
    /* One triangle per face as a start, bounded by what the file can hold. */
    uint64_t cap = e->count < most ? e->count : most;
    if (cap > PLY_MAX_TRIS)
        cap = PLY_MAX_TRIS;
    if (cap) {
        if (!(c->out.idx = malloc((size_t)cap * 3 * sizeof(uint32_t))))
            return oom(c);
        c->tcap = cap;
        if (grow_attrs(c, &c->elems[c->face], cap))
            return CDL_ERR_SYSTEM;
    }
    for (uint64_t i = 0; i < e->count; i++) {
        c->cur_i = i;
        uint32_t t0 = c->out.ntris;
        float val[PLY_MAX_ATTRS][3] = {{0}};
        int rc = begin_instance(c);
        for (int k = 0; !rc && k < e->nprops; k++) {
            const ply_prop *pr = &e->props[k];
            if (pr->role == R_ATTR) {
                double d;
                int64_t iv;
                if (!(rc = read_value(c, pr->type, &d, &iv)) && !isfinite(d))
                    rc = elem_error(c, "%s is not finite (%g)", pr->name, d);
                if (!rc && pr->chan >= 0)
                    val[pr->attr][pr->chan] = attr_value(pr->type, d);
                continue;
            }
            rc = pr->role == R_INDICES ? read_face_indices(c, pr) : skip_prop(c, pr);
        }
        if (rc || (rc = end_instance(c)))
            return rc;
        /* every triangle of the face's fan gets the face's values */
        for (int k = 0; k < e->nattrs; k++)
            for (uint32_t t = t0; t < c->out.ntris; t++)
                memcpy(e->attrs[k].data + (size_t)e->attrs[k].dim * t, val[k],
                       (size_t)e->attrs[k].dim * sizeof(float));
    }
    return 0;
}

/* Hands the attributes over to the mesh (which owns them from then on). */
static int take_attrs(ply_ctx *c)
{
    for (int w = 0; w < 2; w++) {
        ply_elem *e = &c->elems[w ? c->face : c->vert];
        for (int k = 0; k < e->nattrs; k++) {
            cdl_mesh_attr *a = realloc(c->out.attrs, sizeof *a * (size_t)(c->out.nattrs + 1));
            if (!a)
                return oom(c);
            c->out.attrs = a;
            a += c->out.nattrs++;
            memset(a, 0, sizeof *a);
            snprintf(a->name, sizeof a->name, "%s", e->attrs[k].name);
            a->per_face = w;
            a->dim = e->attrs[k].dim;
            a->data = e->attrs[k].data;
            e->attrs[k].data = NULL;
            if (!a->data) /* an empty element */
                c->out.nattrs--;
        }
    }
    return 0;
}

/* ---- entry --------------------------------------------------------------------------------- */

int cdl_ply_read(const char *path, cdl_ply_mesh *m, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    unsigned char *data = NULL;
    size_t size = 0;
    int rc = cdl_read_file(path, PLY_MAX_BYTES, (char **)&data, &size, err);
    if (rc)
        return rc;
    /* The element table is large; keep it off the stack. */
    ply_ctx *c = calloc(1, sizeof *c);
    if (!c) {
        free(data);
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    }
    c->path = path;
    c->err = err;
    c->vert = c->face = -1;
    size_t body = 0;
    rc = cdl_ply_parse_header(c, data, size, &body, &c->line);
    if (!rc) {
        c->p = data + body;
        c->end = data + size;
        for (int i = 0; !rc && i < c->nelems; i++) {
            const ply_elem *e = &c->elems[i];
            c->cur = e;
            c->cur_i = 0;
            if (i == c->vert)
                rc = read_vertices(c, e);
            else if (i == c->face)
                rc = read_faces(c, e);
            else
                rc = skip_element(c, e);
        }
        /* Anything after the last element (padding, stray text) is ignored. */
    }
    if (!rc && c->out.ntris == 0)
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0, "no faces");
    if (!rc)
        rc = take_attrs(c);
    if (!rc) {
        c->out.nverts = c->nverts;
        if (c->tcap > c->out.ntris) { /* give back the reserve; keep it if realloc fails */
            uint32_t *p = realloc(c->out.idx, (size_t)c->out.ntris * 3 * sizeof(uint32_t));
            if (p)
                c->out.idx = p;
        }
        *m = c->out;
    } else {
        cdl_ply_free(&c->out);
    }
    for (int i = 0; i < c->nelems; i++)
        for (int k = 0; k < c->elems[i].nattrs; k++)
            free(c->elems[i].attrs[k].data);
    free(c);
    free(data);
    return rc;
}
