/* The pbrt reader's context: errors and warnings at file:line, paths
 * relative to the main file; what the loader, shapes, lights and
 * materials all use. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdarg.h>
#include <string.h>
#include <sys/stat.h>

#include "core/file.h"
#include "core/log.h"
#include "io/pbrt_internal.h"

int cdl_pbrt_error(cdl_pbrt_ctx *c, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_error_vset(c->err, CDL_ERR_INPUT, c->file, line, fmt, ap);
    va_end(ap);
    return CDL_ERR_INPUT;
}

void cdl_pbrt_warn(cdl_pbrt_ctx *c, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    cdl_vwarn(c->file, line, fmt, ap);
    va_end(ap);
}

int cdl_pbrt_scene_rc(cdl_pbrt_ctx *c, int rc)
{
    return cdl_error_place(c->err, rc, c->s->path, c->file, c->line);
}

void cdl_pbrt_resolve(const cdl_pbrt_ctx *c, const char *name, char *out, size_t n)
{
    cdl_path_join_dir(c->main_path, name, out, n);
}

int cdl_pbrt_check_file(cdl_pbrt_ctx *c, const char *what, const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return cdl_pbrt_error(c, c->line, "%s \"%s\" cannot be opened: %s", what, path, strerror(errno));
    if (S_ISDIR(st.st_mode))
        return cdl_pbrt_error(c, c->line, "%s \"%s\" is a directory, not a file", what, path);
    if (!S_ISREG(st.st_mode))
        return cdl_pbrt_error(c, c->line, "%s \"%s\" is not a regular file", what, path);
    return 0;
}
