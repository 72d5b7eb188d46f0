/* The candela command: a driver over the public API (candela.h) alone. */
#ifndef CLI_H
#define CLI_H

#include <candela/candela.h>
#include <stdio.h>

#define CLI_MAX_OUT 8

/* What `candela render` and `candela photons` take besides the settings. */
typedef struct cli_args {
    const char *scene;
    const char *out[CLI_MAX_OUT];
    int nout;
    int quiet, aov;
} cli_args;

/* Parses argv[1..] into s and a; -1 after --help (printed), else 0 or an
 * error. what names the command in messages. */
int cli_parse(int argc, char **argv, cdl_settings *s, cli_args *a, cdl_error *err);
/* Makes *s and parses into it; 1 when the command ends here (after --help
 * or an error, reported), with *status its exit status. */
int cli_begin(int argc, char **argv, cdl_settings **s, cli_args *a, int *status);
/* Prints "candela: error: ..." for err and returns its exit status. */
int cli_report(const cdl_error *err);
/* 1 if path ends in ext (".exr"), case-insensitive. */
int cli_has_ext(const char *path, const char *ext);
/* "max_radius" -> "--max-radius" */
void cli_flag_name(const char *name, char *buf, size_t n);
/* whether method is in the comma-separated list */
int cli_reads(const char *list, const char *method);

int cli_render(int argc, char **argv);
/* The output name when none is given: the scene file's, else SCENE.exr. */
void cli_default_output(const char *scene_path, const cdl_scene *scene, char *buf, size_t n);
/* "candela ARGS..." for the image's metadata. */
void cli_command_line(int argc, char **argv, char *buf, size_t n);

/* mpi.c (built with MPI): under mpirun, MPI is initialized and
 * `candela render` splits its passes over the ranks. cli_mpi_init returns
 * the number of ranks (1 when not under mpirun). */
int cli_mpi_init(int *argc, char ***argv);
int cli_mpi_size(void);
void cli_mpi_finalize(void);
int cli_render_mpi(int argc, char **argv, const char *cmdline);
int cli_photons(int argc, char **argv);
int cli_diff(int argc, char **argv);

double cli_now(void); /* monotonic seconds */

/* A progress bar on stderr when it is a terminal. */
typedef struct cli_bar {
    double start, last;
    int active, drawn;
} cli_bar;
void cli_bar_begin(cli_bar *b, int quiet);
void cli_bar_update(cli_bar *b, double frac, double elapsed, const char *label);
void cli_bar_end(cli_bar *b);

#endif
