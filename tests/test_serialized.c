/* Mitsuba .serialized reader: files written here with zlib (versions 3 and 4,
 * float and double, with and without normals, uvs and colors, several shapes
 * in one file, a large mesh) read back exactly; every kind of malformation is
 * an error naming the file and the problem, with the mesh left zeroed; and
 * the Sponza file's 37 shapes read with plausible counts.
 * Usage: test_serialized [SPONZA.serialized]   (skipped when not given or absent) */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include "io/serialized.h"
#include "test_util.h"

/* ---- a growable byte buffer ----------------------------------------------------------------- */

typedef struct buf {
    unsigned char *d;
    size_t n, cap;
} buf;

static void put(buf *b, const void *p, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 256;
        b->d = realloc(b->d, b->cap);
        if (!b->d) {
            fprintf(stderr, "out of memory\n");
            exit(2);
        }
    }
    if (n)
        memcpy(b->d + b->n, p, n);
    b->n += n;
}

static void put_le(buf *b, uint64_t v, int size)
{
    unsigned char t[8];
    for (int i = 0; i < size; i++)
        t[i] = (unsigned char)(v >> (8 * i));
    put(b, t, (size_t)size);
}

static void put_real(buf *b, int dbl, double v)
{
    if (dbl) {
        uint64_t u;
        memcpy(&u, &v, 8);
        put_le(b, u, 8);
    } else {
        float f = (float)v;
        uint32_t u;
        memcpy(&u, &f, 4);
        put_le(b, u, 4);
    }
}

static void set_real(buf *b, size_t at, int dbl, double v)
{
    buf t = {0};
    put_real(&t, dbl, v);
    memcpy(b->d + at, t.d, t.n);
    free(t.d);
}

static void set_le(buf *b, size_t at, uint64_t v, int size)
{
    for (int i = 0; i < size; i++)
        b->d[at + (size_t)i] = (unsigned char)(v >> (8 * i));
}

/* ---- test meshes and the writer ------------------------------------------------------------- */

typedef struct tmesh {
    uint32_t nv, nt;
    float *pos, *nrm, *uv, *col;
    uint32_t *idx;
} tmesh;

/* n*n vertices on a bumpy grid, 2(n-1)^2 triangles; every value exact in float. */
static tmesh grid(uint32_t n, float shift)
{
    tmesh t = {n * n, 2 * (n - 1) * (n - 1), NULL, NULL, NULL, NULL, NULL};
    t.pos = malloc(sizeof(float) * 3 * t.nv);
    t.nrm = malloc(sizeof(float) * 3 * t.nv);
    t.uv = malloc(sizeof(float) * 2 * t.nv);
    t.col = malloc(sizeof(float) * 3 * t.nv);
    t.idx = malloc(sizeof(uint32_t) * 3 * t.nt);
    if (!t.pos || !t.nrm || !t.uv || !t.col || !t.idx)
        exit(2);
    for (uint32_t y = 0; y < n; y++)
        for (uint32_t x = 0; x < n; x++) {
            uint32_t i = y * n + x;
            t.pos[3 * i] = (float)x * 0.5f - shift;
            t.pos[3 * i + 1] = (float)((x * 7 + y * 3) % 11) * 0.125f;
            t.pos[3 * i + 2] = -(float)y * 0.25f + shift;
            t.nrm[3 * i] = (i % 3 == 0) ? 1.0f : 0.0f;
            t.nrm[3 * i + 1] = (i % 3 == 1) ? -1.0f : 0.0f;
            t.nrm[3 * i + 2] = (i % 3 == 2) ? 1.0f : 0.0f;
            t.uv[2 * i] = (float)x / 64.0f;
            t.uv[2 * i + 1] = 1.0f - (float)y / 128.0f;
            t.col[3 * i] = t.col[3 * i + 1] = t.col[3 * i + 2] = 0.5f;
        }
    uint32_t k = 0;
    for (uint32_t y = 0; y + 1 < n; y++)
        for (uint32_t x = 0; x + 1 < n; x++) {
            uint32_t a = y * n + x, b = a + 1, c = a + n, d = c + 1;
            uint32_t tri[6] = {a, b, d, a, d, c};
            memcpy(t.idx + 3 * k, tri, sizeof tri);
            k += 2;
        }
    return t;
}

static void tmesh_free(tmesh *t)
{
    free(t->pos);
    free(t->nrm);
    free(t->uv);
    free(t->col);
    free(t->idx);
}

typedef struct wopt {
    int version; /* 3 or 4 */
    int dbl;     /* doubles (else floats) */
    int normals, uv, colors;
    const char *name; /* version 4 shape name ("" when NULL) */
    uint32_t flags;   /* replaces the computed flags when nonzero */
    int no_precision; /* neither the single nor the double flag */
} wopt;

static uint32_t flags_of(const wopt *o)
{
    if (o->flags)
        return o->flags;
    uint32_t f = o->no_precision ? 0 : o->dbl ? 0x2000 : 0x1000;
    return f | (o->normals ? 1u : 0) | (o->uv ? 2u : 0) | (o->colors ? 8u : 0);
}

/* Where the positions start in the decompressed data. */
static size_t pos_at(const wopt *o)
{
    return 4 + (o->version == 4 ? strlen(o->name ? o->name : "") + 1 : 0) + 16;
}

static void payload(buf *p, const tmesh *t, const wopt *o)
{
    put_le(p, flags_of(o), 4);
    if (o->version == 4) {
        const char *nm = o->name ? o->name : "";
        put(p, nm, strlen(nm) + 1);
    }
    put_le(p, t->nv, 8);
    put_le(p, t->nt, 8);
    for (uint32_t i = 0; i < 3 * t->nv; i++)
        put_real(p, o->dbl, t->pos[i]);
    if (o->normals)
        for (uint32_t i = 0; i < 3 * t->nv; i++)
            put_real(p, o->dbl, t->nrm[i]);
    if (o->uv)
        for (uint32_t i = 0; i < 2 * t->nv; i++)
            put_real(p, o->dbl, t->uv[i]);
    if (o->colors)
        for (uint32_t i = 0; i < 3 * t->nv; i++)
            put_real(p, o->dbl, t->col[i]);
    for (uint32_t i = 0; i < 3 * t->nt; i++)
        put_le(p, t->idx[i], 4);
}

/* The 4-byte header and the zlib stream of the payload. */
static void put_shape(buf *f, int version, const buf *p)
{
    put_le(f, 0x041C, 2);
    put_le(f, (uint64_t)version, 2);
    uLongf n = compressBound((uLong)p->n);
    unsigned char *z = malloc(n);
    if (!z || compress(z, &n, p->n ? p->d : (const Bytef *)"", (uLong)p->n) != Z_OK) {
        fprintf(stderr, "compress failed\n");
        exit(2);
    }
    put(f, z, n);
    free(z);
}

static void put_dict(buf *f, int version, const uint64_t *off, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++)
        put_le(f, off[i], version == 4 ? 8 : 4);
    put_le(f, n, 4);
}

/* A file of one shape from a payload. */
static void file_of(buf *f, int version, const buf *p)
{
    uint64_t off = 0;
    put_shape(f, version, p);
    put_dict(f, version, &off, 1);
}

/* ---- checks --------------------------------------------------------------------------------- */

static char tmpdir[256];

static void write_file(const char *path, const void *d, size_t n)
{
    test_write(NULL, path, d, n);
}

static void print_err(int rc, const cdl_error *err)
{
    if (rc) {
        char msg[2048];
        cdl_error_format(err, msg, sizeof msg);
        printf("      error: %s\n", msg);
    }
}

static int same_floats(const float *a, const float *b, size_t n)
{
    return a && b && !memcmp(a, b, n * sizeof(float));
}

static int mesh_matches(const cdl_serialized_mesh *m, const tmesh *t, int normals, int uv)
{
    return m->nverts == t->nv && m->ntris == t->nt && same_floats(m->pos, t->pos, 3 * (size_t)t->nv) &&
           (normals ? same_floats(m->nrm, t->nrm, 3 * (size_t)t->nv) : !m->nrm) &&
           (uv ? same_floats(m->uv, t->uv, 2 * (size_t)t->nv) : !m->uv) && m->idx &&
           !memcmp(m->idx, t->idx, 3 * (size_t)t->nt * sizeof(uint32_t));
}

static int is_zeroed(const cdl_serialized_mesh *m)
{
    return !m->pos && !m->nrm && !m->uv && !m->idx && !m->nverts && !m->ntris;
}

/* Writes b to tmpdir/name, reads shape `shape` and expects an input error
 * naming the file whose message contains want. */
static void expect_error(const char *name, const buf *b, uint32_t shape, const char *want)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    write_file(path, b->d, b->n);
    cdl_serialized_mesh m;
    memset(&m, 0x5a, sizeof m); /* the reader must zero it */
    cdl_error err;
    memset(&err, 0, sizeof err);
    int rc = cdl_serialized_read(path, shape, &m, &err);
    int ok = rc == CDL_ERR_INPUT && strstr(err.msg, want) && !strcmp(err.file, path) && is_zeroed(&m);
    CHECK(ok, "%s (shape %u): \"%s\"", name, shape, err.msg);
    if (!ok)
        printf("      wanted \"%s\", rc %d\n", want, rc);
    if (!rc)
        cdl_serialized_free(&m);
}

/* Round trip of one shape written with o. */
static void roundtrip(const char *name, const tmesh *t, const wopt *o)
{
    buf p = {0}, f = {0};
    payload(&p, t, o);
    file_of(&f, o->version, &p);
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    write_file(path, f.d, f.n);
    cdl_serialized_mesh m;
    cdl_error err;
    int rc = cdl_serialized_read(path, 0, &m, &err);
    print_err(rc, &err);
    CHECK(!rc && mesh_matches(&m, t, o->normals, o->uv),
          "%s: version %d, %s, normals %s, uv %s, colors %s%s: %u vertices, %u triangles exact (%zu bytes)",
          name, o->version,
          o->dbl            ? "double"
          : o->no_precision ? "no precision flag"
                            : "float",
          o->normals ? "yes" : "no", o->uv ? "yes" : "no", o->colors ? "skipped" : "no",
          o->flags ? " (extra flags)" : "", m.nverts, m.ntris, f.n);
    cdl_serialized_free(&m);
    CHECK(is_zeroed(&m), "%s: cdl_serialized_free zeroes the mesh", name);
    free(p.d);
    free(f.d);
}

static void cleanup(void)
{
    DIR *d = opendir(tmpdir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        char path[600];
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%s", tmpdir, e->d_name);
        if (rmdir(path) != 0)
            unlink(path);
    }
    closedir(d);
    rmdir(tmpdir);
}

/* ---- the Sponza file ------------------------------------------------------------------------ */

static void sponza(const char *path)
{
    struct stat st;
    if (!path || stat(path, &st) != 0) {
        printf("skip: Sponza file %s not found\n", path ? path : "(not given)");
        return;
    }
    uint64_t tv = 0, tt = 0;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t n = 0, with_nrm = 0, with_uv = 0, bad = 0;
    cdl_error err;
    int rc;
    for (;; n++) {
        cdl_serialized_mesh m;
        if ((rc = cdl_serialized_read(path, n, &m, &err)))
            break;
        printf("      shape %2u: %5u vertices, %5u triangles%s%s\n", n, m.nverts, m.ntris,
               m.nrm ? ", normals" : "", m.uv ? ", uv" : "");
        tv += m.nverts;
        tt += m.ntris;
        with_nrm += m.nrm != NULL;
        with_uv += m.uv != NULL;
        for (uint32_t i = 0; i < m.nverts; i++) {
            for (int k = 0; k < 3; k++) {
                lo[k] = fminf(lo[k], m.pos[3 * i + (uint32_t)k]);
                hi[k] = fmaxf(hi[k], m.pos[3 * i + (uint32_t)k]);
            }
            if (m.nrm) {
                const float *nn = m.nrm + 3 * (size_t)i;
                bad += fabsf(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] - 1.0f) > 1e-2f;
            }
        }
        cdl_serialized_free(&m);
    }
    CHECK(n == 37 && strstr(err.msg, "shape index 37 out of range: the file holds 37 shapes (0..36)"),
          "Sponza: %u shapes, then \"%s\"", n, err.msg);
    CHECK(tv == 66350 && tt == 66445, "Sponza: %llu vertices, %llu triangles in all (66350, 66445)",
          (unsigned long long)tv, (unsigned long long)tt);
    CHECK(with_nrm == n && with_uv == n && bad == 0,
          "Sponza: every shape has normals (%u unit-length off) and uvs", bad);
    CHECK(fabsf(lo[0] + 17.41f) < 1e-3f && fabsf(hi[0] - 17.41f) < 1e-3f && fabsf(lo[1] + 1.0f) < 1e-3f &&
              fabsf(hi[1] - 15.56f) < 1e-3f && fabsf(lo[2] + 7.8f) < 1e-3f && fabsf(hi[2] - 7.8f) < 1e-3f,
          "Sponza: bounds (%g %g %g) .. (%g %g %g)", lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
}

/* ---- malformations -------------------------------------------------------------------------- */

static void errors(const tmesh *t, const tmesh *t2)
{
    const wopt o3 = {.version = 3, .normals = 1, .uv = 1};
    const wopt o4d = {.version = 4, .dbl = 1, .normals = 1, .uv = 1, .name = "mesh"};
    buf p = {0}, f = {0};
#define RESET() (p.n = 0, f.n = 0)

    /* the header and the dictionary */
    RESET();
    expect_error("e_empty.serialized", &f, 0, "too small for a serialized mesh (0 bytes)");
    payload(&p, t, &o3);
    file_of(&f, 3, &p);
    set_le(&f, 0, 0x1234, 2);
    expect_error("e_id.serialized", &f, 0,
                 "not a Mitsuba serialized mesh: format id 0x1234 (expected 0x041c)");
    set_le(&f, 0, 0x1C04, 2);
    expect_error("e_old.serialized", &f, 0, "big-endian: a mesh from Mitsuba before 0.4");
    set_le(&f, 0, 0x041C, 2);
    set_le(&f, 2, 5, 2);
    expect_error("e_version.serialized", &f, 0, "unsupported version 5 (this reader knows versions 3 and 4)");
    set_le(&f, 2, 3, 2);
    set_le(&f, f.n - 4, 0, 4);
    expect_error("e_count0.serialized", &f, 0, "the dictionary at the end of the file lists no shapes");
    set_le(&f, f.n - 4, 100000, 4);
    expect_error("e_count_big.serialized", &f, 0,
                 "claims 100000 shapes, whose 400000-byte offset table does not fit");
    set_le(&f, f.n - 4, 1, 4);
    expect_error("e_index.serialized", &f, 1, "shape index 1 out of range: the file holds 1 shape (0..0)");
    set_le(&f, f.n - 8, 8, 4);
    expect_error("e_offset0.serialized", &f, 0, "gives shape 0 the offset 8, not 0");

    /* two shapes: offsets past the end, not at a header, the stream overrunning the next shape */
    {
        RESET();
        buf p2 = {0};
        payload(&p, t, &o4d);
        payload(&p2, t2, &o4d);
        put_shape(&f, 4, &p);
        uint64_t off[2] = {0, f.n};
        put_shape(&f, 4, &p2);
        size_t data_end = f.n;
        put_dict(&f, 4, off, 2);
        expect_error("e_index2.serialized", &f, 2,
                     "shape index 2 out of range: the file holds 2 shapes (0..1)");
        set_le(&f, data_end + 8, data_end + 1000, 8);
        char want[160];
        snprintf(want, sizeof want,
                 "shape 1: its dictionary offset %zu is outside the shape data (the file's first %zu bytes)",
                 data_end + 1000, data_end);
        expect_error("e_past1.serialized", &f, 1, want);
        expect_error("e_past0.serialized", &f, 0, want); /* shape 0 ends where shape 1 starts */
        set_le(&f, data_end + 8, data_end, 8);
        expect_error("e_past_dict.serialized", &f, 1, "is outside the shape data");
        set_le(&f, data_end + 8, off[1] - 3, 8);
        expect_error("e_not_header.serialized", &f, 1, "shape 1: no shape header at its dictionary offset");
        expect_error("e_overrun.serialized", &f, 0,
                     "shape 0: truncated: the compressed stream breaks off before its end");
        set_le(&f, data_end + 8, 2, 8);
        expect_error("e_no_room.serialized", &f, 0, "leave no room for its data");
        set_le(&f, data_end + 8, off[1], 8);
        set_le(&f, off[1] + 2, 3, 2);
        expect_error("e_mixed_version.serialized", &f, 1,
                     "shape 1: version 3 differs from the file's version 4");
        free(p2.d);
    }

    /* the compressed stream */
    RESET();
    payload(&p, t, &o3);
    put_shape(&f, 3, &p);
    {
        size_t zend = f.n;
        buf g = {0};
        uint64_t off = 0;
        put(&g, f.d, zend - 10); /* the last 10 compressed bytes missing */
        put_dict(&g, 3, &off, 1);
        expect_error("e_zcut.serialized", &g, 0,
                     "shape 0: truncated: the compressed stream breaks off before its end, after");
        g.n = 0;
        put(&g, f.d, zend);
        put(&g, "junk", 4);
        put_dict(&g, 3, &off, 1);
        expect_error("e_stray.serialized", &g, 0,
                     "4 stray bytes between the end of its compressed stream and the dictionary");
        g.n = 0;
        put(&g, f.d, zend);
        g.d[6] = 0xff; /* first deflate block: BTYPE 3 is invalid */
        put_dict(&g, 3, &off, 1);
        expect_error("e_zcorrupt.serialized", &g, 0,
                     "corrupt compressed data after 0 bytes (zlib: invalid block type)");
        g.n = 0;
        put(&g, f.d, zend);
        g.d[zend - 1] ^= 0x55; /* the Adler-32 checksum */
        put_dict(&g, 3, &off, 1);
        expect_error("e_zcheck.serialized", &g, 0, "corrupt compressed data");
        g.n = 0;
        put(&g, f.d, 4);
        put(&g, "\x78\x9c", 2); /* a zlib header and nothing else */
        put_dict(&g, 3, &off, 1);
        expect_error(
            "e_zheader_only.serialized", &g, 0,
            "truncated: the compressed stream breaks off before its end, after 0 bytes, in the header");
        free(g.d);
    }

    /* the decompressed data against its counts */
    RESET();
    payload(&p, t, &o3);
    p.n -= 4;
    file_of(&f, 3, &p);
    expect_error("e_short.serialized", &f, 0, "shape 0: truncated: the data ends after");
    RESET();
    payload(&p, t, &o3);
    put(&p, "\0\0\0\0", 4);
    file_of(&f, 3, &p);
    expect_error("e_long.serialized", &f, 0, "shape 0: the data is longer than its counts say");
    RESET();
    payload(&p, t, &o4d);
    p.n = 6; /* flags and two bytes of the name */
    file_of(&f, 4, &p);
    expect_error("e_name_cut.serialized", &f, 0, "truncated: the data ends after 6 bytes, in the header");
    RESET();
    put_le(&p, 0x1000, 4);
    for (int i = 0; i < 70000; i++)
        put(&p, "n", 1);
    file_of(&f, 4, &p);
    expect_error("e_name_long.serialized", &f, 0, "the shape name is longer than 65536 bytes");

    /* counts */
    static const struct {
        const char *name;
        uint64_t nv, nt;
        const char *want;
    } counts[] = {
        {"e_nv_huge.serialized", UINT64_MAX, 4,
         "vertex count 18446744073709551615 exceeds the limit of 268435456"},
        {"e_nt_huge.serialized", 5, (uint64_t)1 << 61,
         "triangle count 2305843009213693952 exceeds the limit"},
        {"e_nv_limit.serialized", 268435457, 4, "vertex count 268435457 exceeds"},
        {"e_nv_max.serialized", 268435456, 4, "compressed bytes cannot hold the"},
        {"e_nt_max.serialized", 5, 268435456, "cannot hold the"},
        {"e_nt0.serialized", 5, 0, "shape 0: no triangles (5 vertices)"},
        {"e_nv0.serialized", 0, 4, "4 triangles but no vertices"},
    };
    for (size_t k = 0; k < sizeof counts / sizeof counts[0]; k++) {
        RESET();
        payload(&p, t, &o3);
        set_le(&p, 4, counts[k].nv, 8);
        set_le(&p, 12, counts[k].nt, 8);
        file_of(&f, 3, &p);
        expect_error(counts[k].name, &f, 0, counts[k].want);
    }

    /* flags */
    wopt of = o3;
    of.flags = 0x3003;
    RESET();
    payload(&p, t, &of);
    file_of(&f, 3, &p);
    expect_error("e_both.serialized", &f, 0, "flags 0x3003 mark the data both single and double precision");

    /* values */
    size_t pa = pos_at(&o3), pd = pos_at(&o4d);
    RESET();
    payload(&p, t, &o3);
    set_le(&p, p.n - 4 * 4, t->nv, 4); /* triangle nt-2's last index */
    file_of(&f, 3, &p);
    char want[128];
    snprintf(want, sizeof want, "triangle %u: vertex index %u out of range (%u vertices)", t->nt - 2, t->nv,
             t->nv);
    expect_error("e_idx.serialized", &f, 0, want);
    RESET();
    payload(&p, t, &o3);
    set_real(&p, pa + 4 * 4, 0, NAN);
    file_of(&f, 3, &p);
    expect_error("e_nan.serialized", &f, 0, "shape 0: vertex 1: position y is not finite (nan)");
    RESET();
    payload(&p, t, &o3);
    set_real(&p, pa + 4 * 5, 0, 1e30);
    file_of(&f, 3, &p);
    expect_error("e_far.serialized", &f, 0, "vertex 1: position z = 1e+30 is out of range (|x| > 1e20)");
    RESET();
    payload(&p, t, &o4d);
    set_real(&p, pd + 8 * 6, 1, -INFINITY);
    file_of(&f, 4, &p);
    expect_error("e_inf_d.serialized", &f, 0, "vertex 2: position x is not finite (-inf)");
    RESET();
    payload(&p, t, &o4d);
    set_real(&p, pd + 8 * 3, 1, 1e300);
    file_of(&f, 4, &p);
    expect_error("e_far_d.serialized", &f, 0, "vertex 1: position x = 1e+300 is out of range");
    RESET();
    payload(&p, t, &o3);
    set_real(&p, pa + 4 * (3 * t->nv + 3 * 3 + 2), 0, NAN);
    file_of(&f, 3, &p);
    expect_error("e_nrm_nan.serialized", &f, 0, "vertex 3: normal z is not a finite float (nan)");
    RESET();
    payload(&p, t, &o3);
    set_real(&p, pa + 4 * (6 * t->nv + 2 * 4 + 1), 0, INFINITY);
    file_of(&f, 3, &p);
    expect_error("e_uv_inf.serialized", &f, 0, "vertex 4: texture coordinate v is not a finite float (inf)");
    RESET();
    payload(&p, t, &o4d);
    set_real(&p, pd + 8 * (6 * t->nv), 1, 1e300);
    file_of(&f, 4, &p);
    expect_error("e_uv_big_d.serialized", &f, 0,
                 "vertex 0: texture coordinate u is not a finite float (1e+300)");

    /* the file itself */
    {
        char path[512];
        snprintf(path, sizeof path, "%s/adir.serialized", tmpdir);
        mkdir(path, 0755);
        cdl_serialized_mesh m;
        cdl_error err;
        int rc = cdl_serialized_read(path, 0, &m, &err);
        CHECK(rc == CDL_ERR_INPUT && strstr(err.msg, "is a directory") && is_zeroed(&m),
              "a directory: \"%s\"", err.msg);
        snprintf(path, sizeof path, "%s/missing.serialized", tmpdir);
        rc = cdl_serialized_read(path, 0, &m, &err);
        CHECK(rc == CDL_ERR_INPUT && strstr(err.msg, "cannot open: No such file") && is_zeroed(&m),
              "a missing file: \"%s\"", err.msg);
        rc = cdl_serialized_read(path, 0, &m, NULL);
        CHECK(rc == CDL_ERR_INPUT, "a NULL cdl_error is allowed");
    }
#undef RESET
    free(p.d);
    free(f.d);
}

int main(int argc, char **argv)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/candela-serialized.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 2;
    }
    tmesh t = grid(3, 0.0f), t2 = grid(2, 3.5f);

    /* one shape: versions, precisions and attributes */
    roundtrip("v3_float_nrm_uv.serialized", &t, &(wopt){.version = 3, .normals = 1, .uv = 1});
    roundtrip("v3_double_all.serialized", &t,
              &(wopt){.version = 3, .dbl = 1, .normals = 1, .uv = 1, .colors = 1});
    roundtrip("v3_float_plain.serialized", &t, &(wopt){.version = 3});
    roundtrip("v4_float_uv.serialized", &t, &(wopt){.version = 4, .uv = 1, .name = "floor"});
    roundtrip(
        "v4_double_nrm_col.serialized", &t,
        &(wopt){
            .version = 4, .dbl = 1, .normals = 1, .colors = 1, .name = "a longer name, in UTF-8: \xc3\xa9"});
    roundtrip("v4_float_col.serialized", &t, &(wopt){.version = 4, .colors = 1, .uv = 1});
    roundtrip("v4_noprec.serialized", &t, &(wopt){.version = 4, .no_precision = 1, .normals = 1});
    roundtrip("v3_faceflag.serialized", &t,
              &(wopt){.version = 3, .flags = 0x1000 | 0x10 | 0x4 | 0x2, .uv = 1});
    /* bits Mitsuba does not know (0x100, 0x40) are read past, with a warning */
    roundtrip("v3_unknown_flags.serialized", &t, &(wopt){.version = 3, .flags = 0x1000 | 0x100 | 0x40 | 0x2, .uv = 1});
    {
        /* big enough for many inflate calls and scratch chunks */
        tmesh big = grid(400, 1.0f);
        roundtrip("v4_big_double.serialized", &big,
                  &(wopt){.version = 4, .dbl = 1, .normals = 1, .uv = 1, .colors = 1, .name = "big"});
        roundtrip("v3_big_float.serialized", &big, &(wopt){.version = 3, .normals = 1, .uv = 1});
        tmesh_free(&big);
    }

    /* several shapes in one file, each version */
    for (int v = 3; v <= 4; v++) {
        const tmesh *ts[3] = {&t, &t2, &t};
        wopt os[3] = {{.version = v, .normals = 1, .uv = 1, .name = "first"},
                      {.version = v, .dbl = 1, .uv = 1, .colors = 1},
                      {.version = v, .dbl = v == 4, .normals = 1, .name = "third"}};
        buf f = {0};
        uint64_t off[3];
        for (int s = 0; s < 3; s++) {
            buf p = {0};
            payload(&p, ts[s], &os[s]);
            off[s] = f.n;
            put_shape(&f, v, &p);
            free(p.d);
        }
        put_dict(&f, v, off, 3);
        char path[512];
        snprintf(path, sizeof path, "%s/three_v%d.serialized", tmpdir, v);
        write_file(path, f.d, f.n);
        free(f.d);
        for (uint32_t s = 0; s < 3; s++) {
            cdl_serialized_mesh m;
            cdl_error err;
            int rc = cdl_serialized_read(path, s, &m, &err);
            print_err(rc, &err);
            CHECK(!rc && mesh_matches(&m, ts[s], os[s].normals, os[s].uv),
                  "three shapes, version %d: shape %u (%u vertices, %u triangles) exact", v, s, m.nverts,
                  m.ntris);
            cdl_serialized_free(&m);
        }
    }

    errors(&t, &t2);
    tmesh_free(&t);
    tmesh_free(&t2);
    cleanup();

    sponza(argc > 1 ? argv[1] : NULL);

    printf("%s: %d failure%s\n", test_failures ? "FAIL" : "ok", test_failures, test_failures == 1 ? "" : "s");
    return test_failures ? 1 : 0;
}
