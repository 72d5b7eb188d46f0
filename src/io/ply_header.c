/* PLY header parsing: the format line, element and property declarations,
 * the type table, and the roles of the properties the reader keeps. The
 * body is read by ply.c. */
#include "io/ply_format.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

/* ---- types -------------------------------------------------------------------------------- */

const ply_type cdl_ply_types[T_NTYPES] = {
    {"char", "int8", 1},   {"uchar", "uint8", 1}, {"short", "int16", 2},   {"ushort", "uint16", 2},
    {"int", "int32", 4},   {"uint", "uint32", 4}, {"float", "float32", 4}, {"double", "float64", 8},
};

/* ---- header -------------------------------------------------------------------------------- */

static int type_from_name(const char *s)
{
    for (int t = 0; t < T_NTYPES; t++)
        if (!strcmp(s, cdl_ply_types[t].name) || !strcmp(s, cdl_ply_types[t].alias))
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

/* The attribute prefix of property name n and its channel letter (0 when
 * the name has no channel suffix). */
static char attr_split(const char *n, char *prefix, size_t size)
{
    static const char *bare[2][4] = {{"r", "g", "b", "a"}, {"red", "green", "blue", "alpha"}};
    for (int s = 0; s < 2; s++)
        for (int k = 0; k < 4; k++)
            if (!strcmp(n, bare[s][k])) {
                snprintf(prefix, size, "color");
                return "rgba"[k];
            }
    const char *us = strrchr(n, '_');
    if (us && us > n && us[1] && !us[2] && strchr("xyzwrgba01234", us[1])) {
        snprintf(prefix, size, "%.*s", (int)(us - n), n);
        return us[1];
    }
    snprintf(prefix, size, "%s", n);
    return 0;
}

/* Channel of letter ch in a group that started with letter first (or -1:
 * not its scheme). */
static int attr_chan(char first, char ch)
{
    static const char *schemes[] = {"xyzw", "rgba", "0123", "1234"};
    for (int s = 0; s < 4; s++)
        if (schemes[s][0] == first && ch && strchr(schemes[s], ch))
            return (int)(strchr(schemes[s], ch) - schemes[s]);
    return -1;
}

/* Groups e's unused scalar properties into attributes named kind_prefix. */
static void assign_attrs(ply_elem *e, const char *kind)
{
    char prev[CDL_ATTR_NAME] = "", first = 0;
    int prev_chan = -2;
    for (int i = 0; i < e->nprops; i++) {
        ply_prop *p = &e->props[i];
        char prefix[CDL_ATTR_NAME];
        if (p->role != R_SKIP || p->list) {
            prev_chan = -2;
            continue;
        }
        char ch = attr_split(p->name, prefix, sizeof prefix);
        int chan = prev_chan >= 0 && !strcmp(prefix, prev) ? attr_chan(first, ch) : -1;
        if (chan < 0 || chan != prev_chan + 1) { /* a new attribute */
            if (e->nattrs == PLY_MAX_ATTRS)
                continue;
            ply_attr *a = &e->attrs[e->nattrs++];
            size_t nk = strlen(kind), np = strlen(prefix); /* long names are cut */
            if (nk + 1 + np >= sizeof a->name)
                np = sizeof a->name - nk - 2;
            memcpy(a->name, kind, nk);
            a->name[nk] = '_';
            memcpy(a->name + nk + 1, prefix, np);
            a->name[nk + 1 + np] = 0;
            a->dim = 0;
            first = ch;
            chan = attr_chan(first, ch) == 0 ? 0 : -2; /* -2: a lone property */
        }
        ply_attr *a = &e->attrs[e->nattrs - 1];
        p->role = R_ATTR;
        p->attr = e->nattrs - 1;
        p->chan = a->dim < 3 ? a->dim : -1;
        if (a->dim < 3)
            a->dim++;
        snprintf(prev, sizeof prev, "%s", prefix);
        prev_chan = chan;
    }
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
                             cdl_ply_types[ix->type].name);
    ix->role = R_INDICES;
    assign_attrs(v, "vertex");
    assign_attrs(f, "face");
    c->nverts = (uint32_t)v->count;
    return 0;
}

/* Parses the header; on success *body is the offset of the first body byte
 * and *body_line the text line it starts on. */
int cdl_ply_parse_header(ply_ctx *c, unsigned char *data, size_t size, size_t *body, int *body_line)
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
