/* The arguments of `candela render` and `candela photons`: outputs and the
 * scene here, every other option through cdl_settings_set, and --help from
 * the library's option table. */
#include <ctype.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "cli.h"

int cli_has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), m = strlen(ext);
    return n >= m && !strcasecmp(path + n - m, ext);
}

static int set_error(cdl_error *err, int code, const char *file, const char *msg, const char *arg)
{
    err->code = code;
    err->line = 0;
    snprintf(err->file, sizeof err->file, "%s", file);
    snprintf(err->msg, sizeof err->msg, msg, arg);
    return code;
}

/* Output files are checked before rendering so a typo costs no render. */
static int check_output(const char *path, cdl_error *err)
{
    if (!cli_has_ext(path, ".exr") && !cli_has_ext(path, ".png") && !cli_has_ext(path, ".pfm"))
        return set_error(err, CDL_ERR_USAGE, "-o", "unknown image format '%.400s' (use .exr, .png or .pfm)", path);
    char dir[1024];
    const char *slash = strrchr(path, '/');
    if (!slash)
        return 0;
    snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    struct stat st;
    if (dir[0] && (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)))
        return set_error(err, CDL_ERR_INPUT, path, "output directory '%.400s' does not exist", dir);
    return 0;
}

/* The table entry of option o ("--photons", "-C", "-i"), or NULL. */
static const cdl_option_info *find(const char *o)
{
    while (*o == '-')
        o++;
    if (!strcmp(o, "i"))
        o = "integrator";
    for (int i = 0; i < cdl_option_count(); i++)
        if (!strcmp(cdl_option_get(i)->name, o))
            return cdl_option_get(i);
    return NULL;
}

/* text from column col, wrapped at 80 columns, continuation lines indented */
static void wrapped(const char *text, int col, int indent)
{
    const char *p = text;
    while (*p) {
        int room = 80 - col, len = (int)strlen(p);
        if (len <= room) {
            printf("%s\n", p);
            break;
        }
        int cut = room;
        while (cut > 0 && p[cut] != ' ')
            cut--;
        if (cut == 0)
            cut = room;
        printf("%.*s\n%*s", cut, p, indent, "");
        p += cut;
        while (*p == ' ')
            p++;
        col = indent;
    }
}

static void help(void)
{
    printf("usage: candela render SCENE [options]\n"
           "\n"
           "SCENE is a Wavefront OBJ file (materials from its MTL files), a pbrt-v3/v4\n"
           "scene file (.pbrt) or a Mitsuba 0.6/3 scene file (.xml), whose camera, film,\n"
           "sampler and integrator settings apply unless the options below override them.\n"
           "Under mpirun (a build with MPI) the passes are split over the ranks and rank 0\n"
           "writes the image: mpirun -np N candela render SCENE --threads T ...\n"
           "\n"
           "  -o, --output FILE       .exr (32-bit float), .png (sRGB) or .pfm; repeatable\n"
           "                          (default: SCENE's name with .exr, in the current directory)\n");
    const char *section = "General";
    for (int i = 0; i < cdl_option_count(); i++) {
        const cdl_option_info *o = cdl_option_get(i);
        if (strcmp(o->section, section)) {
            section = o->section;
            printf("\n%s:\n", section);
        }
        char left[128], text[1024];
        int one = strlen(o->name) == 1;
        snprintf(left, sizeof left, "  %s%s%s%s%s", !strcmp(o->name, "integrator") ? "-i, " : !strcmp(o->name, "quiet") ? "-q, " : "    ",
                 one ? "-" : "--", o->name, o->value[0] ? " " : "", o->value);
        snprintf(text, sizeof text, "%s%s%s%s", o->help, o->value[0] && o->default_value[0] && !strstr(o->help, "default") ? " (default " : "",
                 o->value[0] && o->default_value[0] && !strstr(o->help, "default") ? o->default_value : "",
                 o->value[0] && o->default_value[0] && !strstr(o->help, "default") ? ")" : "");
        int len = (int)strlen(left);
        printf("%s%*s", left, len < 26 ? 26 - len : 2, "");
        wrapped(text, len < 26 ? 26 : len + 2, 26);
    }
    printf("\nIntegrators:\n");
    for (int i = 0; i < cdl_integrator_count(); i++) {
        printf("  %-8s ", cdl_integrator_name(i));
        wrapped(cdl_integrator_summary(i), 11, 11);
    }
    printf("\nThe summary line gives wall time, samples per pixel and Mrays/s (all rays\n"
           "traced divided by the render time). Ctrl-C writes the image so far (exit 130).\n");
}

int cli_parse(int argc, char **argv, cdl_settings *s, cli_args *a, cdl_error *err)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            help();
            return -1;
        }
        if (o[0] != '-' || !o[1]) {
            if (a->scene)
                return set_error(err, CDL_ERR_USAGE, o, "only one scene file may be given%s", "");
            a->scene = o;
            continue;
        }
        int rc;
        if (!strcmp(o, "-o") || !strcmp(o, "--output")) {
            if (i + 1 >= argc)
                return set_error(err, CDL_ERR_USAGE, o, "expects a value%s", "");
            if (a->nout == CLI_MAX_OUT)
                return set_error(err, CDL_ERR_USAGE, o, "at most 8 outputs%s", "");
            if ((rc = check_output(argv[++i], err)))
                return rc;
            a->out[a->nout++] = argv[i];
            continue;
        }
        const cdl_option_info *info = find(o);
        if (!info || !info->value[0]) { /* a flag, or unknown: the library says which */
            if ((rc = cdl_settings_set(s, o, NULL, err)))
                return rc;
            a->quiet |= !strcmp(o, "-q") || !strcmp(o, "--quiet");
            continue;
        }
        /* an option's value is the next argument, even one that starts
         * with '-' (so --spp -5 is an error about --spp) */
        if (i + 1 >= argc)
            return set_error(err, CDL_ERR_USAGE, o, "expects a value%s", "");
        if ((rc = cdl_settings_set(s, o, argv[++i], err)))
            return rc;
        a->aov |= !strcmp(info->name, "aov");
    }
    if (!a->scene)
        return set_error(err, CDL_ERR_USAGE, "render", "no scene file given (see candela render --help)%s", "");
    int rc = cdl_settings_check(s, err);
    if (rc)
        return rc;
    if (a->aov) {
        int exr = 0;
        for (int i = 0; i < a->nout; i++)
            exr |= cli_has_ext(a->out[i], ".exr");
        if (!exr)
            return set_error(err, CDL_ERR_USAGE, "--aov", "output layers need an .exr output (-o FILE.exr)%s", "");
    }
    return 0;
}

int cli_begin(int argc, char **argv, cdl_settings **s, cli_args *a, int *status)
{
    cdl_error err;
    *s = cdl_settings_create();
    if (!*s) {
        fprintf(stderr, "candela: error: out of memory\n");
        *status = 1;
        return 1;
    }
    int rc = cli_parse(argc, argv, *s, a, &err);
    if (rc) {
        cdl_settings_release(*s);
        *s = NULL;
        *status = rc < 0 ? 0 : cli_report(&err);
        return 1;
    }
    return 0;
}
