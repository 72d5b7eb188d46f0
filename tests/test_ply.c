/* PLY reader: the same mesh written as ascii, binary little and big endian
 * reads back identically; polygons are fan-triangulated; uv under each
 * accepted name; normals; skipped elements and properties in every format;
 * a few error messages; a 1M-triangle file; and the veach-bidir meshes.
 * Usage: test_ply [VEACH_BIDIR_MODELS_DIR]   (the real meshes are skipped
 * when the directory is not given or absent) */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/ply.h"
#include "test_util.h"

/* ---- a growable byte buffer and PLY writers ------------------------------------------------- */

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
    memcpy(b->d + b->n, p, n);
    b->n += n;
}

__attribute__((format(printf, 2, 3))) static void putf(buf *b, const char *fmt, ...)
{
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    put(b, tmp, (size_t)n);
}

enum { ASCII, LE, BE };
static const char *fmt_name[] = {"ascii", "binary_little_endian", "binary_big_endian"};

/* Writes an integer or float value of a PLY type in the file's format. */
static void put_int(buf *b, int fmt, int size, int64_t v)
{
    if (fmt == ASCII) {
        putf(b, "%lld ", (long long)v);
        return;
    }
    unsigned char t[8];
    uint64_t u = (uint64_t)v;
    for (int i = 0; i < size; i++)
        t[fmt == LE ? i : size - 1 - i] = (unsigned char)(u >> (8 * i));
    put(b, t, (size_t)size);
}

static void put_float(buf *b, int fmt, int dbl, double v)
{
    if (fmt == ASCII) {
        putf(b, "%.17g ", v);
        return;
    }
    uint64_t u;
    if (dbl) {
        memcpy(&u, &v, 8);
    } else {
        float f = (float)v;
        uint32_t w;
        memcpy(&w, &f, 4);
        u = w;
    }
    put_int(b, fmt, dbl ? 8 : 4, (int64_t)u);
}

static void end_row(buf *b, int fmt)
{
    if (fmt == ASCII)
        put(b, "\n", 1);
}

/* The test mesh: 7 vertices; a triangle, a quad and a pentagon. */
#define NV 7
#define NF 3
static const int face_n[NF] = {3, 4, 5};
static const int face_v[] = {0, 1, 2, 2, 3, 4, 5, 0, 2, 4, 5, 6};
/* fan triangulation around each face's first vertex */
static const uint32_t want_idx[] = {0, 1, 2, 2, 3, 4, 2, 4, 5, 0, 2, 4, 0, 4, 5, 0, 5, 6};
#define NT 6

static float vpos(int i, int k) { return (float)(i * 0.75 - k * 1.25 + (k == 2 ? 1e-3 * i : 0)); }
static float vnrm(int i, int k) { return k == (i % 3) ? (i & 1 ? -1.0f : 1.0f) : 0.0f; }
static float vuv(int i, int k) { return k ? 1.0f - (float)i / 8 : (float)i / 7; }

typedef struct wopt {
    int fmt;
    int normals;
    const char *u, *v;   /* uv property names, NULL = none */
    int extras;          /* skipped vertex props (a uchar and a list), edge and material elements */
    int face_extra;      /* an int face_indices after the index list (pbrt-v4) */
    const char *idxname; /* vertex_indices or vertex_index */
    int dbl;             /* positions as double */
    int count_size;      /* list count size in bytes: 1, 2 or 4 */
    int idx_size;        /* index size: 2 or 4 */
} wopt;

static void write_mesh(buf *b, const wopt *o)
{
    static const char *cnt_t[] = {"", "uchar", "ushort", "", "int"};
    static const char *idx_t[] = {"", "", "ushort", "", "uint"};
    putf(b, "ply\nformat %s 1.0\ncomment test mesh\nobj_info generated\n", fmt_name[o->fmt]);
    putf(b, "element vertex %d\n", NV);
    const char *pt = o->dbl ? "double" : "float";
    if (o->extras)
        putf(b, "property uchar red\n");
    putf(b, "property %s x\nproperty %s y\nproperty %s z\n", pt, pt, pt);
    if (o->normals)
        putf(b, "property float nx\nproperty float ny\nproperty float nz\n");
    if (o->extras)
        putf(b, "property list uchar short tags\n");
    if (o->u)
        putf(b, "property float %s\nproperty float %s\n", o->u, o->v);
    if (o->extras)
        putf(b, "element edge 2\nproperty int vertex1\nproperty int vertex2\n"
                "property list uint8 float32 weights\n");
    putf(b, "element face %d\nproperty list %s %s %s\n", NF, cnt_t[o->count_size],
         idx_t[o->idx_size], o->idxname);
    if (o->face_extra)
        putf(b, "property int face_indices\n");
    if (o->extras)
        putf(b, "element material 2\nproperty uchar r\nproperty uchar g\nproperty double shine\n");
    putf(b, "end_header\n");

    for (int i = 0; i < NV; i++) {
        if (o->extras)
            put_int(b, o->fmt, 1, 200 + i);
        for (int k = 0; k < 3; k++)
            put_float(b, o->fmt, o->dbl, vpos(i, k));
        if (o->normals)
            for (int k = 0; k < 3; k++)
                put_float(b, o->fmt, 0, vnrm(i, k));
        if (o->extras) { /* lists of length 0, 1, 2, ... */
            put_int(b, o->fmt, 1, i % 3);
            for (int k = 0; k < i % 3; k++)
                put_int(b, o->fmt, 2, -k);
        }
        if (o->u)
            for (int k = 0; k < 2; k++)
                put_float(b, o->fmt, 0, vuv(i, k));
        end_row(b, o->fmt);
    }
    if (o->extras)
        for (int e = 0; e < 2; e++) {
            put_int(b, o->fmt, 4, e);
            put_int(b, o->fmt, 4, e + 1);
            put_int(b, o->fmt, 1, 2 + e);
            for (int k = 0; k < 2 + e; k++)
                put_float(b, o->fmt, 0, 0.5 * k);
            end_row(b, o->fmt);
        }
    for (int f = 0, at = 0; f < NF; f++) {
        put_int(b, o->fmt, o->count_size, face_n[f]);
        for (int k = 0; k < face_n[f]; k++)
            put_int(b, o->fmt, o->idx_size, face_v[at++]);
        if (o->face_extra)
            put_int(b, o->fmt, 4, 1000 + f);
        end_row(b, o->fmt);
    }
    if (o->extras)
        for (int e = 0; e < 2; e++) {
            put_int(b, o->fmt, 1, 10);
            put_int(b, o->fmt, 1, 20);
            put_float(b, o->fmt, 1, 0.25);
            end_row(b, o->fmt);
        }
}

static char tmpdir[256];
static int nfiles;

static void write_file(const char *path, const void *d, size_t n)
{
    test_write(NULL, path, d, n);
    nfiles++;
}

/* Writes the mesh to tmpdir/name and reads it back. */
static int roundtrip(const char *name, const wopt *o, cdl_ply_mesh *m, cdl_error *err)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    buf b = {0};
    write_mesh(&b, o);
    write_file(path, b.d, b.n);
    free(b.d);
    return cdl_ply_read(path, m, err);
}

static void print_err(int rc, const cdl_error *err)
{
    if (rc) {
        char msg[2048];
        cdl_error_format(err, msg, sizeof msg);
        printf("      error: %s\n", msg);
    }
}

/* Exact comparison with the mesh the writer was given. */
static int mesh_matches(const cdl_ply_mesh *m, int normals, int uv)
{
    if (m->nverts != NV || m->ntris != NT || !m->pos || !m->idx)
        return 0;
    if (!!m->nrm != !!normals || !!m->uv != !!uv)
        return 0;
    for (int i = 0; i < NV; i++)
        for (int k = 0; k < 3; k++)
            if (m->pos[3 * i + k] != vpos(i, k) || (normals && m->nrm[3 * i + k] != vnrm(i, k)) ||
                (uv && k < 2 && m->uv[2 * i + k] != vuv(i, k)))
                return 0;
    return !memcmp(m->idx, want_idx, sizeof want_idx);
}

static int same_mesh(const cdl_ply_mesh *a, const cdl_ply_mesh *b)
{
    if (a->nverts != b->nverts || a->ntris != b->ntris || !!a->nrm != !!b->nrm || !!a->uv != !!b->uv)
        return 0;
    size_t nv = a->nverts;
    return !memcmp(a->pos, b->pos, nv * 12) && (!a->nrm || !memcmp(a->nrm, b->nrm, nv * 12)) &&
           (!a->uv || !memcmp(a->uv, b->uv, nv * 8)) &&
           !memcmp(a->idx, b->idx, (size_t)a->ntris * 12);
}

/* Writes text (or bytes) and checks the formatted error contains want. */
static void expect_error(const char *name, const void *data, size_t n, const char *want)
{
    char path[512], msg[2048];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    write_file(path, data, n);
    cdl_ply_mesh m;
    cdl_error err;
    int rc = cdl_ply_read(path, &m, &err);
    msg[0] = 0;
    if (rc)
        cdl_error_format(&err, msg, sizeof msg);
    const char *base = strrchr(msg, '/');
    int ok = rc == CDL_ERR_INPUT && strstr(msg, want) && !m.pos && !m.idx && m.ntris == 0;
    CHECK(ok, "%s rejected: %s%s%s", name, base ? base + 1 : msg, ok ? "" : " -- expected: ",
          ok ? "" : want);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* A grid of quads, binary little endian: ~1M triangles. */
static void big_mesh(void)
{
    const int n = 708; /* quads per side */
    const int nv = (n + 1) * (n + 1);
    buf b = {0};
    putf(&b, "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\n"
             "property float y\nproperty float z\nproperty float nx\nproperty float ny\n"
             "property float nz\nproperty float u\nproperty float v\nelement face %d\n"
             "property list uchar int vertex_indices\nend_header\n",
         nv, n * n);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            float v[8] = {(float)i, (float)j, 0, 0, 0, 1, (float)i / n, (float)j / n};
            for (int k = 0; k < 8; k++)
                put_float(&b, LE, 0, v[k]);
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int32_t q[4] = {j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                            (j + 1) * (n + 1) + i};
            put_int(&b, LE, 1, 4);
            for (int k = 0; k < 4; k++)
                put_int(&b, LE, 4, q[k]);
        }
    char path[512];
    snprintf(path, sizeof path, "%s/big.ply", tmpdir);
    write_file(path, b.d, b.n);
    free(b.d);
    cdl_ply_mesh m;
    cdl_error err;
    double t0 = now();
    int rc = cdl_ply_read(path, &m, &err);
    double t = now() - t0;
    print_err(rc, &err);
    uint32_t bad = 0;
    for (size_t k = 0; !rc && k < 3 * (size_t)m.ntris; k++)
        bad += m.idx[k] >= m.nverts;
    CHECK(!rc && m.nverts == (uint32_t)nv && m.ntris == 2u * n * n && !bad,
          "1M-triangle binary file: %u vertices, %u triangles (%d), read in %.0f ms", m.nverts,
          m.ntris, 2 * n * n, t * 1e3);
    cdl_ply_free(&m);
}

static void real_meshes(const char *dir)
{
    struct stat st;
    if (!dir || stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
        printf("skip: veach-bidir models directory %s not found\n", dir ? dir : "(not given)");
        return;
    }
    uint64_t total = 0;
    int nread = 0;
    for (int k = 0; k < 12; k++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/Mesh%03d.ply", dir, k);
        cdl_ply_mesh m;
        cdl_error err;
        int rc = cdl_ply_read(path, &m, &err);
        print_err(rc, &err);
        uint32_t bad = 0;
        for (size_t i = 0; !rc && i < 3 * (size_t)m.ntris; i++)
            bad += m.idx[i] >= m.nverts;
        for (size_t i = 0; !rc && i < 3 * (size_t)m.nverts; i++)
            bad += !isfinite(m.pos[i]);
        CHECK(!rc && m.nverts > 0 && m.ntris > 0 && !bad,
              "Mesh%03d.ply: %u vertices, %u triangles, normals %s, uv %s, %u bad values", k,
              m.nverts, m.ntris, m.nrm ? "yes" : "no", m.uv ? "yes" : "no", bad);
        total += m.ntris;
        nread += !rc;
        cdl_ply_free(&m);
    }
    CHECK(nread == 12 && total == 11540, "veach-bidir: %d meshes, %llu triangles in all (README: 11,540)",
          nread, (unsigned long long)total);
}

static void cleanup(void)
{
    DIR *d = opendir(tmpdir);
    if (!d)
        return;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", tmpdir, e->d_name);
        unlink(path);
    }
    closedir(d);
    rmdir(tmpdir);
}

int main(int argc, char **argv)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(tmpdir, sizeof tmpdir, "%s/candela-ply.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 2;
    }
    cdl_error err;
    int rc;

    /* Same mesh, three formats, every kind of skipped data. */
    cdl_ply_mesh m[3];
    for (int f = 0; f < 3; f++) {
        wopt o = {.fmt = f, .normals = 1, .u = "u", .v = "v", .extras = 1, .face_extra = 1,
                  .idxname = "vertex_indices", .count_size = 1, .idx_size = 4};
        char name[64];
        snprintf(name, sizeof name, "full_%s.ply", fmt_name[f]);
        rc = roundtrip(name, &o, &m[f], &err);
        print_err(rc, &err);
        CHECK(!rc && mesh_matches(&m[f], 1, 1),
              "%s: %u vertices, %u triangles (%d, %d), normals and uv exact; edge, material, list "
              "and face_indices skipped",
              fmt_name[f], m[f].nverts, m[f].ntris, NV, NT);
    }
    CHECK(same_mesh(&m[0], &m[1]) && same_mesh(&m[1], &m[2]),
          "ascii, little and big endian give identical arrays");
    CHECK(m[0].ntris == NT && !memcmp(m[0].idx, want_idx, sizeof want_idx),
          "triangle, quad and pentagon fan-triangulated into %u triangles: (%u %u %u) (%u %u %u) "
          "(%u %u %u) ...",
          m[0].ntris, m[0].idx[3], m[0].idx[4], m[0].idx[5], m[0].idx[6], m[0].idx[7], m[0].idx[8],
          m[0].idx[9], m[0].idx[10], m[0].idx[11]);
    for (int f = 0; f < 3; f++)
        cdl_ply_free(&m[f]);

    /* uv under each name, no normals, plain files; other index types and names. */
    static const char *uvn[5][2] = {
        {"u", "v"}, {"s", "t"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}, {"u", "w"}};
    for (int k = 0; k < 5; k++)
        for (int f = 0; f < 3; f++) {
            wopt o = {.fmt = f, .u = uvn[k][0], .v = uvn[k][1], .idxname = k & 1 ? "vertex_index" : "vertex_indices",
                      .dbl = k == 2, .count_size = k == 3 ? 4 : k == 1 ? 2 : 1,
                      .idx_size = k == 4 ? 2 : 4};
            char name[64];
            snprintf(name, sizeof name, "uv%d_%s.ply", k, fmt_name[f]);
            cdl_ply_mesh mm;
            rc = roundtrip(name, &o, &mm, &err);
            print_err(rc, &err);
            int want_uv = k < 4;
            CHECK(!rc && mesh_matches(&mm, 0, want_uv) && !mm.nrm,
                  "%s: uv as '%s %s' -> uv %s (%s), normals none; %s, %s positions, count %d "
                  "bytes, index %d bytes",
                  fmt_name[f], uvn[k][0], uvn[k][1], mm.uv ? "read" : "none",
                  want_uv ? "read" : "none", o.idxname, o.dbl ? "double" : "float", o.count_size,
                  o.idx_size);
            cdl_ply_free(&mm);
        }

    /* Errors: line numbers in the header and ASCII bodies, element numbers in binary. */
    {
        const char *t = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                        "end_header\n0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n";
        expect_error("e_ascii_word.ply", t, strlen(t),
                     "e_ascii_word.ply:12: vertex 2: 'zero' is not a number");
        t = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 1 0\n\n3 0 1 2\n4 0 1 2 3\n";
        expect_error("e_ascii_index.ply", t, strlen(t),
                     "e_ascii_index.ply:15: face 1: vertex index 3 out of range (3 vertices)");
        t = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0 7\n";
        expect_error("e_ascii_extra.ply", t, strlen(t),
                     "e_ascii_extra.ply:10: vertex 0: too many values on the line");
        t = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n";
        expect_error("e_ascii_short.ply", t, strlen(t),
                     "e_ascii_short.ply: truncated: expected 3 vertices, file ends after 2");
        t = "ply\nformat binary_big_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
            "property float y\nproperty float z\nelement face 1\n"
            "property list uchar int vertex_indices\nend_header\n0123456789ab";
        expect_error("e_huge.ply", t, strlen(t),
                     "e_huge.ply: truncated: expected 4000000000 vertices, file ends after 1");

        wopt o = {.fmt = LE, .idxname = "vertex_indices", .count_size = 1, .idx_size = 4};
        buf b = {0};
        write_mesh(&b, &o);
        /* last index of the last face (the pentagon's 6) -> 4096 */
        size_t last = b.n - 4;
        b.d[last] = 0x00, b.d[last + 1] = 0x10;
        expect_error("e_bin_index.ply", b.d, b.n,
                     "e_bin_index.ply: face 2: vertex index 4096 out of range (7 vertices)");
        expect_error("e_bin_trunc.ply", b.d, b.n - 9,
                     "e_bin_trunc.ply: truncated: expected 3 faces, file ends after 2");
        free(b.d);
        char dir[300];
        snprintf(dir, sizeof dir, "%s/adir.ply", tmpdir);
        mkdir(dir, 0700);
        cdl_ply_mesh mm;
        rc = cdl_ply_read(dir, &mm, &err);
        CHECK(rc == CDL_ERR_INPUT && strstr(err.msg, "directory"), "a directory is rejected: %s",
              err.msg);
        rmdir(dir);
    }

    big_mesh();
    real_meshes(argc > 1 ? argv[1] : NULL);

    cleanup();
    printf("%d files written; %s\n", nfiles, test_failures ? "FAILED" : "all passed");
    return test_failures != 0;
}
