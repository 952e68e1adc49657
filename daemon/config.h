/* config.h — the daemon's configuration: embedded defaults, then a config
 * file (`key = value` lines, '#' comments), then environment variables
 * PACKD_<KEY>, then command-line flags --<key-with-dashes> VALUE.
 * One table of keys (config.c) drives all four, and deploy/packd.conf.example
 * documents each key. */
#ifndef PK_CONFIG_H
#define PK_CONFIG_H

#include <stddef.h>

typedef enum { PK_LOG_DEBUG, PK_LOG_INFO, PK_LOG_WARN, PK_LOG_ERROR } pk_log_level;
/* auto: on unless bind is a loopback address and no trusted proxy is configured */
typedef enum { PK_AUTH_AUTO, PK_AUTH_ON, PK_AUTH_OFF } pk_auth_mode;
/* where jobs run (daemon/executor.h) */
typedef enum { PK_EXECUTOR_LOCAL, PK_EXECUTOR_SLURM } pk_executor_kind;

typedef struct pk_config {
    char bind[64]; /* listen address (IPv4 dotted quad) */
    char public_url
        [256]; /* base of absolute links, e.g. https://packd.lab.example; "" = from Host */
    int port;
    char data[1024]; /* data directory: queue.db, jobs/, files/ */
    char input_dir
        [1024]; /* "" = requests name no server path; else the directory they may name files in */
    long input_max_bytes;       /* largest file a request may name in input_dir */
    int workers;                /* concurrent worker processes */
    int job_threads;            /* threads of each job's parallel sections (same results for any) */
    int worker_nice;            /* niceness of local workers: the HTTP loops get a core first */
    long max_body_bytes;        /* largest request body (POST /files, /execution) */
    long max_particles;         /* cap on limits.max_particles of each job */
    double max_wall_time_s;     /* cap on limits.wall_time_s; the worker is killed 30 s after */
    int max_queued;             /* accepted (waiting) jobs in total; beyond: 503 */
    int max_queued_per_owner;   /* accepted jobs per owner; beyond: 429 */
    int max_attempts;           /* runs of one job interrupted by daemon deaths before it fails */
    double grace_s;             /* SIGTERM: time running jobs get to finish */
    int http_threads;           /* HTTP event-loop threads (epoll each) */
    int max_connections;        /* open HTTP connections in total */
    int max_connections_per_ip; /* open HTTP connections of one client address (0: no limit) */
    int idle_timeout_s;    /* a connection silent this long is closed (headers, body, keep-alive) */
    double head_timeout_s; /* a request head must arrive within this time (new or kept-alive) */
    double body_timeout_s; /* a request body must arrive within this time after its headers */
    double
        body_min_rate; /* bytes/s: a body of n bytes gets head_timeout_s + n / this (≤ body_timeout_s) */
    double sync_wait_s;            /* Prefer: respond-sync waits this long for the job, then 201 */
    double result_cache_max_age_s; /* reuse an equal successful job this young (0: never) */
    double
        checkpoint_interval_s; /* between two checkpoints of a long job (job dir checkpoint.h5) */
    pk_log_level log_level;
    pk_auth_mode auth;       /* bearer tokens required (daemon/http/auth.c) */
    char trusted_proxy[64];  /* peer whose X-Packd-Owner is honoured; "" = none */
    char allowed_hosts[512]; /* Host header names accepted, comma-separated ("" = this machine's) */
    char callback_allow[512];  /* private/loopback addresses callbacks may reach, comma-separated */
    char cors_origins[512];    /* origins browsers may call from, comma-separated ("" = CORS off) */
    pk_executor_kind executor; /* local workers or a Slurm cluster */
    char slurm_partition[64];  /* sbatch --partition; "" = the cluster's default */
    char slurm_account[64];    /* sbatch --account; "" = the user's default */
    char slurm_qos[64];        /* sbatch --qos; "" = the default */
    char slurm_options[512];   /* more sbatch options, split at blanks */
    char slurm_packd[1024];    /* packd on the nodes; "" = this binary's path */
    int slurm_mem_mb;          /* MB per job (per rank of an MPI job); 0 = the default */
    char slurm_mpi[32];        /* srun --mpi of a job of several ranks (pmix) */
    int slurm_max_jobs;        /* jobs on Slurm at once (submitted, not ended) */
    double slurm_local_below_s; /* limits.wall_time_s at most this: run locally (0 = never) */
    char config_file[1024];     /* the file read, "" if none (kept for SIGHUP) */
} pk_config;

/* Embedded defaults: 127.0.0.1:8080, data ./var, workers = online cores. */
void pk_config_defaults(pk_config *c);

/* Set one key from text; 0 on success, -1 with a message in err. */
int pk_config_set(pk_config *c, const char *key, const char *value, char *err, size_t errlen);

/* Read a config file; 0 on success, -1 with "file:line: message" in err. */
int pk_config_load_file(pk_config *c, const char *path, char *err, size_t errlen);

/* Apply PACKD_<KEY> variables from the environment; -1 with err on a bad value. */
int pk_config_load_env(pk_config *c, char *err, size_t errlen);

/* Full load for `packd serve ARGS`: defaults, --config file (or $PACKD_CONFIG),
 * env, flags.  Returns 0, -1 with err on an error, 1 for --help. */
int pk_config_from_args(pk_config *c, int argc, char **argv, char *err, size_t errlen);

const char *pk_log_level_name(pk_log_level l);
const char *pk_executor_kind_name(pk_executor_kind k);

/* Print the keys with their defaults (for --help). */
void pk_config_print_keys(void *file);

#endif
