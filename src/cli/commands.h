#ifndef CDL_COMMANDS_H
#define CDL_COMMANDS_H

/* Each returns the process exit status. */
int cdl_cmd_render(int argc, char **argv);
int cdl_cmd_diff(int argc, char **argv);
int cdl_cmd_photons(int argc, char **argv);

/* Prints "candela: error: ..." for err and returns its exit status. */
struct cdl_error;
int cdl_report(const struct cdl_error *err);

#endif
