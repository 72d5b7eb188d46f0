/* Reads one PLY file with cdl_ply_read, for the bad_ply corpus run by
 * bad_input/run.sh. Usage: ply_check FILE.ply
 * Error: one line "candela: error: FILE[:LINE]: message" on stderr, exit 1.
 * Success: the counts on stdout, exit 0. */
#include <stdio.h>

#include "io/ply.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "candela: error: usage: ply_check FILE.ply\n");
        return 2;
    }
    cdl_ply_mesh m;
    cdl_error err;
    if (cdl_ply_read(argv[1], &m, &err)) {
        char buf[2048];
        cdl_error_format(&err, buf, sizeof buf);
        fprintf(stderr, "candela: error: %s\n", buf);
        return 1;
    }
    printf("%s: %u vertices, %u triangles%s%s\n", argv[1], m.nverts, m.ntris,
           m.nrm ? ", normals" : "", m.uv ? ", uv" : "");
    cdl_ply_free(&m);
    return 0;
}
