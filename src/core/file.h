/* Reading whole files and resolving names relative to another file: shared
 * by every scene and mesh reader, so each rejects the same bad paths the
 * same way (directories, devices, oversized files). */
#ifndef CDL_FILE_H
#define CDL_FILE_H

#include <stddef.h>
#include <stdint.h>

#include "core/error.h"

/* Reads a whole regular file of at most max_bytes into *data (malloc'd,
 * NUL-terminated one past *size, so text parsers may rely on it). */
int cdl_read_file(const char *path, uint64_t max_bytes, char **data, size_t *size, cdl_error *err);

/* Directory part of path joined with name (name kept if absolute). */
void cdl_path_join_dir(const char *path, const char *name, char *out, size_t n);

#endif
