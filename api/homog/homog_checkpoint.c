/* homog_checkpoint.c — load-path checkpoints of 'homogenize' jobs
 * (api/homog/homog_checkpoint.h). */
#include "homog_checkpoint.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api/results/checkpoint_h5.h"
#include "api/results/h5_result.h"

#define G "checkpoint/"

enum {
    C_DONE,
    C_NOT_CONVERGED,
    C_TOTAL_ITER,
    C_MAX_ITER,
    C_HAVE_A,
    C_N,
    C_NCONTACT,
    C_NHIST,
    C_COUNT
};

int pk_homog_ckpt_save(const char *path, const char *digest, const pk_homog_ckpt *c,
                       const pk_homog_state *com, json_t *rec, char *err, size_t errlen)
{
    char *text = json_dumps(rec, JSON_COMPACT | JSON_REAL_PRECISION(17));
    double *u = calloc(com->n ? com->n : 1, sizeof *u);
    pk_h5 *h = text && u ? pk_h5_create(path, NULL, err, errlen) : NULL;
    if (!h) {
        if (!text || !u)
            snprintf(err, errlen, "out of memory for the checkpoint");
        free(text);
        free(u);
        return -1;
    }
    if (com->u)
        memcpy(u, com->u, com->n * sizeof *u);
    const int64_t cnt[C_COUNT] = {(int64_t)c->done,
                                  (int64_t)c->not_converged,
                                  (int64_t)c->total_iter,
                                  (int64_t)c->max_iter_step,
                                  c->have_A,
                                  (int64_t)com->n,
                                  (int64_t)com->ncontact,
                                  (int64_t)com->hist.n};
    int rc = pk_h5_obs_string(h, G "digest", digest);
    rc |= pk_h5_obs_ints(h, G "counters", cnt, C_COUNT);
    rc |= pk_h5_obs_doubles(h, G "F", com->F, 9, NULL);
    rc |= pk_h5_obs_doubles(h, G "A", c->A, 81, NULL);
    /* the step report as it is in memory: the digest names the packd version */
    rc |= pk_h5_obs_doubles(h, G "last_step", (const double *)&c->last,
                            sizeof c->last / sizeof(double), NULL);
    rc |= pk_h5_obs_doubles(h, G "x", com->x, 3 * com->n, NULL);
    rc |= pk_h5_obs_ints(h, G "keys", (const int64_t *)com->keys, com->ncontact);
    rc |= pk_h5_obs_doubles(h, G "u", u, com->n, NULL);
    rc |= pk_h5_obs_ints(h, G "hist_key", (const int64_t *)com->hist.key, com->hist.n);
    rc |= pk_h5_obs_doubles(h, G "hist_gamma", com->hist.gamma, com->hist.n, NULL);
    rc |= pk_h5_obs_doubles(h, G "hist_gamma_pl", com->hist.gamma_pl, com->hist.n, NULL);
    rc |= pk_h5_obs_doubles(h, G "hist_alpha", com->hist.alpha, com->hist.n, NULL);
    rc |= pk_h5_obs_string(h, G "record", text);
    free(text);
    free(u);
    if (rc) {
        snprintf(err, errlen, "cannot build the checkpoint %s", path);
        pk_h5_abort(h);
        return -1;
    }
    return pk_h5_commit(h, err, errlen);
}

_Static_assert(sizeof(pk_homog_step) % sizeof(double) == 0, "the step report is stored as doubles");

int pk_homog_ckpt_load(const char *path, const char *digest, pk_homog_ckpt *c, pk_homog_state *com,
                       json_t **rec, char *err, size_t errlen)
{
    int absent;
    hid_t f = pk_ckpt_open(path, digest, &absent, err, errlen);
    if (f < 0)
        return absent ? 1 : -1;
    int64_t cnt[C_COUNT];
    int rc = -1;
    pk_homog_ckpt in = {0};
    pk_homog_state s = {0};
    pk_fric_hist hist = {0};
    char *text = NULL;
    if (pk_ckpt_read(f, "counters", H5T_NATIVE_INT64, cnt, C_COUNT) != 0 ||
        cnt[C_N] != (int64_t)com->n || cnt[C_NCONTACT] < 0 || cnt[C_NHIST] < 0)
        goto bad;
    s.n = com->n;
    s.ncontact = (size_t)cnt[C_NCONTACT];
    hist.n = hist.cap = (size_t)cnt[C_NHIST];
    s.x = malloc((3 * s.n + 1) * sizeof *s.x);
    s.u = malloc((s.n + 1) * sizeof *s.u);
    s.keys = malloc((s.ncontact + 1) * sizeof *s.keys);
    hist.key = malloc((hist.n + 1) * sizeof *hist.key);
    hist.gamma = malloc((hist.n + 1) * sizeof *hist.gamma);
    hist.gamma_pl = malloc((hist.n + 1) * sizeof *hist.gamma_pl);
    hist.alpha = malloc((hist.n + 1) * sizeof *hist.alpha);
    if (!s.x || !s.u || !s.keys || !hist.key || !hist.gamma || !hist.gamma_pl || !hist.alpha ||
        pk_ckpt_read(f, "F", H5T_NATIVE_DOUBLE, s.F, 9) != 0 ||
        pk_ckpt_read(f, "A", H5T_NATIVE_DOUBLE, in.A, 81) != 0 ||
        pk_ckpt_read(f, "last_step", H5T_NATIVE_DOUBLE, &in.last,
                     sizeof in.last / sizeof(double)) != 0 ||
        pk_ckpt_read(f, "x", H5T_NATIVE_DOUBLE, s.x, 3 * s.n) != 0 ||
        pk_ckpt_read(f, "keys", H5T_NATIVE_INT64, s.keys, s.ncontact) != 0 ||
        pk_ckpt_read(f, "u", H5T_NATIVE_DOUBLE, s.u, s.n) != 0 ||
        pk_ckpt_read(f, "hist_key", H5T_NATIVE_INT64, hist.key, hist.n) != 0 ||
        pk_ckpt_read(f, "hist_gamma", H5T_NATIVE_DOUBLE, hist.gamma, hist.n) != 0 ||
        pk_ckpt_read(f, "hist_gamma_pl", H5T_NATIVE_DOUBLE, hist.gamma_pl, hist.n) != 0 ||
        pk_ckpt_read(f, "hist_alpha", H5T_NATIVE_DOUBLE, hist.alpha, hist.n) != 0 ||
        !(text = pk_ckpt_read_string(f, "record")))
        goto bad;
    json_t *r = json_loads(text, 0, NULL);
    if (!json_is_object(r)) {
        json_decref(r);
        goto bad;
    }
    s.hist = hist;
    memset(&hist, 0, sizeof hist); /* owned by s now */
    if (pk_homog_state_copy(com, &s) != 0) {
        json_decref(r);
        snprintf(err, errlen, "out of memory restoring %s", path);
        goto out;
    }
    in.done = (size_t)cnt[C_DONE];
    in.not_converged = (size_t)cnt[C_NOT_CONVERGED];
    in.total_iter = (size_t)cnt[C_TOTAL_ITER];
    in.max_iter_step = (size_t)cnt[C_MAX_ITER];
    in.have_A = (int)cnt[C_HAVE_A];
    *c = in;
    *rec = r;
    rc = 0;
    goto out;
bad:
    snprintf(err, errlen, "checkpoint %s is incomplete or of another RVE", path);
out:
    free(text);
    pk_homog_state_free(&s);
    pk_fric_hist_free(&hist);
    H5Fclose(f);
    return rc;
}
