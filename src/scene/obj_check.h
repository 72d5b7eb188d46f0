/* Line-level validation of Wavefront OBJ and MTL files before Assimp
 * imports them. Assimp accepts much that is broken (NaN coordinates,
 * missing MTL files) and its messages carry no line numbers; this pass
 * rejects bad input with the file and line of the first problem. */
#ifndef CDL_OBJ_CHECK_H
#define CDL_OBJ_CHECK_H

#include "core/error.h"

int cdl_obj_check(const char *path, cdl_error *err);

/* Shared by the loaders: reads a whole regular file (NUL-terminated),
 * rejecting directories, unreadable and oversized files. */
int cdl_read_text_file(const char *path, char **data, size_t *size, cdl_error *err);

/* Directory part of path joined with name (name kept if absolute). */
void cdl_path_join_dir(const char *path, const char *name, char *out, size_t n);

#endif
