/* fe2_mpi.c — an fe2 run over the ranks of an MPI launch: the blocks, the
 * commands rank 0 sends (a round at u, commit, the centres of a Gauss point,
 * stop) and the answers.  Contract: fe2_mpi.h. */
#include "fe2_mpi.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "api/par/mpi_world.h"
#include "core/base/par.h"

enum { OP_EVAL = 1, OP_COMMIT, OP_CENTRES, OP_STOP };
enum { TAG_RVE = 11, TAG_CMD, TAG_RES, TAG_ACK, TAG_CENTRES };

/* The RVE's header: ok, dim, L[3], periodic[3], n. */
#define RVE_HEAD 9

static void block_of(const pk_fe2_mpi *d, int r, size_t *lo, size_t *hi)
{
    pk_par_range(d->ngp, r, d->size, 1, lo, hi);
}

/* Why a wait ended (rc of pk_mpi_exchange): the ranks of its transfers not
 * done — the lost rank among them — with their Gauss points. */
static void lost(pk_fe2_mpi *d, int rc, const pk_mpi_msg *m, size_t n, const char *what, char *why,
                 size_t whylen)
{
    d->broken = 1;
    const char *cause = rc == PK_MPI_CANCELLED
        ? "a signal came while waiting (the launcher signals every rank when one dies; or "
          "the job was cancelled)"
        : d->deadline > 0 && pk_wall_seconds() > d->deadline ? "no answer within the wall time"
                                                             : "an MPI error (a rank is gone)";
    int len = snprintf(why, whylen, "during %s, no answer from MPI rank", what);
    int named = 0, last = -1;
    for (size_t i = 0; i < n && len >= 0 && (size_t)len < whylen; i++) {
        if (m[i].done || m[i].peer == last)
            continue;
        last = m[i].peer;
        size_t lo = 0, hi = 0;
        block_of(d, m[i].peer, &lo, &hi);
        len += snprintf(why + len, whylen - (size_t)len, "%s %d of %d (Gauss points %zu..%zu)",
                        named++ ? "," : "", m[i].peer, d->size, lo, hi - 1);
    }
    if (len >= 0 && (size_t)len < whylen)
        snprintf(why + len, whylen - (size_t)len, "%s: %s", named ? "" : "s (none pending)", cause);
}

/* Rank 0: one message of n bytes (buf) to every other rank (tag). */
static int to_all(pk_fe2_mpi *d, int tag, void *buf, size_t n, const char *what, char *why,
                  size_t whylen)
{
    pk_mpi_msg m[PK_PAR_MAX];
    size_t k = 0;
    for (int r = 1; r < d->size; r++)
        m[k++] = (pk_mpi_msg){r, tag, 1, buf, n, 0};
    int rc = pk_mpi_exchange(m, k, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        lost(d, rc, m, k, what, why, whylen);
        return -1;
    }
    d->bytes_out += k * n;
    return 0;
}

/* A command: op, its argument, u (OP_EVAL) — one fixed-size message. */
static int command(pk_fe2_mpi *d, int op, size_t arg, const double *u, const char *what, char *why,
                   size_t whylen)
{
    d->cmd[0] = op, d->cmd[1] = (double)arg;
    if (u)
        memcpy(&d->cmd[2], u, d->ndof * sizeof *u);
    return to_all(d, TAG_CMD, d->cmd, (2 + d->ndof) * sizeof *d->cmd, what, why, whylen);
}

static int round_start(void *ctx, const double *u, size_t ndof, char *why, size_t whylen)
{
    pk_fe2_mpi *d = ctx;
    (void)ndof;
    return command(d, OP_EVAL, 0, u, "a round", why, whylen) == 0 ? PK_FE2_DIST_OK
                                                                  : PK_FE2_DIST_LOST;
}

static int round_finish(void *ctx, pk_fe2_gp_result *res, char *why, size_t whylen)
{
    pk_fe2_mpi *d = ctx;
    pk_mpi_msg m[PK_PAR_MAX];
    size_t k = 0, bytes = 0;
    for (int r = 1; r < d->size; r++) {
        size_t lo, hi;
        block_of(d, r, &lo, &hi);
        m[k++] = (pk_mpi_msg){r, TAG_RES, 0, &res[lo], (hi - lo) * sizeof *res, 0};
        bytes += (hi - lo) * sizeof *res;
    }
    int rc = pk_mpi_exchange(m, k, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        lost(d, rc, m, k, "a round", why, whylen);
        return PK_FE2_DIST_LOST;
    }
    d->bytes_in += bytes;
    return PK_FE2_DIST_OK;
}

static int commit_all(void *ctx, char *why, size_t whylen)
{
    pk_fe2_mpi *d = ctx;
    if (command(d, OP_COMMIT, 0, NULL, "a commit", why, whylen) != 0)
        return PK_FE2_DIST_LOST;
    int32_t st[PK_PAR_MAX];
    pk_mpi_msg m[PK_PAR_MAX];
    size_t k = 0;
    for (int r = 1; r < d->size; r++)
        m[k++] = (pk_mpi_msg){r, TAG_ACK, 0, &st[r], sizeof st[r], 0};
    int rc = pk_mpi_exchange(m, k, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        lost(d, rc, m, k, "a commit", why, whylen);
        return PK_FE2_DIST_LOST;
    }
    for (int r = 1; r < d->size; r++)
        if (st[r] != 0) {
            snprintf(why, whylen, "MPI rank %d: out of memory (commit of its Gauss points)", r);
            return PK_FE2_DIST_LOST;
        }
    return PK_FE2_DIST_OK;
}

int pk_fe2_mpi_init(pk_fe2_mpi *d, size_t ngp, size_t ndof, const pk_monitor *mon)
{
    memset(d, 0, sizeof *d);
    d->rank = pk_mpi_rank(), d->size = pk_mpi_size();
    d->ngp = ngp, d->ndof = ndof;
    d->cancel = mon ? mon->cancel : NULL;
    d->deadline = mon && mon->wall_limit_s > 0 ? mon->t_job + mon->wall_limit_s : 0;
    if (d->size > PK_PAR_MAX)
        return -1;
    block_of(d, d->rank, &d->lo, &d->hi);
    d->dist = (pk_fe2_distributor){d, d->lo, d->hi, round_start, round_finish, commit_all};
    d->cmd = calloc(2 + ndof, sizeof *d->cmd);
    return d->cmd ? 0 : -1;
}

void pk_fe2_mpi_attach(pk_fe2_mpi *d, const pk_fe2_rve *mr, size_t ngrain)
{
    d->mr = mr;
    d->ngrain = ngrain;
}

int pk_fe2_mpi_share_rve(pk_fe2_mpi *d, int ok, pk_box *box, pk_particles *p, char *err,
                         size_t errlen)
{
    double head[RVE_HEAD] = {0};
    if (d->rank == 0) {
        head[0] = ok;
        if (ok) {
            head[1] = box->dim, head[8] = (double)p->n;
            for (int k = 0; k < 3; k++)
                head[2 + k] = box->L[k], head[5 + k] = box->periodic[k];
        }
        if (to_all(d, TAG_RVE, head, sizeof head, "the RVE's hand-over", err, errlen) != 0)
            return -1;
        if (!ok)
            return 0;
        const size_t n = p->n;
        double *body = malloc((5 * n + 1) * sizeof *body);
        if (!body) {
            snprintf(err, errlen, "out of memory");
            return -1;
        }
        memcpy(body, p->x, 3 * n * sizeof *body);
        memcpy(body + 3 * n, p->r, n * sizeof *body);
        for (size_t i = 0; i < n; i++)
            body[4 * n + i] = p->species[i];
        int rc = to_all(d, TAG_RVE, body, 5 * n * sizeof *body, "the RVE's hand-over", err, errlen);
        free(body);
        return rc;
    }
    pk_mpi_msg m = {0, TAG_RVE, 0, head, sizeof head, 0};
    int rc = pk_mpi_exchange(&m, 1, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        lost(d, rc, &m, 1, "the RVE's hand-over", err, errlen);
        return -1;
    }
    if (!head[0])
        return 1;
    const size_t n = (size_t)head[8];
    memset(box, 0, sizeof *box);
    box->dim = (int)head[1];
    for (int k = 0; k < 3; k++)
        box->L[k] = head[2 + k], box->periodic[k] = head[5 + k] != 0;
    double *body = malloc((5 * n + 1) * sizeof *body);
    if (!body || pk_particles_init(p, box->dim, n ? n : 1) != 0) {
        free(body);
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    m = (pk_mpi_msg){0, TAG_RVE, 0, body, 5 * n * sizeof *body, 0};
    rc = pk_mpi_exchange(&m, 1, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        free(body);
        lost(d, rc, &m, 1, "the RVE's hand-over", err, errlen);
        return -1;
    }
    for (size_t i = 0; i < n; i++)
        pk_particles_push(p, &body[3 * i], body[3 * n + i], (int32_t)body[4 * n + i]);
    free(body);
    return 0;
}

/* A rank other than 0 that a signal interrupted: the launcher signals every
 * rank when one dies (or the job is cancelled).  Rank 0 still writes its
 * partial result and ends the launch (MPI_Abort); leaving first (an abort
 * of our own) would kill it mid-write.  So wait for that end, at most
 * LINGER_S: Slurm's default KillWait, after which the launcher kills anyway. */
#define LINGER_S 30.0

static void linger(void)
{
    const struct timespec ts = {0, 10000000};
    for (double t0 = pk_wall_seconds(); pk_wall_seconds() - t0 < LINGER_S;)
        nanosleep(&ts, NULL);
}

int pk_fe2_mpi_serve(pk_fe2_mpi *d, const pk_fe2_problem *pb, char *err, size_t errlen)
{
    const size_t nb = d->hi - d->lo, cmd_bytes = (2 + d->ndof) * sizeof *d->cmd;
    pk_fe2_gp_result *res = calloc(nb ? nb : 1, sizeof *res);
    if (!res) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int rc = -1;
    for (;;) {
        pk_mpi_msg m = {0, TAG_CMD, 0, d->cmd, cmd_bytes, 0};
        int w = pk_mpi_exchange(&m, 1, d->cancel, d->deadline);
        if (w != PK_MPI_OK) {
            lost(d, w, &m, 1, "the wait for a command", err, errlen);
            if (w == PK_MPI_CANCELLED)
                linger();
            break;
        }
        const int op = (int)d->cmd[0];
        if (op == OP_STOP) {
            rc = 0;
            break;
        }
        int32_t st = 0;
        if (op == OP_EVAL) {
            st = pk_fe2_eval_block(pb, &d->cmd[2], d->lo, d->hi, res, NULL);
            for (size_t i = 0; st != 0 && i < nb; i++) { /* memory: every point failed */
                res[i].rc = 1;
                snprintf(res[i].why, sizeof res[i].why, "MPI rank %d: out of memory", d->rank);
            }
            m = (pk_mpi_msg){0, TAG_RES, 1, res, nb * sizeof *res, 0};
        } else if (op == OP_COMMIT) {
            st = pk_fe2_commit_block(pb, d->lo, d->hi);
            m = (pk_mpi_msg){0, TAG_ACK, 1, &st, sizeof st, 0};
        } else if (op == OP_CENTRES) {
            const size_t g = (size_t)d->cmd[1];
            if (g < d->lo || g >= d->hi) {
                snprintf(err, errlen, "rank %d asked for Gauss point %zu, holds %zu..%zu", d->rank,
                         g, d->lo, d->hi);
                break;
            }
            m = (pk_mpi_msg){
                0, TAG_CENTRES, 1, d->mr->committed[g].x, 3 * d->ngrain * sizeof(double), 0};
        } else {
            snprintf(err, errlen, "unknown command %d from rank 0", op);
            break;
        }
        if ((w = pk_mpi_exchange(&m, 1, d->cancel, d->deadline)) != PK_MPI_OK) {
            lost(d, w, &m, 1, "an answer", err, errlen);
            if (w == PK_MPI_CANCELLED)
                linger();
            break;
        }
    }
    free(res);
    return rc;
}

int pk_fe2_mpi_centres(pk_fe2_mpi *d, size_t g, double *x, char *err, size_t errlen)
{
    const size_t bytes = 3 * d->ngrain * sizeof *x;
    if (g >= d->lo && g < d->hi) {
        memcpy(x, d->mr->committed[g].x, bytes);
        return 0;
    }
    int r = 1;
    for (size_t lo, hi; r < d->size; r++) {
        block_of(d, r, &lo, &hi);
        if (g >= lo && g < hi)
            break;
    }
    pk_mpi_msg m[2] = {{r, TAG_CMD, 1, d->cmd, (2 + d->ndof) * sizeof *d->cmd, 0},
                       {r, TAG_CENTRES, 0, x, bytes, 0}};
    d->cmd[0] = OP_CENTRES, d->cmd[1] = (double)g;
    int rc = pk_mpi_exchange(m, 2, d->cancel, d->deadline);
    if (rc != PK_MPI_OK) {
        lost(d, rc, m, 2, "the output of a Gauss point's RVE", err, errlen);
        return -1;
    }
    d->bytes_in += bytes;
    return 0;
}

void pk_fe2_mpi_stop(pk_fe2_mpi *d)
{
    char why[256];
    if (d->rank == 0 && d->size > 1 && !d->broken)
        command(d, OP_STOP, 0, NULL, "the stop", why, sizeof why);
}

void pk_fe2_mpi_free(pk_fe2_mpi *d)
{
    free(d->cmd);
    memset(d, 0, sizeof *d);
}
