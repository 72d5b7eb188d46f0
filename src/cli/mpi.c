/* `mpirun -np N candela render ...`: every rank loads the scene and renders
 * its share of the passes (pass i on rank i mod N, each rank on its cores
 * with OpenMP); rank 0 sums the ranks' accumulators (MPI_Reduce) and writes
 * the image. A pass is deterministic given (seed, index), so the image is
 * the one-process render's up to the order of the sums. Only rank 0 talks:
 * the others' stdout and stderr go to /dev/null, except the error of the
 * first rank that fails. */
#define _POSIX_C_SOURCE 200809L
#include <fcntl.h>
#include <mpi.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"

static int rank, nranks, err_fd = 2;
static cdl_renderer *volatile interrupted_render;
static volatile sig_atomic_t interrupted;

int cli_mpi_init(int *argc, char ***argv)
{
    /* only under mpirun: a plain run stays a plain process (no singleton MPI) */
    if (!getenv("OMPI_COMM_WORLD_SIZE") && !getenv("PMI_SIZE") && !getenv("PMIX_RANK"))
        return 1;
    int provided;
    if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
        return 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nranks);
    if (nranks > 1 && rank > 0) {
        err_fd = dup(2);
        int null = open("/dev/null", O_WRONLY);
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
            close(null);
        }
    }
    return nranks;
}

int cli_mpi_size(void)
{
    return nranks ? nranks : 1;
}

void cli_mpi_finalize(void)
{
    int up = 0;
    MPI_Initialized(&up);
    if (up)
        MPI_Finalize();
}

static void on_signal(int sig)
{
    (void)sig;
    interrupted = 1;
    cdl_renderer_cancel(interrupted_render); /* an atomic store */
}

/* 0 when every rank is fine; else every rank returns the status of the
 * first rank that failed, which alone prints its error. */
static int agree(int rc, const cdl_error *err)
{
    int mine = rc ? rank : nranks, first;
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (first == nranks)
        return 0;
    int status = rc ? (err->code == CDL_ERR_USAGE ? 2 : 1) : 0;
    MPI_Bcast(&status, 1, MPI_INT, first, MPI_COMM_WORLD);
    if (rank == first) {
        char buf[2048];
        cdl_error_format(err, buf, sizeof buf);
        if (rank)
            dprintf(err_fd, "candela: error: rank %d: %s\n", rank, buf);
        else
            dprintf(err_fd, "candela: error: %s\n", buf);
    }
    return status;
}

/* MPI counts are ints: sums in chunks (root < 0: every rank gets them). */
static void sum_doubles(const double *in, double *out, size_t n, int root)
{
    const size_t chunk = (size_t)1 << 26;
    for (size_t off = 0; off < n; off += chunk) {
        int m = (int)(n - off < chunk ? n - off : chunk);
        if (root < 0)
            MPI_Allreduce(in + off, out + off, m, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
        else
            MPI_Reduce(in + off, out ? out + off : NULL, m, MPI_DOUBLE, MPI_SUM, root, MPI_COMM_WORLD);
    }
}

/* The folds of an adapting method (gkde) up to pass upto, each with the
 * state summed over the ranks: every rank runs the same sequence. */
static void fold_adaptive(cdl_renderer *r, double *mine, double *sum, size_t n, uint32_t upto)
{
    cdl_error err;
    while (n && cdl_renderer_adapt_next(r) <= upto) {
        cdl_renderer_adapt_get(r, mine, n, &err);
        sum_doubles(mine, sum, n, -1);
        cdl_renderer_adapt_fold(r, sum, n, &err);
    }
}

static int on_progress(void *user, const cdl_progress *p)
{
    char label[64];
    snprintf(label, sizeof label, "%u spp on rank 0", p->passes);
    cli_bar_update(user, p->fraction, p->seconds, label);
    return 0;
}

int cli_render_mpi(int argc, char **argv, const char *cmdline)
{
    cdl_error err;
    cli_args a;
    cdl_settings *s = NULL;
    int status = 0;
    /* argument errors are the same on every rank: rank 0 reports them */
    int stop = cli_begin(argc, argv, &s, &a, &status);
    int all_stop;
    MPI_Allreduce(&stop, &all_stop, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (all_stop) {
        if (s)
            cdl_settings_release(s);
        return status;
    }
    cdl_scene *scene = NULL;
    cdl_renderer *r = NULL;
    int rc = cdl_scene_open(a.scene, s, &scene, &err);
    if (!rc)
        rc = cdl_renderer_create(scene, s, &r, &err);
    cdl_settings_release(s);
    if ((status = agree(rc, &err))) {
        cdl_renderer_release(r);
        cdl_scene_release(scene);
        return status;
    }
    char defout[1024];
    if (a.nout == 0) {
        cli_default_output(a.scene, scene, defout, sizeof defout);
        a.out[a.nout++] = defout;
    }

    uint32_t spp;
    double budget;
    cdl_renderer_budget(r, &spp, &budget);
    /* passes that adapt to earlier ones stay those of one process (spp budgets) */
    size_t na = 0;
    double *amine = NULL, *asum = NULL;
    rc = spp ? cdl_renderer_adapt_size(r, &na, &err) : 0;
    if (!rc && na && (!(amine = malloc(na * sizeof *amine)) || !(asum = malloc(na * sizeof *asum))))
        err = (cdl_error){rc = CDL_ERR_SYSTEM, 0, "", "out of memory for the adaptive state"};
    if ((status = agree(rc, &err))) {
        free(amine);
        free(asum);
        cdl_renderer_release(r);
        cdl_scene_release(scene);
        return status;
    }
    interrupted_render = r;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal); /* what mpirun sends the ranks on Ctrl-C */
    cli_bar bar;
    cli_bar_begin(&bar, a.quiet || rank > 0);
    MPI_Barrier(MPI_COMM_WORLD); /* a common start for the time budget */
    double t0 = cli_now(), last = 0.0;
    rc = 0;
    for (uint32_t k = 0; !rc && !interrupted; k++) {
        uint64_t index = (uint64_t)k * (uint64_t)nranks + (uint64_t)rank;
        double now = cli_now() - t0;
        if (spp ? index >= spp : (k > 0 && now + last > budget))
            break;
        if (index > UINT32_MAX)
            break;
        if (spp)
            fold_adaptive(r, amine, asum, na, (uint32_t)index);
        double tp = cli_now();
        rc = cdl_renderer_render_pass(r, (uint32_t)index, &err);
        last = cli_now() - tp;
        if (!rc && !interrupted) {
            cdl_progress p = {k + 1, cli_now() - t0, 0.0};
            p.fraction = spp ? (double)(k + 1) * nranks / spp : p.seconds / budget;
            p.fraction = p.fraction < 1.0 ? p.fraction : 1.0;
            on_progress(&bar, &p);
        }
    }
    if (spp)
        fold_adaptive(r, amine, asum, na, spp - 1); /* the folds the others still make */
    free(amine);
    free(asum);
    cli_bar_end(&bar);
    double t_render = cli_now() - t0;
    int pass_failed = rc ? (err.code == CDL_ERR_USAGE ? 2 : 1) : 0;
    if (rc) { /* the passes done so far still count */
        char buf[2048];
        cdl_error_format(&err, buf, sizeof buf);
        dprintf(err_fd, "candela: error: rank %d: %s\n", rank, buf);
    }

    /* the sum of every rank's accumulators on rank 0 */
    double t_comm = cli_now();
    size_t n = cdl_renderer_accum_size(r);
    double *mine = malloc(n * sizeof *mine), *sum = rank == 0 ? malloc(n * sizeof *sum) : NULL;
    int ok = mine && (rank > 0 || sum), all_ok;
    if (ok)
        cdl_renderer_accum_get(r, mine, n, &err);
    MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (all_ok)
        sum_doubles(mine, sum, n, 0);
    t_comm = cli_now() - t_comm;
    double stats[3] = {t_comm, t_render, (double)cdl_renderer_passes(r)}, smax[3], smin[3];
    MPI_Reduce(stats, smax, 3, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    MPI_Reduce(stats, smin, 3, MPI_DOUBLE, MPI_MIN, 0, MPI_COMM_WORLD);
    int any_int = interrupted, any_interrupted;
    MPI_Reduce(&any_int, &any_interrupted, 1, MPI_INT, MPI_MAX, 0, MPI_COMM_WORLD);
    signal(SIGINT, SIG_DFL);
    signal(SIGTERM, SIG_DFL);
    interrupted_render = NULL;

    if (rank == 0) {
        if (!all_ok) {
            status = cli_report(&(cdl_error){CDL_ERR_SYSTEM, 0, "", "out of memory for the film reduction"});
        } else if ((rc = cdl_renderer_accum_set(r, sum, n, &err))) {
            status = cli_report(&err);
        } else {
            uint32_t passes = cdl_renderer_passes(r);
            for (int i = 0; !rc && i < a.nout && passes > 0; i++)
                rc = cdl_renderer_write(r, a.out[i], cmdline, &err);
            status = rc ? cli_report(&err) : 0;
            if (!rc && passes > 0)
                printf("%s: %s %dx%d, %u spp in %.2f s, %d ranks x %.0f threads, %.0f-%.0f passes per rank, "
                       "communication %.3f s%s -> %s%s\n",
                       a.scene, cdl_renderer_integrator(r), cdl_renderer_width(r), cdl_renderer_height(r), passes,
                       smax[1] + smax[0], nranks, cdl_renderer_stat_value(r, "threads"), smin[2], smax[2],
                       smax[0], any_interrupted ? " (interrupted)" : "", a.out[0], a.nout > 1 ? " ..." : "");
        }
    }
    free(mine);
    free(sum);
    cdl_renderer_release(r);
    cdl_scene_release(scene);
    if (!status && pass_failed)
        status = pass_failed;
    if (!status && rank == 0 && any_interrupted)
        status = 130;
    return status;
}
