#define _POSIX_C_SOURCE 200809L
#include "io/obj_check.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stb_image.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/file.h"
#include "core/log.h"
#include "scene/scene.h"

#define MAX_TEXT_BYTES ((uint64_t)1 << 31)

int cdl_read_text_file(const char *path, char **data, size_t *size, cdl_error *err)
{
    return cdl_read_file(path, MAX_TEXT_BYTES, data, size, err);
}

/* A tokenizer over one line: whitespace separated words. */
typedef struct line_cursor {
    char *p;
} line_cursor;

static char *next_word(line_cursor *c)
{
    while (*c->p == ' ' || *c->p == '\t' || *c->p == '\r')
        c->p++;
    if (!*c->p)
        return NULL;
    char *w = c->p;
    while (*c->p && *c->p != ' ' && *c->p != '\t' && *c->p != '\r')
        c->p++;
    if (*c->p)
        *c->p++ = 0;
    return w;
}

/* Rest of the line with surrounding whitespace removed (file names). */
static char *rest_of_line(line_cursor *c)
{
    while (*c->p == ' ' || *c->p == '\t')
        c->p++;
    char *s = c->p, *e = s + strlen(s);
    while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r'))
        *--e = 0;
    return s;
}

static int parse_float(const char *w, float *out)
{
    char *end;
    errno = 0;
    double d = strtod(w, &end);
    if (end == w || *end)
        return -1;
    *out = (float)d;
    return 0;
}

/* Splits data into lines in place; calls back with 1-based numbers. */
typedef int (*line_fn)(void *ctx, char *line, int lineno);

static int for_each_line(char *data, size_t size, const char *path, line_fn fn, void *ctx,
                         cdl_error *err)
{
    int lineno = 0;
    char *p = data, *end = data + size;
    while (p < end) {
        char *nl = memchr(p, '\n', (size_t)(end - p));
        char *e = nl ? nl : end;
        lineno++;
        for (char *q = p; q < e; q++) {
            unsigned char ch = (unsigned char)*q;
            if ((ch < 0x20 && ch != '\t' && ch != '\r') || ch == 0x7f)
                return cdl_error_set(err, CDL_ERR_INPUT, path, lineno,
                                     "binary data (byte 0x%02x): not a text file", ch);
        }
        *e = 0;
        char *hash = strchr(p, '#');
        if (hash)
            *hash = 0;
        int rc = fn(ctx, p, lineno);
        if (rc)
            return rc;
        p = e + 1;
    }
    return 0;
}

/* ---------------- MTL ---------------- */

typedef struct mtl_names {
    char **names;
    int n, cap;
} mtl_names;

typedef struct mtl_ctx {
    const char *path;
    cdl_error *err;
    mtl_names *names;
    int in_material;
} mtl_ctx;

static int mtl_error(mtl_ctx *c, int line, const char *what)
{
    return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s", what);
}

/* Reads 1 or 3 numbers into v (one number means grey). */
static int mtl_color(mtl_ctx *c, line_cursor *lc, const char *key, int line, float lo, float hi)
{
    float v[3];
    int n = 0;
    char *w;
    while ((w = next_word(lc))) {
        if (n == 3 || parse_float(w, &v[n]))
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "%s expects 1 or 3 numbers, got '%s'", key, w);
        n++;
    }
    if (n != 1 && n != 3)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s expects 1 or 3 numbers", key);
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]) || v[i] < lo || v[i] > hi)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "%s value %g outside [%g, %g]", key, (double)v[i], (double)lo,
                                 (double)hi);
    return 0;
}

static int mtl_scalar(mtl_ctx *c, line_cursor *lc, const char *key, int line, float lo, float hi,
                      int integer)
{
    char *w = next_word(lc);
    float v;
    if (!w || parse_float(w, &v) || next_word(lc))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s expects one number", key);
    if (!isfinite(v) || v < lo || v > hi || (integer && v != floorf(v)))
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s value %s outside %s[%g, %g]",
                             key, w, integer ? "the integers in " : "", (double)lo, (double)hi);
    return 0;
}

static int mtl_line(void *vc, char *line, int lineno)
{
    mtl_ctx *c = vc;
    line_cursor lc = {line};
    char *key = next_word(&lc);
    if (!key)
        return 0;
    if (!strcmp(key, "newmtl")) {
        char *name = rest_of_line(&lc);
        if (!*name)
            return mtl_error(c, lineno, "newmtl without a name");
        if (c->names->n == c->names->cap) {
            int cap = c->names->cap ? 2 * c->names->cap : 16;
            char **p = realloc(c->names->names, sizeof(char *) * (size_t)cap);
            if (!p)
                return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, lineno, "out of memory");
            c->names->names = p;
            c->names->cap = cap;
        }
        char *dup = strdup(name);
        if (!dup)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, lineno, "out of memory");
        c->names->names[c->names->n++] = dup;
        c->in_material = 1;
        return 0;
    }
    if (!c->in_material)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "'%s' before any newmtl", key);
    if (!strcmp(key, "Kd") || !strcmp(key, "Ks") || !strcmp(key, "Tf"))
        return mtl_color(c, &lc, key, lineno, 0.0f, 1.0f);
    if (!strcmp(key, "Ka"))
        return mtl_color(c, &lc, key, lineno, 0.0f, 1e20f);
    if (!strcmp(key, "Ke"))
        return mtl_color(c, &lc, key, lineno, 0.0f, 1e20f);
    if (!strcmp(key, "Ns"))
        return mtl_scalar(c, &lc, key, lineno, 0.0f, 1e6f, 0);
    if (!strcmp(key, "Ni"))
        return mtl_scalar(c, &lc, key, lineno, 1e-3f, 100.0f, 0);
    if (!strcmp(key, "d") || !strcmp(key, "Tr"))
        return mtl_scalar(c, &lc, key, lineno, 0.0f, 1.0f, 0);
    if (!strcmp(key, "illum"))
        return mtl_scalar(c, &lc, key, lineno, 0.0f, 10.0f, 1);
    if (!strncmp(key, "map_", 4) || !strcmp(key, "bump") || !strcmp(key, "disp") ||
        !strcmp(key, "decal") || !strcmp(key, "refl") || !strcmp(key, "norm")) {
        /* Options (-bm 1 ...) come first; the file name is the last word. */
        char *w, *last = NULL;
        while ((w = next_word(&lc)))
            last = w;
        if (!last)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "%s without a file name", key);
        char full[2048];
        cdl_path_join_dir(c->path, last, full, sizeof full);
        struct stat st;
        if (stat(full, &st) != 0)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "%s: cannot open '%s': %s",
                                 key, full, strerror(errno));
        if (!S_ISREG(st.st_mode))
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "%s: '%s' is not a regular file",
                                 key, full);
        if (!strcmp(key, "map_Kd")) {
            int w0, h0, n0;
            if (!stbi_info(full, &w0, &h0, &n0))
                return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno,
                                     "map_Kd: '%s' is not a readable image (%s)", full,
                                     stbi_failure_reason());
        } else {
            cdl_warn(c->path, lineno, "%s is not supported and is ignored", key);
        }
        return 0;
    }
    return 0; /* Pr, Pm, sharpness, ... carry nothing candela uses */
}

static int check_mtl(const char *path, mtl_names *names, cdl_error *err)
{
    char *data;
    size_t size;
    int rc = cdl_read_text_file(path, &data, &size, err);
    if (rc)
        return rc;
    mtl_ctx c = {path, err, names, 0};
    rc = for_each_line(data, size, path, mtl_line, &c, err);
    free(data);
    return rc;
}

/* ---------------- OBJ ---------------- */

typedef struct obj_ctx {
    const char *path;
    cdl_error *err;
    long nv, nvt, nvn, nfaces;
    mtl_names names;
    int nmtllib;
    /* first usemtl of each name is checked once all MTLs are read */
    char **use;
    int *use_line;
    int nuse, capuse;
    int warned_unknown;
} obj_ctx;

static int obj_numbers(obj_ctx *c, line_cursor *lc, const char *key, int line, int min, int max,
                       float limit, int *count)
{
    int n = 0;
    char *w;
    while ((w = next_word(lc))) {
        float v;
        if (parse_float(w, &v))
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s: '%s' is not a number", key, w);
        /* Assimp counts a vertex's numbers by their first character and
         * silently drops a vertex with a number such as ".5" */
        if (!isdigit((unsigned char)w[0]) && w[0] != '-' && w[0] != '+')
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "%s: write '%s' with a digit first (as 0%s): the importer misreads it", key, w, w);
        if (!isfinite(v) || fabsf(v) > limit)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                                 "%s: coordinate %s is not finite or beyond %g", key, w, (double)limit);
        n++;
    }
    if (count)
        *count = n;
    if (n < min || n > max)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "%s expects %d to %d numbers, got %d",
                             key, min, max, n);
    return 0;
}

/* One index of a face; 0 means "absent" (as in v//vn). */
static int obj_index(obj_ctx *c, const char **s, long count, const char *what, int line, int required)
{
    const char *p = *s;
    if (*p == '/' || *p == 0) {
        if (required)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "face is missing a %s index", what);
        return 0;
    }
    char *end;
    errno = 0;
    long i = strtol(p, &end, 10);
    if (end == p || (*end && *end != '/') || errno)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "bad %s index in face", what);
    long r = i < 0 ? count + 1 + i : i;
    if (i == 0 || r < 1 || r > count)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line,
                             "%s index %ld out of range (%ld defined so far)", what, i, count);
    *s = end;
    return 0;
}

static int obj_face(obj_ctx *c, line_cursor *lc, int line)
{
    int n = 0;
    char *w;
    while ((w = next_word(lc))) {
        const char *s = w;
        if (obj_index(c, &s, c->nv, "vertex", line, 1))
            return c->err->code;
        if (*s == '/') {
            s++;
            if (*s != '/' && obj_index(c, &s, c->nvt, "texture coordinate", line, 0))
                return c->err->code;
            if (*s == '/') {
                s++;
                if (obj_index(c, &s, c->nvn, "normal", line, 1))
                    return c->err->code;
            }
        }
        if (*s)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "malformed face vertex '%s'", w);
        n++;
    }
    if (n < 3)
        return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, line, "face needs at least 3 vertices, got %d", n);
    c->nfaces++;
    return 0;
}

static int obj_line(void *vc, char *line, int lineno)
{
    obj_ctx *c = vc;
    line_cursor lc = {line};
    char *key = next_word(&lc);
    if (!key)
        return 0;
    if (!strcmp(key, "v")) {
        c->nv++;
        int n = 0, rc = obj_numbers(c, &lc, key, lineno, 3, 6, CDL_MAX_COORD, &n);
        /* Assimp reads x y z, x y z w or x y z r g b, and drops any other
         * count's vertex, which shifts every later index */
        if (!rc && n == 5)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno,
                                 "v expects 3 (x y z), 4 (x y z w) or 6 (x y z r g b) numbers, got 5");
        return rc;
    }
    if (!strcmp(key, "vt")) {
        c->nvt++;
        return obj_numbers(c, &lc, key, lineno, 1, 3, CDL_MAX_COORD, NULL);
    }
    if (!strcmp(key, "vn")) {
        c->nvn++;
        return obj_numbers(c, &lc, key, lineno, 3, 3, CDL_MAX_COORD, NULL);
    }
    if (!strcmp(key, "f"))
        return obj_face(c, &lc, lineno);
    if (!strcmp(key, "mtllib")) {
        char *name = rest_of_line(&lc);
        if (!*name)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "mtllib without a file name");
        char full[2048];
        cdl_path_join_dir(c->path, name, full, sizeof full);
        struct stat st;
        if (stat(full, &st) != 0)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "mtllib: cannot open '%s': %s",
                                 full, strerror(errno));
        if (!S_ISREG(st.st_mode))
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno,
                                 "mtllib: '%s' is not a regular file", full);
        c->nmtllib++;
        return check_mtl(full, &c->names, c->err);
    }
    if (!strcmp(key, "usemtl")) {
        char *name = rest_of_line(&lc);
        if (!*name)
            return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, lineno, "usemtl without a name");
        for (int i = 0; i < c->nuse; i++)
            if (!strcmp(c->use[i], name))
                return 0;
        if (c->nuse == c->capuse) {
            int cap = c->capuse ? 2 * c->capuse : 16;
            char **u = realloc(c->use, sizeof(char *) * (size_t)cap);
            if (u)
                c->use = u;
            int *l = realloc(c->use_line, sizeof(int) * (size_t)cap);
            if (l)
                c->use_line = l;
            if (!u || !l)
                return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, lineno, "out of memory");
            c->capuse = cap;
        }
        c->use[c->nuse] = strdup(name);
        if (!c->use[c->nuse])
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, lineno, "out of memory");
        c->use_line[c->nuse++] = lineno;
        return 0;
    }
    static const char *known[] = {"g", "o", "s", "l", "p", "vp", "mg", "cstype", "deg", "bmat",
                                  "step", "curv", "curv2", "surf", "parm", "trim", "hole",
                                  "scrv", "sp", "end", "con", "bevel", "c_interp", "d_interp",
                                  "lod", "usemap", "maplib", "shadow_obj", "trace_obj", "ctech",
                                  "stech", "call", "csh"};
    for (size_t i = 0; i < sizeof known / sizeof *known; i++)
        if (!strcmp(key, known[i]))
            return 0;
    if (!c->warned_unknown) {
        cdl_warn(c->path, lineno, "unknown statement '%.32s' ignored", key);
        c->warned_unknown = 1;
    }
    return 0;
}

int cdl_obj_check(const char *path, cdl_error *err)
{
    char *data;
    size_t size;
    int rc = cdl_read_text_file(path, &data, &size, err);
    if (rc)
        return rc;
    obj_ctx c;
    memset(&c, 0, sizeof c);
    c.path = path;
    c.err = err;
    rc = for_each_line(data, size, path, obj_line, &c, err);
    free(data);
    if (!rc && c.nfaces == 0)
        rc = cdl_error_set(err, CDL_ERR_INPUT, path, 0,
                           size == 0 ? "empty file: no faces" : "no faces in the file");
    for (int i = 0; !rc && i < c.nuse; i++) {
        int found = 0;
        for (int k = 0; k < c.names.n && !found; k++)
            found = !strcmp(c.names.names[k], c.use[i]);
        if (!found) /* Assimp, like the renderers OBJ comes from, gives such faces a default material */
            cdl_warn(path, c.use_line[i],
                     c.nmtllib ? "usemtl '%s': no such material in the MTL files (a default diffuse is used)"
                               : "usemtl '%s' but the file names no mtllib (a default diffuse is used)",
                     c.use[i]);
    }
    for (int i = 0; i < c.nuse; i++)
        free(c.use[i]);
    free(c.use);
    free(c.use_line);
    for (int i = 0; i < c.names.n; i++)
        free(c.names.names[i]);
    free(c.names.names);
    return rc;
}
