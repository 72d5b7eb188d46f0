/* Line-level validation of Wavefront OBJ and MTL files before Assimp
 * imports them. Assimp accepts much that is broken (NaN coordinates,
 * missing MTL files) and its messages carry no line numbers; this pass
 * rejects bad input with the file and line of the first problem. */
#ifndef CDL_OBJ_CHECK_H
#define CDL_OBJ_CHECK_H

#include "core/error.h"
#include "core/file.h"

int cdl_obj_check(const char *path, cdl_error *err);

/* A whole text file (scene descriptions: at most 2 GiB), see cdl_read_file. */
int cdl_read_text_file(const char *path, char **data, size_t *size, cdl_error *err);

#endif
