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

/* The library's name of command-line option o ("--max-radius" ->
 * "max_radius", "-C" -> "C", "-i" -> "integrator"), or NULL if o is not
 * spelt as an option. */
static const char *option_name(const char *o, char *buf, size_t n)
{
    if (!strcmp(o, "-i"))
        return "integrator";
    if (!strcmp(o, "-q"))
        return "quiet";
    if (!strcmp(o, "-D")) /* Mitsuba's spelling */
        return "define";
    int single = o[0] == '-' && o[1] && !o[2]; /* -C, -S, -R */
    if (!single && strncmp(o, "--", 2))
        return NULL;
    snprintf(buf, n, "%s", o + (single ? 1 : 2));
    for (char *p = buf; *p; p++) {
        if (*p == '_') /* the command line spells names with '-' only */
            return NULL;
        if (*p == '-')
            *p = '_';
    }
    return buf;
}

/* The option's spelling on the command line: "max_radius" -> "--max-radius". */
void cli_flag_name(const char *name, char *buf, size_t n)
{
    snprintf(buf, n, "%s%.60s", strlen(name) == 1 ? "-" : "--", name);
    for (char *p = buf + 2; *p; p++)
        if (*p == '_')
            *p = '-';
}

/* The list entry of option name read by method (NULL: any), or NULL. */
static const cdl_option_info *find(const char *name, const char *method)
{
    for (int i = 0; i < cdl_option_count(); i++) {
        const cdl_option_info *o = cdl_option_get(i);
        if (!strcmp(o->name, name) && (!method || !o->integrators[0] || cli_reads(o->integrators, method)))
            return o;
    }
    return NULL;
}

int cli_reads(const char *list, const char *method)
{
    size_t n = strlen(method);
    for (const char *p = list; *p;) {
        const char *e = strchr(p, ',');
        size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && !strncmp(p, method, n))
            return 1;
        p += len + (e != NULL);
    }
    return 0;
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

/* The options of method (NULL: all), by section. */
static void help(const char *method)
{
    if (method)
        printf("usage: candela render SCENE -i %s [options]\n\n", method);
    else
        printf("usage: candela render SCENE [options]\n"
               "\n"
               "SCENE is a Wavefront OBJ file (materials from its MTL files), a pbrt-v3/v4\n"
               "scene file (.pbrt) or a Mitsuba 0.6/3 scene file (.xml), whose camera, film,\n"
               "sampler and integrator settings apply unless the options below override them.\n"
               "Under mpirun (a build with MPI) the passes are split over the ranks and rank 0\n"
               "writes the image: mpirun -np N candela render SCENE --threads T ...\n"
               "An option the method does not read is an error; candela render -i METHOD\n"
               "--help lists that method's.\n"
               "\n");
    printf("  -o, --output FILE       .exr (32-bit float), .png (sRGB) or .pfm; repeatable\n"
           "                          (default: SCENE's name with .exr, in the current directory)\n");
    const char *section = "General";
    for (int i = 0; i < cdl_option_count(); i++) {
        const cdl_option_info *o = cdl_option_get(i);
        if (method && o->integrators[0] && !cli_reads(o->integrators, method))
            continue;
        if (strcmp(o->section, section)) {
            section = o->section;
            printf("\n%s:\n", section);
        }
        char left[128], text[1200], flag[64];
        cli_flag_name(o->name, flag, sizeof flag);
        snprintf(left, sizeof left, "  %s%s%s%s", !strcmp(o->name, "integrator") ? "-i, " : !strcmp(o->name, "quiet") ? "-q, " : "    ",
                 flag, o->value[0] ? " " : "", o->value);
        int dflt = o->value[0] && o->default_value[0] && !strstr(o->help, "default");
        snprintf(text, sizeof text, "%s%s%s%s", o->help, dflt ? " (default " : "", dflt ? o->default_value : "",
                 dflt ? ")" : "");
        int len = (int)strlen(left);
        printf("%s%*s", left, len < 26 ? 26 - len : 2, "");
        wrapped(text, len < 26 ? 26 : len + 2, 26);
    }
    if (!method) {
        printf("\nIntegrators:\n");
        for (int i = 0; i < cdl_integrator_count(); i++) {
            printf("  %-8s ", cdl_integrator_name(i));
            wrapped(cdl_integrator_summary(i), 11, 11);
        }
    }
    printf("\nThe summary line gives wall time, samples per pixel and Mrays/s (all rays\n"
           "traced divided by the render time). Ctrl-C writes the image so far (exit 130).\n");
}

/* -i METHOD (or --integrator METHOD) in argv, else NULL */
static const char *method_arg(int argc, char **argv)
{
    const char *m = NULL;
    for (int i = 1; i + 1 < argc; i++)
        if (!strcmp(argv[i], "-i") || !strcmp(argv[i], "--integrator"))
            m = argv[i + 1];
    for (int i = 0; m && i < cdl_integrator_count(); i++)
        if (!strcmp(cdl_integrator_name(i), m))
            return m;
    return NULL;
}

int cli_parse(int argc, char **argv, cdl_settings *s, cli_args *a, cdl_error *err)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            help(method_arg(argc, argv));
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
        char nb[64];
        const char *name = option_name(o, nb, sizeof nb);
        const cdl_option_info *info = name ? find(name, NULL) : NULL;
        if (!info)
            return set_error(err, CDL_ERR_USAGE, o, "unknown option (see candela render --help)%s", "");
        if (!info->value[0]) { /* a bare switch */
            if ((rc = cdl_settings_set(s, name, NULL, err)))
                return rc;
            a->quiet |= !strcmp(name, "quiet");
            continue;
        }
        /* an option's value is the next argument, even one that starts
         * with '-' (so --spp -5 is an error about --spp) */
        if (i + 1 >= argc)
            return set_error(err, CDL_ERR_USAGE, o, "expects a value%s", "");
        if ((rc = cdl_settings_set(s, name, argv[++i], err)))
            return rc;
        a->aov |= !strcmp(name, "aov");
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
