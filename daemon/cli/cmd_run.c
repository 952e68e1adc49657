/* cmd_run.c — `packd run JOB.json -o OUT.h5`: one job in this process (what a
 * worker runs); usage in main.c, exit statuses in docs/architecture.md. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "input_hint.h"
#include "run_line.h"
#include "run_summary.h"
#include "api/picture/picture.h"
#include "api/process.h"
#include "api/digest.h"
#include "api/par/mpi_world.h"
#include "api/results/result_digest.h"
#include "api/results/xdmf.h"

static volatile sig_atomic_t cancel_requested;

static void on_signal(int sig)
{
    (void)sig;
    cancel_requested = 1;
}

typedef struct {
    FILE *out;        /* JSON lines of progress, or NULL */
    pk_run_line line; /* the live line on a terminal */
} progress_sink;

/* One JSON object per line: what the daemon relays to its SSE listeners;
 * and the live line when stderr is a terminal. */
static int print_progress(const pk_progress *p, void *ctx)
{
    progress_sink *s = ctx;
    pk_run_line_draw(&s->line, p);
    if (!s->out)
        return 0;
    json_t *j = json_pack("{s:s,s:f,s:f,s:I,s:I,s:f}", "stage", p->stage ? p->stage : "",
                          "fraction", p->fraction, "phi", p->phi, "done", (json_int_t)p->done,
                          "total", (json_int_t)p->total, "elapsed_s", p->elapsed_s);
    if (p->eta_s >= 0)
        json_object_set_new(j, "eta_s", json_real(p->eta_s));
    if (p->delta_d > 0)
        json_object_set_new(j, "delta_d", json_real(p->delta_d));
    if (p->message)
        json_object_set_new(j, "message", json_string(p->message));
    json_dumpf(j, s->out, JSON_COMPACT);
    fputc('\n', s->out);
    fflush(s->out);
    json_decref(j);
    return 0;
}

static void run_help(FILE *f)
{
    fputs("usage: packd run JOB.json -o OUT.h5 [options]\n"
          "run one job in this process and write its HDF5 result\n\n"
          "  -o OUT.h5                  the result file\n"
          "  --xdmf OUT.xdmf            also write an XDMF sidecar (ParaView)\n"
          "  --pictures DIR             also draw the result's pictures into DIR\n"
          "  --json                     print the summary as JSON even on a terminal\n"
          "  --progress                 progress as JSON lines on stderr\n"
          "  --progress-fd N            progress as JSON lines on file descriptor N\n"
          "  --progress-file F          progress as JSON lines appended to file F\n"
          "  --threads N                threads of the parallel sections (1..64, default 1)\n"
          "  --checkpoint FILE          save/resume the run's state in FILE\n"
          "  --checkpoint-interval S    seconds between checkpoints (default 30)\n"
          "  --author NAME              the result's /h5md/author, the person responsible\n"
          "                             (default $USER; \"\" or no $USER: \"unknown\")\n\n"
          "Under mpirun -np R (or srun --ntasks=R --mpi=pmix) an fe2 job spreads its\n"
          "Gauss points over the R ranks, rank 0 alone writing and printing (docs/fe2.md);\n"
          "other processes run on rank 0 alone.\n\n"
          "On a terminal, a live progress line on stderr and a short summary on stdout;\n"
          "otherwise (or with --json) the summary as JSON on stdout, without the time\n"
          "series (they are in the result file).  Exit 0 done, 1 invalid job, 2 error,\n"
          "3 the job failed (partial result written), 64 usage.\n",
          f);
    fprintf(f, "This packd was built %s MPI.\n", pk_mpi_built() ? "with" : "without");
}

static int run_job(int argc, char **argv);

/* Launched as R MPI ranks (mpirun -np R, srun): every rank runs this;
 * rank 0 is `packd run` as ever, the others take part only in the processes
 * that spread their work over ranks (fe2: api/fe2/fe2_mpi.h) and write and
 * print nothing on stdout. */
int cmd_run(int argc, char **argv)
{
    char err[400];
    if (pk_mpi_init(err, sizeof err) != 0) {
        fprintf(stderr, "packd run: %s\n", err);
        return 2;
    }
    int status = run_job(argc, argv);
    pk_mpi_finish(status);
    return status;
}

/* The processes whose work spreads over MPI ranks (rank 0 runs the others
 * alone). */
static int spreads_over_ranks(const json_t *job)
{
    const char *id = json_string_value(json_object_get(job, "process"));
    return id && !strcmp(id, "fe2");
}

static int run_job(int argc, char **argv)
{
    const char *job_path = NULL, *out_path = NULL, *xdmf_path = NULL, *pictures_dir = NULL;
    const char *ckpt_path = NULL, *author = getenv("USER");
    double ckpt_interval = 30;
    int progress_fd = -1, json_summary = 0;
    const char *progress_file = NULL; /* the Slurm executor reads it (no pipe across nodes) */
    /* the parallel sections' threads (the daemon passes its job_threads):
     * the results are the same for any number.  Default 1: on this 2-core
     * VM a whole 10⁴-grain step gains only 1.0–1.2x on 2 threads and loses
     * when another process shares the core (docs/homogenization.md). */
    int threads = 1;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-o") && i + 1 < argc)
            out_path = argv[++i];
        else if (!strcmp(argv[i], "--xdmf") && i + 1 < argc)
            xdmf_path = argv[++i];
        else if (!strcmp(argv[i], "--pictures") && i + 1 < argc)
            pictures_dir = argv[++i];
        else if (!strcmp(argv[i], "--json"))
            json_summary = 1;
        else if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            run_help(stdout);
            return 0;
        } else if (!strcmp(argv[i], "--progress"))
            progress_fd = 2;
        else if (!strcmp(argv[i], "--progress-fd") && i + 1 < argc)
            progress_fd = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--progress-file") && i + 1 < argc)
            progress_file = argv[++i];
        else if (!strcmp(argv[i], "--checkpoint") && i + 1 < argc)
            ckpt_path = argv[++i];
        else if (!strcmp(argv[i], "--author") && i + 1 < argc)
            author = argv[++i];
        else if (!strcmp(argv[i], "--checkpoint-interval") && i + 1 < argc) {
            char *end;
            ckpt_interval = strtod(argv[++i], &end);
            if (*end || !(ckpt_interval > 0 && ckpt_interval <= 1e6)) {
                fprintf(stderr,
                        "packd run: --checkpoint-interval takes seconds in (0, 1e6], not '%s'\n",
                        argv[i]);
                return 64;
            }
        } else if (!strcmp(argv[i], "--threads") && i + 1 < argc) {
            char *end;
            long t = strtol(argv[++i], &end, 10);
            if (*end || t < 1 || t > 64) {
                fprintf(stderr, "packd run: --threads takes 1..64, not '%s'\n", argv[i]);
                return 64;
            }
            threads = (int)t;
        } else if (!job_path && argv[i][0] != '-')
            job_path = argv[i];
        else if (!job_path && !strcmp(argv[i], "-"))
            job_path = argv[i];
        else {
            job_path = NULL;
            break;
        }
    }
    if (!job_path || !out_path) {
        run_help(stderr);
        return 64;
    }
    json_t *job = cli_load_json(job_path);
    if (!job)
        return 1;
    const int other_rank = pk_mpi_rank() > 0;
    if (other_rank && !spreads_over_ranks(job)) {
        json_decref(job);
        return 0;
    }

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    progress_sink sink = {NULL};
    if (other_rank) { /* rank 0 reports the progress */
        progress_fd = -1;
        progress_file = NULL;
    }
    if (progress_file) {
        sink.out = fopen(progress_file, "a");
        if (!sink.out)
            fprintf(stderr, "packd run: --progress-file %s: %s\n", progress_file, strerror(errno));
    } else if (progress_fd >= 0) {
        sink.out = progress_fd == 2 ? stderr : fdopen(progress_fd, "w");
        if (!sink.out)
            fprintf(stderr, "packd run: --progress-fd %d: %s\n", progress_fd, strerror(errno));
    }
    /* no live line when the JSON lines go to stderr themselves */
    pk_run_line_init(&sink.line, progress_fd == 2 || other_rank ? NULL : stderr);
    /* JSON lines every 0.5 s as ever; the live line alone up to 10 times a second */
    pk_monitor mon = {.fn = print_progress,
                      .ctx = &sink,
                      .cancel = &cancel_requested,
                      .interval_s = sink.out || !sink.line.tty ? 0.5 : 0.1};
    pk_schema_errors errs = {0};
    json_t *summary = NULL;
    char err[1024] = "";
    /* the file's author: the service's job owner, else who runs packd (NULL: unknown) */
    pk_run_ctx run = {.threads = threads, .mon = &mon, .author = author};
    /* a checkpoint resumes only the job (and packd version) that wrote it */
    char digest[65];
    if (ckpt_path && !other_rank) {
        char *text = json_dumps(job, JSON_SORT_KEYS | JSON_COMPACT);
        size_t n = text ? strlen(text) : 0;
        char *src = text ? malloc(n + sizeof PACKD_VERSION + 1) : NULL;
        if (!src) {
            free(text);
            fprintf(stderr, "packd run: out of memory\n");
            json_decref(job);
            return 2;
        }
        memcpy(src, text, n);
        src[n] = '\n';
        memcpy(src + n + 1, PACKD_VERSION, sizeof PACKD_VERSION);
        pk_sha256_hex(src, n + sizeof PACKD_VERSION, digest);
        free(src);
        free(text);
        run.checkpoint = (pk_run_checkpoint){ckpt_path, digest, ckpt_interval};
    }
    int rc = pk_job_run(job, &run, out_path, &summary, &errs, err, sizeof err);
    pk_run_line_clear(&sink.line);
    int status;
    if (other_rank) { /* rank 0 reports the job; a rank's own trouble on stderr */
        if (rc != 0 && rc != 1)
            fprintf(stderr, "packd run: MPI rank %d: %s\n", pk_mpi_rank(), err);
        status = rc == 0 || rc == 1 ? rc : 2;
    } else if (rc == 1) {
        cli_print_errors(job_path, &errs);
        cli_hint_missing_inputs(stderr, job_path, job, &errs);
        status = 1;
    } else if (rc != 0 && rc != 2) { /* 2: failed, partial file and summary (below) */
        fprintf(stderr, "packd run: %s\n", err);
        status = 2;
    } else {
        if (rc == 2) /* failed, with its partial file and summary */
            fprintf(stderr, "packd run: failed: %s (partial result in %s)\n", err, out_path);
        char digest_hex[65];
        if (pk_result_digest_stored(out_path, digest_hex) == 0)
            json_object_set_new(summary, "result_digest", json_string(digest_hex));
        /* the XML names the HDF5 file by its path relative to the XML */
        if (xdmf_path && pk_xdmf_write(out_path, NULL, xdmf_path, err, sizeof err) != 0) {
            fprintf(stderr, "packd run: %s\n", err);
            xdmf_path = NULL;
        }
        if (pictures_dir) {
            if (pk_picture_write_set(out_path, pictures_dir, err, sizeof err) == 0)
                fprintf(stderr, "packd run: no picture drawn: %s\n", err);
            pk_picture_release();
        }
        pk_run_summary_drop_series(summary);
        if (!json_summary && isatty(STDOUT_FILENO))
            pk_run_summary_print(stdout, summary, out_path, xdmf_path,
                                 pk_wall_seconds() - sink.line.t0, sink.line.utf8);
        else {
            json_dumpf(summary, stdout, JSON_INDENT(2) | JSON_REAL_PRECISION(10));
            putchar('\n');
        }
        status = rc == 2 ? 3 : 0;
    }
    if (sink.out && sink.out != stderr)
        fclose(sink.out);
    json_decref(summary);
    pk_schema_errors_free(&errs);
    json_decref(job);
    return status;
}
