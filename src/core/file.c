#define _POSIX_C_SOURCE 200809L
#include "core/file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int cdl_read_file(const char *path, uint64_t max_bytes, char **data, size_t *size, cdl_error *err)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot open: %s", strerror(errno));
    if (S_ISDIR(st.st_mode))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "is a directory, not a file");
    if (!S_ISREG(st.st_mode))
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "not a regular file");
    if ((uint64_t)st.st_size > max_bytes || (uint64_t)st.st_size >= SIZE_MAX)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "file too large (%llu bytes)",
                             (unsigned long long)st.st_size);
    FILE *f = fopen(path, "rb");
    if (!f)
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "cannot open: %s", strerror(errno));
    size_t n = (size_t)st.st_size;
    char *buf = malloc(n + 1);
    if (!buf) {
        fclose(f);
        return cdl_error_set(err, CDL_ERR_SYSTEM, path, 0, "out of memory");
    }
    size_t got = fread(buf, 1, n, f);
    int bad = ferror(f);
    fclose(f);
    if (bad || got != n) {
        free(buf);
        return cdl_error_set(err, CDL_ERR_INPUT, path, 0, "read error");
    }
    buf[n] = 0;
    *data = buf;
    *size = n;
    return 0;
}

void cdl_path_join_dir(const char *path, const char *name, char *out, size_t n)
{
    const char *slash = strrchr(path, '/');
    if (name[0] == '/' || !slash)
        snprintf(out, n, "%s", name);
    else
        snprintf(out, n, "%.*s/%s", (int)(slash - path), path, name);
}

