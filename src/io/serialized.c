#define _POSIX_C_SOURCE 200809L
#include "io/serialized.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "core/log.h"
#include "scene/scene.h"

#define SER_ID 0x041Cu
#define SER_ID_SWAPPED 0x1C04u   /* the id of the big-endian format before version 3 */
#define SER_MAX_COUNT (1u << 28) /* vertices or triangles in one shape */
#define SER_MAX_NAME 65536u      /* bytes of a version 4 shape name */
/* Deflate expands at most 1032:1 (zlib's technical notes), so counts that
 * need more than this from the compressed bytes are refused before anything
 * is allocated for them. */
#define SER_MAX_RATIO 1032u
#define SER_CHUNK 32768u /* scratch for doubles and skipped colors */

enum {
    F_NORMALS = 0x0001,
    F_UV = 0x0002,
    F_TANGENTS = 0x0004, /* defined by Mitsuba but never written; it adds no data */
    F_COLORS = 0x0008,
    F_FACE_NORMALS = 0x0010,
    F_SINGLE = 0x1000,
    F_DOUBLE = 0x2000,
    F_KNOWN = F_NORMALS | F_UV | F_TANGENTS | F_COLORS | F_FACE_NORMALS | F_SINGLE | F_DOUBLE
};

enum { K_POS, K_NRM, K_UV, K_SKIP };
static const char *kind_name[] = {"position", "normal", "texture coordinate", "color"};

typedef struct ser_ctx {
    const char *path;
    cdl_error *err;
    uint32_t shape;
    int fd;
    uint64_t fsize;
    int version;
    unsigned char *comp; /* the shape's bytes, its 4-byte header included */
    unsigned char *in;   /* compressed bytes not yet handed to zlib ... */
    uint64_t in_left;    /* ... and how many (zlib takes at most UINT_MAX at a time) */
    int next_is_dict;    /* for messages: the dictionary, not a shape, follows */
    z_stream z;
    int z_live, z_end;
    uint64_t out;  /* bytes decompressed so far */
    uint64_t need; /* bytes the counts say the stream holds; 0 until they are read */
    cdl_serialized_mesh m;
} ser_ctx;

void cdl_serialized_free(cdl_serialized_mesh *m)
{
    if (m)
        cdl_mesh_free(m);
}

/* ---- messages ------------------------------------------------------------------------------ */

__attribute__((format(printf, 2, 3))) static int file_fail(ser_ctx *c, const char *fmt, ...)
{
    char msg[448];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0, "%s", msg);
}

/* "shape 3: ...": the binary data has no lines, so the shape locates the problem. */
__attribute__((format(printf, 2, 3))) static int shape_fail(ser_ctx *c, const char *fmt, ...)
{
    char msg[448];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return cdl_error_set(c->err, CDL_ERR_INPUT, c->path, 0, "shape %" PRIu32 ": %s", c->shape, msg);
}

static int oom(ser_ctx *c)
{
    return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, 0, "out of memory");
}

/* ---- little-endian values ------------------------------------------------------------------ */

static inline uint32_t le16(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8;
}

static inline uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static inline uint64_t le64(const unsigned char *p)
{
    return le32(p) | (uint64_t)le32(p + 4) << 32;
}

static inline float le_float(const unsigned char *p)
{
    uint32_t w = le32(p);
    float f;
    memcpy(&f, &w, 4);
    return f;
}

static inline double le_double(const unsigned char *p)
{
    uint64_t w = le64(p);
    double d;
    memcpy(&d, &w, 8);
    return d;
}

/* ---- the file ------------------------------------------------------------------------------ */

static int open_file(ser_ctx *c)
{
    struct stat st;
    /* stat before open: opening a FIFO would block */
    if (stat(c->path, &st) != 0)
        return file_fail(c, "cannot open: %s", strerror(errno));
    if (S_ISDIR(st.st_mode))
        return file_fail(c, "is a directory, not a file");
    if (!S_ISREG(st.st_mode))
        return file_fail(c, "not a regular file");
    c->fd = open(c->path, O_RDONLY);
    if (c->fd < 0)
        return file_fail(c, "cannot open: %s", strerror(errno));
    if (fstat(c->fd, &st) != 0 || !S_ISREG(st.st_mode))
        return file_fail(c, "not a regular file");
    c->fsize = (uint64_t)st.st_size;
    return 0;
}

static int read_at(ser_ctx *c, uint64_t off, void *buf, size_t n)
{
    unsigned char *p = buf;
    while (n > 0) {
        ssize_t got = pread(c->fd, p, n, (off_t)off);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0)
            return cdl_error_set(c->err, CDL_ERR_SYSTEM, c->path, 0, "read error: %s", strerror(errno));
        if (got == 0)
            return file_fail(c, "read error: the file ends at byte %" PRIu64 " (it shrank while read?)", off);
        p += got;
        n -= (size_t)got;
        off += (uint64_t)got;
    }
    return 0;
}

/* The format id and version at the start of the file. */
static int check_file_header(ser_ctx *c, const unsigned char *h)
{
    uint32_t id = le16(h), ver = le16(h + 2);
    if (id == SER_ID_SWAPPED)
        return file_fail(c, "format id 0x041c stored big-endian: a mesh from Mitsuba before 0.4, which "
                            "this reader does not support (re-export it with a newer Mitsuba)");
    if (id != SER_ID)
        return file_fail(c, "not a Mitsuba serialized mesh: format id 0x%04" PRIx32 " (expected 0x041c)", id);
    if (ver != 3 && ver != 4)
        return file_fail(c, "unsupported version %" PRIu32 " (this reader knows versions 3 and 4)", ver);
    c->version = (int)ver;
    return 0;
}

/* Finds the shape's bytes [*begin, *end) through the dictionary at the end of
 * the file. The dictionary's width follows the first shape's version. */
static int locate(ser_ctx *c, uint64_t *begin, uint64_t *end)
{
    unsigned char b[8];
    int rc;
    if (c->fsize < 8)
        return file_fail(c, "too small for a serialized mesh (%" PRIu64 " bytes)", c->fsize);
    if ((rc = read_at(c, 0, b, 4)) || (rc = check_file_header(c, b)))
        return rc;
    if ((rc = read_at(c, c->fsize - 4, b, 4)))
        return rc;
    uint32_t count = le32(b);
    unsigned esz = c->version == 4 ? 8 : 4;
    if (count == 0)
        return file_fail(c, "the dictionary at the end of the file lists no shapes");
    uint64_t dict = (uint64_t)count * esz + 4;
    if (dict > c->fsize - 4)
        return file_fail(c,
                         "the dictionary at the end of the file claims %" PRIu32 " shapes, whose %" PRIu64
                         "-byte offset table does not fit in the %" PRIu64 "-byte file",
                         count, dict - 4, c->fsize);
    uint64_t dict_start = c->fsize - dict;
    if (c->shape >= count)
        return file_fail(
            c, "shape index %" PRIu32 " out of range: the file holds %" PRIu32 " shape%s (0..%" PRIu32 ")",
            c->shape, count, count == 1 ? "" : "s", count - 1);

    uint64_t off[3] = {0, 0, 0}; /* shape 0, this shape, the next one */
    uint32_t which[3] = {0, c->shape, c->shape + 1};
    for (int k = 0; k < 3; k++) {
        if (which[k] >= count)
            break;
        if ((rc = read_at(c, dict_start + (uint64_t)which[k] * esz, b, esz)))
            return rc;
        off[k] = esz == 8 ? le64(b) : le32(b);
    }
    /* The first shape starts the file; anything else here means a damaged
     * dictionary or offsets of the wrong width, and every offset is suspect. */
    if (off[0] != 0)
        return file_fail(
            c, "the dictionary gives shape 0 the offset %" PRIu64 ", not 0 (a damaged dictionary?)", off[0]);
    c->next_is_dict = c->shape + 1 >= count;
    *begin = off[1];
    *end = c->next_is_dict ? dict_start : off[2];
    if (*begin >= dict_start)
        return shape_fail(c,
                          "its dictionary offset %" PRIu64
                          " is outside the shape data (the file's first %" PRIu64 " bytes)",
                          *begin, dict_start);
    if (*end > dict_start)
        return file_fail(c,
                         "shape %" PRIu32 ": its dictionary offset %" PRIu64
                         " is outside the shape data (the file's first %" PRIu64 " bytes)",
                         c->shape + 1, *end, dict_start);
    if (*end <= *begin + 4)
        return shape_fail(c,
                          "the dictionary offsets of shapes %" PRIu32 " and %" PRIu32 " (%" PRIu64
                          ", %" PRIu64 ") leave no room for its data",
                          c->shape, c->shape + 1, *begin, *end);
    return 0;
}

/* ---- the compressed stream ----------------------------------------------------------------- */

static int zfail(ser_ctx *c, int zrc)
{
    switch (zrc) {
    case Z_MEM_ERROR:
        return oom(c);
    case Z_BUF_ERROR: /* no progress possible: the input ran out before the end marker */
        if (c->need)
            return shape_fail(c,
                              "truncated: the compressed stream breaks off before its end, after %" PRIu64
                              " of %" PRIu64 " bytes",
                              c->out, c->need);
        return shape_fail(c,
                          "truncated: the compressed stream breaks off before its end, after %" PRIu64
                          " bytes, in the header",
                          c->out);
    case Z_NEED_DICT:
        return shape_fail(c, "corrupt compressed data (it asks for a preset dictionary)");
    case Z_DATA_ERROR:
        return shape_fail(c, "corrupt compressed data after %" PRIu64 " bytes (zlib: %s)", c->out,
                          c->z.msg ? c->z.msg : "invalid data");
    default:
        return shape_fail(c, "zlib error %d after %" PRIu64 " bytes", zrc, c->out);
    }
}

static void refill(ser_ctx *c)
{
    if (c->z.avail_in == 0 && c->in_left > 0) {
        uInt k = c->in_left > UINT_MAX ? UINT_MAX : (uInt)c->in_left;
        c->z.next_in = c->in;
        c->z.avail_in = k;
        c->in += k;
        c->in_left -= k;
    }
}

/* Exactly n decompressed bytes into dst: a stream that ends first is
 * short of what its counts promise. */
static int zread(ser_ctx *c, void *dst, size_t n)
{
    unsigned char *p = dst;
    while (n > 0) {
        if (c->z_end) {
            if (c->need)
                return shape_fail(
                    c, "truncated: the data ends after %" PRIu64 " bytes, its counts need %" PRIu64, c->out,
                    c->need);
            return shape_fail(c, "truncated: the data ends after %" PRIu64 " bytes, in the header", c->out);
        }
        refill(c);
        uInt chunk = n > UINT_MAX ? UINT_MAX : (uInt)n;
        c->z.next_out = p;
        c->z.avail_out = chunk;
        int zrc = inflate(&c->z, Z_NO_FLUSH);
        size_t got = chunk - c->z.avail_out;
        p += got;
        n -= got;
        c->out += got;
        if (zrc == Z_STREAM_END)
            c->z_end = 1;
        else if (zrc != Z_OK)
            return zfail(c, zrc);
    }
    return 0;
}

/* After the last index: the stream must end there (its checksum checked by
 * zlib), and the next shape or the dictionary must follow at once. */
static int finish(ser_ctx *c)
{
    while (!c->z_end) {
        unsigned char extra;
        refill(c);
        c->z.next_out = &extra;
        c->z.avail_out = 1;
        int zrc = inflate(&c->z, Z_NO_FLUSH);
        if (c->z.avail_out == 0)
            return shape_fail(c, "the data is longer than its counts say (more than %" PRIu64 " bytes)",
                              c->need);
        if (zrc == Z_STREAM_END)
            c->z_end = 1;
        else if (zrc != Z_OK)
            return zfail(c, zrc);
    }
    uint64_t rest = c->z.avail_in + c->in_left;
    if (rest)
        return shape_fail(c, "%" PRIu64 " stray bytes between the end of its compressed stream and the %s",
                          rest, c->next_is_dict ? "dictionary" : "next shape");
    return 0;
}

/* ---- the mesh ------------------------------------------------------------------------------ */

/* Value i (of dim per vertex) of an attribute, as read from the file. */
static int check_value(ser_ctx *c, int kind, uint64_t i, unsigned dim, double d, float *out)
{
    static const char axes[2][4] = {"xyz", "uv"};
    char comp = axes[dim == 2][i % dim];
    uint64_t v = i / dim;
    if (kind == K_POS) {
        if (!isfinite(d))
            return shape_fail(c, "vertex %" PRIu64 ": position %c is not finite (%g)", v, comp, d);
        if (fabs(d) > CDL_MAX_COORD)
            return shape_fail(c, "vertex %" PRIu64 ": position %c = %g is out of range (|x| > 1e20)", v, comp,
                              d);
        *out = (float)d;
        return 0;
    }
    float f = (float)d;
    if (!isfinite(f)) /* a finite double may still overflow the float */
        return shape_fail(c, "vertex %" PRIu64 ": %s %c is not a finite float (%g)", v, kind_name[kind], comp,
                          d);
    *out = f;
    return 0;
}

/* nverts * dim values of one attribute into dst (NULL: read past them). */
static int read_attr(ser_ctx *c, float *dst, uint32_t nverts, unsigned dim, int dbl, int kind)
{
    uint64_t n = (uint64_t)nverts * dim;
    int rc;
    if (dst && !dbl) { /* floats decompress in place; the loop fixes byte order and checks them */
        unsigned char *raw = (unsigned char *)dst;
        if ((rc = zread(c, raw, (size_t)n * 4)))
            return rc;
        for (uint64_t i = 0; i < n; i++)
            if ((rc = check_value(c, kind, i, dim, le_float(raw + 4 * i), &dst[i])))
                return rc;
        return 0;
    }
    unsigned char tmp[SER_CHUNK];
    unsigned vsz = dbl ? 8 : 4;
    for (uint64_t i = 0; i < n;) {
        size_t k = (size_t)(n - i < SER_CHUNK / vsz ? n - i : SER_CHUNK / vsz);
        if ((rc = zread(c, tmp, k * vsz)))
            return rc;
        if (dst)
            for (size_t j = 0; j < k; j++)
                if ((rc = check_value(c, kind, i + j, dim, le_double(tmp + 8 * j), &dst[i + j])))
                    return rc;
        i += k;
    }
    return 0;
}

static int read_indices(ser_ctx *c)
{
    uint64_t n = (uint64_t)c->m.ntris * 3;
    unsigned char *raw = (unsigned char *)c->m.idx;
    int rc = zread(c, raw, (size_t)n * 4);
    if (rc)
        return rc;
    for (uint64_t i = 0; i < n; i++) {
        uint32_t v = le32(raw + 4 * i);
        if (v >= c->m.nverts)
            return shape_fail(
                c, "triangle %" PRIu64 ": vertex index %" PRIu32 " out of range (%" PRIu32 " vertices)",
                i / 3, v, c->m.nverts);
        c->m.idx[i] = v;
    }
    return 0;
}

/* Skips the NUL-terminated name of a version 4 shape. */
static int skip_name(ser_ctx *c)
{
    for (uint32_t len = 0; len <= SER_MAX_NAME; len++) {
        unsigned char ch;
        int rc = zread(c, &ch, 1);
        if (rc)
            return rc;
        if (ch == 0)
            return 0;
    }
    return shape_fail(c, "the shape name is longer than %u bytes (no terminating NUL?)", SER_MAX_NAME);
}

static int check_flags(ser_ctx *c, uint32_t flags)
{
    if (flags & ~(uint32_t)F_KNOWN) /* Mitsuba reads past bits it does not know */
        cdl_warn(c->path, 0, "shape %" PRIu32 ": unknown flags 0x%" PRIx32 " (flags 0x%" PRIx32 ") ignored", c->shape,
                 flags & ~(uint32_t)F_KNOWN, flags);
    if ((flags & F_SINGLE) && (flags & F_DOUBLE))
        return shape_fail(c, "flags 0x%" PRIx32 " mark the data both single and double precision", flags);
    return 0;
}

static int read_mesh(ser_ctx *c, uint64_t comp_bytes)
{
    unsigned char b[16];
    int rc;
    if ((rc = zread(c, b, 4)) || (rc = check_flags(c, le32(b))))
        return rc;
    uint32_t flags = le32(b);
    /* Mitsuba reads data flagged neither single nor double as single. */
    int dbl = (flags & F_DOUBLE) != 0;
    if (c->version == 4 && (rc = skip_name(c)))
        return rc;
    if ((rc = zread(c, b, 16)))
        return rc;
    uint64_t nv = le64(b), nt = le64(b + 8);
    /* The limit also keeps indices uint32: the format widens them to uint64
     * only past 2^32 - 1 vertices. */
    if (nv > SER_MAX_COUNT)
        return shape_fail(c, "vertex count %" PRIu64 " exceeds the limit of %u", nv, SER_MAX_COUNT);
    if (nt > SER_MAX_COUNT)
        return shape_fail(c, "triangle count %" PRIu64 " exceeds the limit of %u", nt, SER_MAX_COUNT);
    if (nt == 0)
        return shape_fail(c, "no triangles (%" PRIu64 " vertices)", nv);
    if (nv == 0)
        return shape_fail(c, "%" PRIu64 " triangles but no vertices", nt);

    unsigned per_vertex =
        3u + (flags & F_NORMALS ? 3u : 0u) + (flags & F_UV ? 2u : 0u) + (flags & F_COLORS ? 3u : 0u);
    uint64_t body = nv * per_vertex * (dbl ? 8 : 4) + nt * 12; /* < 2^35 under the limits */
    c->need = c->out + body;
    if (body > comp_bytes * SER_MAX_RATIO)
        return shape_fail(c,
                          "%" PRIu64 " compressed bytes cannot hold the %" PRIu64 " bytes of %" PRIu64
                          " vertices and %" PRIu64 " triangles (truncated?)",
                          comp_bytes, c->need, nv, nt);
    if (nv * 3 * sizeof(float) > SIZE_MAX || nt * 3 * sizeof(uint32_t) > SIZE_MAX)
        return oom(c);

    c->m.nverts = (uint32_t)nv;
    c->m.ntris = (uint32_t)nt;
    size_t nvs = (size_t)nv, nts = (size_t)nt;
    if (!(c->m.pos = malloc(nvs * 3 * sizeof(float))) ||
        ((flags & F_NORMALS) && !(c->m.nrm = malloc(nvs * 3 * sizeof(float)))) ||
        ((flags & F_UV) && !(c->m.uv = malloc(nvs * 2 * sizeof(float)))) ||
        !(c->m.idx = malloc(nts * 3 * sizeof(uint32_t))))
        return oom(c);
    if ((rc = read_attr(c, c->m.pos, c->m.nverts, 3, dbl, K_POS)))
        return rc;
    if ((flags & F_NORMALS) && (rc = read_attr(c, c->m.nrm, c->m.nverts, 3, dbl, K_NRM)))
        return rc;
    if ((flags & F_UV) && (rc = read_attr(c, c->m.uv, c->m.nverts, 2, dbl, K_UV)))
        return rc;
    if ((flags & F_COLORS) && (rc = read_attr(c, NULL, c->m.nverts, 3, dbl, K_SKIP)))
        return rc;
    if ((rc = read_indices(c)))
        return rc;
    return finish(c);
}

static int read_shape(ser_ctx *c)
{
    uint64_t begin = 0, end = 0;
    int rc;
    if ((rc = open_file(c)) || (rc = locate(c, &begin, &end)))
        return rc;
    uint64_t len = end - begin;
    if (len > SIZE_MAX || !(c->comp = malloc((size_t)len)))
        return oom(c);
    if ((rc = read_at(c, begin, c->comp, (size_t)len)))
        return rc;
    /* Every shape repeats the header; a mismatch means a wrong offset. */
    uint32_t id = le16(c->comp), ver = le16(c->comp + 2);
    if (id != SER_ID)
        return shape_fail(c,
                          "no shape header at its dictionary offset %" PRIu64 " (found 0x%04" PRIx32
                          " instead of 0x041c)",
                          begin, id);
    if (ver != (uint32_t)c->version)
        return shape_fail(c, "version %" PRIu32 " differs from the file's version %d", ver, c->version);

    c->in = c->comp + 4;
    c->in_left = len - 4;
    int zrc = inflateInit(&c->z);
    if (zrc != Z_OK)
        return zrc == Z_MEM_ERROR ? oom(c) : shape_fail(c, "zlib initialisation failed (%d)", zrc);
    c->z_live = 1;
    return read_mesh(c, len - 4);
}

int cdl_serialized_read(const char *path, uint32_t shape_index, cdl_serialized_mesh *m, cdl_error *err)
{
    memset(m, 0, sizeof *m);
    ser_ctx c;
    memset(&c, 0, sizeof c);
    c.path = path;
    c.err = err;
    c.shape = shape_index;
    c.fd = -1;
    int rc = read_shape(&c);
    if (c.z_live)
        inflateEnd(&c.z);
    if (c.fd >= 0)
        close(c.fd);
    free(c.comp);
    if (rc)
        cdl_serialized_free(&c.m);
    else
        *m = c.m;
    return rc;
}
