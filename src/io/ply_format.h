/* State shared by the two parts of the PLY reader: ply_header.c (format,
 * element and property declarations, the type table) and ply.c (ASCII and
 * binary body decoding, face triangulation, the entry point). Not a public
 * interface (see ply.h); included by those two files only. */
#ifndef CDL_PLY_INTERNAL_H
#define CDL_PLY_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"
#include "io/ply.h"

#define PLY_MAX_BYTES ((uint64_t)1 << 34) /* 16 GiB: far beyond any mesh we render */
#define PLY_MAX_ELEMS 32
#define PLY_MAX_PROPS 64
#define PLY_MAX_TRIS (UINT32_MAX / 3u) /* keeps 3 * ntris within a uint32_t */

enum { FMT_NONE, FMT_ASCII, FMT_LE, FMT_BE };
enum { T_INT8, T_UINT8, T_INT16, T_UINT16, T_INT32, T_UINT32, T_FLOAT32, T_FLOAT64, T_NTYPES };
#define IS_INT_TYPE(t) ((t) <= T_UINT32)

typedef struct ply_type {
    const char *name, *alias;
    unsigned size;
} ply_type;

/* Names, aliases and sizes of the scalar types (ply_header.c). */
extern const ply_type cdl_ply_types[T_NTYPES];

/* What a property is used for; everything else is read and dropped. */
enum { R_SKIP, R_X, R_Y, R_Z, R_NX, R_NY, R_NZ, R_U, R_V, R_INDICES, R_ATTR };

typedef struct ply_prop {
    const char *name; /* points into the (NUL-split) header */
    int type;         /* item type for lists */
    int list, count_type, role, line;
    int attr, chan;   /* R_ATTR: the element's attribute and channel */
} ply_prop;

/* Mitsuba's grouping of a vertex's or face's other scalar properties:
 * consecutive {prefix}_{x|y|z|w}, _{r|g|b|a}, _{0..3} or _{1..4} (and a
 * bare r g b a or red green blue alpha, prefix "color") form one
 * attribute "{vertex|face}_{prefix}"; channels past the third are dropped. */
#define PLY_MAX_ATTRS 16
typedef struct ply_attr {
    char name[CDL_ATTR_NAME];
    int dim;     /* channels kept, 1..3 */
    float *data; /* dim per vertex, or per triangle for faces */
} ply_attr;

typedef struct ply_elem {
    const char *name;
    uint64_t count;
    int line, nprops;
    ply_prop props[PLY_MAX_PROPS];
    int nattrs;
    ply_attr attrs[PLY_MAX_ATTRS];
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

/* Strict decimal integer: optional sign and digits only. -1 = not an
 * integer, -2 = more than 18 significant digits. */
static inline int parse_int(const char *s, int64_t *out)
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

/* Parses the header of the file in data (NUL-terminated at data[size]; the
 * header lines are split in place, names point into them), fills c->fmt,
 * c->elems, c->vert, c->face, the property roles and c->nverts. On success
 * *body is the offset of the first body byte and *body_line the text line it
 * starts on. */
int cdl_ply_parse_header(ply_ctx *c, unsigned char *data, size_t size, size_t *body,
                         int *body_line);

#endif
