#define _POSIX_C_SOURCE 200809L
#include "scene/ply.h"

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

#define PLY_MAX_BYTES ((uint64_t)1 << 34) /* 16 GiB: far beyond any mesh we render */
#define PLY_MAX_ELEMS 32
#define PLY_MAX_PROPS 64
#define PLY_MAX_TRIS (UINT32_MAX / 3u) /* keeps 3 * ntris within a uint32_t */

enum { FMT_NONE, FMT_ASCII, FMT_LE, FMT_BE };
enum { T_INT8, T_UINT8, T_INT16, T_UINT16, T_INT32, T_UINT32, T_FLOAT32, T_FLOAT64, T_NTYPES };
#define IS_INT_TYPE(t) ((t) <= T_UINT32)

static const struct {
    const char *name, *alias;
    unsigned size;
} ply_types[T_NTYPES] = {
    {"char", "int8", 1},   {"uchar", "uint8", 1}, {"short", "int16", 2},   {"ushort", "uint16", 2},
    {"int", "int32", 4},   {"uint", "uint32", 4}, {"float", "float32", 4}, {"double", "float64", 8},
};

/* What a property is used for; everything else is read and dropped. */
enum { R_SKIP, R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_U, R_V, R_INDICES };

typedef struct ply_prop {
    const char *name; /* points into the (NUL-split) header */
    int type;         /* item type for lists */
    int list, count_type, role, line;
} ply_prop;

typedef struct ply_elem {
    const char *name;
    uint64_t count;
    int line, nprops;
    ply_prop props[PLY_MAX_PROPS];
} ply_elem;

typedef struct ply_ctx {
    const char *path;
    cdl_error *err;
    int fmt, nelems;
    ply_elem elems[PLY_MAX_ELEMS];
    int vert, face; /* index into elems, or -1 */
    const unsigned char *p, *end; /* body cursor */
    int line;                     /* ASCII: text line of p */
    const ply_elem *cur;          /* element being read, for messages */
    uint64_t cur_i;
    uint32_t nverts; /* declared vertex count, bounds the indices */
    cdl_ply_mesh out;
    uint64_t vcap, tcap;
} ply_ctx;

void cdl_ply_free(cdl_ply_mesh *m)
{
    if (!m)
        return;
    free(m->pos);
    free(m->nrm);
    free(m->uv);
    free(m->idx);
    memset(m, 0, sizeof *m);
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

/* Strict decimal integer: optional sign and digits only. -1 = not an
 * integer, -2 = more than 18 significant digits. */
static int parse_int(const char *s, int64_t *out)
{
    int neg = 0, nd = 0;
    if (*s == '+' || *s == '-')
        neg = *s++ == '-';
    if (*s < '0' || *s > '9')
        return -1;
    uint64_t v = 0;
    for (; *s >= '0' && *s <= '9'; s++) {
        if (v || *s != '0')
            nd++;
        if (nd > 18)
            return -2;
        v = v * 10 + (uint64_t)(*s - '0');
    }
    if (*s)
        return -1;
    *out = neg ? -(int64_t)v : (int64_t)v;
    return 0;
}

/* ---- header -------------------------------------------------------------------------------- */

static int type_from_name(const char *s)
{
    for (int t = 0; t < T_NTYPES; t++)
        if (!strcmp(s, ply_types[t].name) || !strcmp(s, ply_types[t].alias))
            return t;
    return -1;
}

static char *next_hword(char **cur)
{
    char *p = *cur;
    while (*p == ' ' || *p == '\t' || *p == '\r')
        p++;
    if (!*p) {
        *cur = p;
        return NULL;
    }
    char *w = p;
    while (*p && *p != ' ' && *p != '\t' && *p != '\r')
        p++;
    if (*p)
        *p++ = 0;
    *cur = p;
    return w;
}

static ply_prop *find_prop(ply_elem *e, const char *name)
{
    for (int i = 0; i < e->nprops; i++)
        if (!strcmp(e->props[i].name, name))
            return &e->props[i];
    return NULL;
}

static int parse_property(ply_ctx *c, char **cur, int line)
{
    if (c->nelems == 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "property before any element");
    ply_elem *e = &c->elems[c->nelems - 1];
    if (e->nprops == PLY_MAX_PROPS)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "too many properties in element '%.64s' (max %d)", e->name,
                             PLY_MAX_PROPS);
    ply_prop pr = {.role = R_SKIP, .line = line, .count_type = -1};
    char *w = next_hword(cur);
    if (!w)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "property needs a type and a name");
    if (!strcmp(w, "list")) {
        char *ct = next_hword(cur), *it = next_hword(cur);
        pr.name = next_hword(cur);
        if (!pr.name)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "property list needs a count type, an item type and a name");
        pr.list = 1;
        pr.count_type = type_from_name(ct);
        if (pr.count_type < 0)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "unknown property type '%.32s'", ct);
        if (!IS_INT_TYPE(pr.count_type))
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "list count type must be an integer type, not '%s'", ct);
        w = it;
    } else {
        pr.name = next_hword(cur);
        if (!pr.name)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "property needs a type and a name");
    }
    pr.type = type_from_name(w);
    if (pr.type < 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "unknown property type '%.32s'", w);
    if (next_hword(cur))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "extra words after property '%.64s'", pr.name);
    if (find_prop(e, pr.name))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "duplicate property '%.64s' in element '%.64s'", pr.name, e->name);
    e->props[e->nprops++] = pr;
    return 0;
}

static int parse_element(ply_ctx *c, char **cur, int line)
{
    if (c->nelems == PLY_MAX_ELEMS)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "too many elements (max %d)",
                             PLY_MAX_ELEMS);
    char *name = next_hword(cur), *cnt = next_hword(cur);
    if (!cnt)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "element needs a name and a count");
    if (next_hword(cur))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "extra words after element '%.64s'", name);
    int64_t n;
    int rc = parse_int(cnt, &n);
    if (rc == -1)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "element count '%.32s' is not a number", cnt);
    if (rc == 0 && n < 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "element count %" PRId64 " is negative", n);
    if (rc == -2 || n > (int64_t)UINT32_MAX)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "element count %.32s is too large (max %" PRIu32 ")", cnt, UINT32_MAX);
    int is_vert = !strcmp(name, "vertex"), is_face = !strcmp(name, "face");
    if ((is_vert && c->vert >= 0) || (is_face && c->face >= 0))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "duplicate element '%s'", name);
    if (is_vert)
        c->vert = c->nelems;
    if (is_face)
        c->face = c->nelems;
    ply_elem *e = &c->elems[c->nelems++];
    e->name = name;
    e->count = (uint64_t)n;
    e->line = line;
    e->nprops = 0;
    return 0;
}

/* Marks which properties are kept and checks the vertex and face elements. */
static int assign_roles(ply_ctx *c)
{
    if (c->vert < 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0, "no vertex element");
    if (c->face < 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0, "no face element");
    ply_elem *v = &c->elems[c->vert], *f = &c->elems[c->face];
    static const char *xyz[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; k++) {
        ply_prop *p = find_prop(v, xyz[k]);
        if (!p)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, v->line,
                                 "vertex element has no '%s' property", xyz[k]);
        if (p->list)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, p->line,
                                 "vertex property '%s' must not be a list", xyz[k]);
        p->role = R_X + k;
    }
    /* Normals and uv only when complete; a lone "u" is just another property. */
    ply_prop *n[3] = {find_prop(v, "nx"), find_prop(v, "ny"), find_prop(v, "nz")};
    if (n[0] && n[1] && n[2] && !n[0]->list && !n[1]->list && !n[2]->list)
        for (int k = 0; k < 3; k++)
            n[k]->role = R_NX + k;
    static const char *uvnames[4][2] = {
        {"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};
    for (int k = 0; k < 4; k++) {
        ply_prop *a = find_prop(v, uvnames[k][0]), *b = find_prop(v, uvnames[k][1]);
        if (a && b && !a->list && !b->list) {
            a->role = R_U;
            b->role = R_V;
            break;
        }
    }
    ply_prop *ix = find_prop(f, "vertex_indices");
    if (!ix)
        ix = find_prop(f, "vertex_index");
    if (!ix)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, f->line,
                             "face element has no vertex_indices list");
    if (!ix->list)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, ix->line,
                             "face property '%s' must be a list", ix->name);
    if (!IS_INT_TYPE(ix->type))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, ix->line,
                             "face property '%s' must hold integers, not %s", ix->name,
                             ply_types[ix->type].name);
    ix->role = R_INDICES;
    c->nverts = (uint32_t)v->count;
    return 0;
}

/* Parses the header; on success *body is the offset of the first body byte
 * and *body_line the text line it starts on. */
static int parse_header(ply_ctx *c, unsigned char *data, size_t size, size_t *body, int *body_line)
{
    if (size == 0)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0, "empty file");
    size_t off = 0;
    int line = 0, done = 0;
    while (!done) {
        if (off >= size)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0,
                                 "no end_header line (the header runs to the end of the file)");
        unsigned char *s = data + off;
        unsigned char *nl = memchr(s, '\n', size - off);
        size_t len = nl ? (size_t)(nl - s) : size - off;
        off += len + (nl ? 1 : 0);
        line++;
        if (line == 1) {
            /* The magic first, so that binary garbage gets a plain answer. */
            size_t k = len;
            while (k > 0 && (s[k - 1] == '\r' || s[k - 1] == ' ' || s[k - 1] == '\t'))
                k--;
            if (k != 3 || memcmp(s, "ply", 3) != 0)
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 1,
                                     "not a PLY file (the first line is not 'ply')");
            continue;
        }
        for (size_t k = 0; k < len; k++)
            if ((s[k] < 0x20 && s[k] != '\t' && s[k] != '\r') || s[k] == 0x7f)
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "binary data in the header (byte 0x%02x)", s[k]);
        s[len] = 0; /* the newline or the buffer's terminator */
        char *cur = (char *)s;
        char *kw = next_hword(&cur);
        if (!kw)
            continue; /* blank line */
        int rc = 0;
        if (!strcmp(kw, "comment") || !strcmp(kw, "obj_info")) {
            continue;
        } else if (!strcmp(kw, "format")) {
            char *f = next_hword(&cur), *ver = next_hword(&cur);
            if (c->fmt != FMT_NONE)
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "duplicate format line");
            if (!ver)
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "format needs a type and a version");
            if (!strcmp(f, "ascii"))
                c->fmt = FMT_ASCII;
            else if (!strcmp(f, "binary_little_endian"))
                c->fmt = FMT_LE;
            else if (!strcmp(f, "binary_big_endian"))
                c->fmt = FMT_BE;
            else
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "unknown format '%.40s' (expected ascii, binary_little_endian "
                                     "or binary_big_endian)", f);
            if (strcmp(ver, "1.0") && strcmp(ver, "1"))
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "unsupported PLY version '%.32s' (expected 1.0)", ver);
            if (next_hword(&cur))
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "extra words after the format");
        } else if (!strcmp(kw, "element")) {
            rc = parse_element(c, &cur, line);
        } else if (!strcmp(kw, "property")) {
            rc = parse_property(c, &cur, line);
        } else if (!strcmp(kw, "end_header")) {
            if (c->fmt == FMT_NONE)
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                     "no format line before end_header");
            done = 1;
        } else {
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "unknown header keyword '%.40s'", kw);
        }
        if (rc)
            return rc;
    }
    *body = off;
    *body_line = line + 1;
    return assign_roles(c);
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
                              ply_types[t].name);
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
    unsigned sz = ply_types[t].size;
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
        uint64_t bytes = (uint64_t)n * ply_types[pr->type].size;
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
            b += ply_types[p->count_type].size + items * ply_types[p->type].size;
        else
            b += ply_types[p->type].size;
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

static int grow_verts(ply_ctx *c, uint64_t cap, int has_n, int has_uv)
{
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
    return 0;
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
    if (c->fmt != FMT_ASCII && (uint64_t)n * ply_types[pr->type].size > (uint64_t)(c->end - c->p))
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
    }
    for (uint64_t i = 0; i < e->count; i++) {
        c->cur_i = i;
        int rc = begin_instance(c);
        for (int k = 0; !rc && k < e->nprops; k++) {
            const ply_prop *pr = &e->props[k];
            rc = pr->role == R_INDICES ? read_face_indices(c, pr) : skip_prop(c, pr);
        }
        if (rc || (rc = end_instance(c)))
            return rc;
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
    rc = parse_header(c, data, size, &body, &c->line);
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
    free(c);
    free(data);
    return rc;
}
