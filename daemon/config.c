/* config.c — the daemon's configuration: one key table, defaults, file, env, flags.
 * Contract: daemon/config.h. */
#include "config.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

typedef enum { K_STR, K_INT, K_LONG, K_DOUBLE, K_LEVEL, K_AUTH, K_ADDR, K_EXEC } key_type;

/* Keys whose value is one of some names (stored as the enum's int). */
static const char *const level_names[] = {"debug", "info", "warn", "error", NULL};
static const char *const auth_names[] = {"auto", "on", "off", NULL};
static const char *const executor_names[] = {"local", "slurm", NULL};
_Static_assert(sizeof(pk_auth_mode) == sizeof(int) && sizeof(pk_log_level) == sizeof(int) &&
                   sizeof(pk_executor_kind) == sizeof(int),
               "named values are stored as int");

static const char *const *names_of(key_type t)
{
    return t == K_LEVEL ? level_names
        : t == K_AUTH   ? auth_names
        : t == K_EXEC   ? executor_names
                        : NULL;
}

static const struct key {
    const char *name;
    key_type type;
    size_t off, size;
    double lo, hi; /* range of numbers */
    const char *help;
} keys[] = {
#define F(m) offsetof(pk_config, m), sizeof(((pk_config *)0)->m)
    {"bind", K_STR, F(bind), 0, 0, "listen address"},
    {"port", K_INT, F(port), 0, 65535, "TCP port (0 = any free port)"},
    {"data", K_STR, F(data), 0, 0, "data directory"},
    {"input_dir", K_STR, F(input_dir), 0, 0,
     "directory whose files jobs may name by path (unset: uploads and results only)"},
    {"input_max_bytes", K_LONG, F(input_max_bytes), 1, 1e13,
     "largest file a job may name in input_dir"},
    {"workers", K_INT, F(workers), 0, 1024,
     "concurrent worker processes (0 = accept but run nothing)"},
    {"job_threads", K_INT, F(job_threads), 1, 64,
     "threads of each job's parallel sections (the results are the same for any)"},
    {"worker_nice", K_INT, F(worker_nice), 0, 19,
     "niceness of local worker processes: the HTTP loops get a core before busy workers"},
    {"max_body_bytes", K_LONG, F(max_body_bytes), 1024, 1e12, "largest request body"},
    {"max_particles", K_LONG, F(max_particles), 1, 1e12, "cap on a job's limits.max_particles"},
    {"max_wall_time_s", K_DOUBLE, F(max_wall_time_s), 1, 1e9, "cap on a job's limits.wall_time_s"},
    {"max_queued", K_INT, F(max_queued), 1, 1e9, "waiting jobs in total (beyond: 503)"},
    {"max_queued_per_owner", K_INT, F(max_queued_per_owner), 1, 1e9,
     "waiting jobs per owner (beyond: 429)"},
    {"max_attempts", K_INT, F(max_attempts), 1, 100,
     "starts of one job before an interrupted job fails"},
    {"checkpoint_interval_s", K_DOUBLE, F(checkpoint_interval_s), 0.1, 1e6,
     "wall seconds between checkpoints of a long EDMD job (resumed after a restart)"},
    {"grace_s", K_DOUBLE, F(grace_s), 0, 86400, "SIGTERM: time running jobs get to finish"},
    {"http_threads", K_INT, F(http_threads), 1, 64, "HTTP event-loop threads (restart to change)"},
    {"max_connections", K_INT, F(max_connections), 16, 1000000,
     "open HTTP connections in total (restart to change)"},
    {"max_connections_per_ip", K_INT, F(max_connections_per_ip), 0, 1000000,
     "open HTTP connections per client address, 0 = no limit (restart to change)"},
    {"idle_timeout_s", K_INT, F(idle_timeout_s), 1, 86400,
     "close a connection silent this long (restart to change)"},
    {"sync_wait_s", K_DOUBLE, F(sync_wait_s), 0, 300,
     "Prefer: respond-sync: seconds an execute request waits for its job (then 201 async)"},
    {"result_cache_max_age_s", K_DOUBLE, F(result_cache_max_age_s), 0, 1e10,
     "answer a request from the owner's successful job with equal inputs (and seed) that "
     "finished at most this long ago (0 = never; the request's Cache-Control: no-cache runs it)"},
    {"head_timeout_s", K_DOUBLE, F(head_timeout_s), 0.5, 3600,
     "seconds a request head may take, from the connection or the previous response (beyond: "
     "closed)"},
    {"body_timeout_s", K_DOUBLE, F(body_timeout_s), 1, 86400,
     "most seconds a request body may take after its head (beyond: connection closed)"},
    {"body_min_rate", K_DOUBLE, F(body_min_rate), 1, 1e12,
     "bytes/s: a body of n bytes must arrive within head_timeout_s + n / body_min_rate"},
    {"log_level", K_LEVEL, F(log_level), 0, 0, "debug | info | warn | error"},
    {"public_url", K_STR, F(public_url), 0, 0,
     "base URL of absolute links (reverse proxy); unset: http://<Host header>"},
    {"auth", K_AUTH, F(auth), 0, 0,
     "bearer tokens required: auto (on unless bind is loopback without trusted_proxy) | on | off"},
    {"allowed_hosts", K_STR, F(allowed_hosts), 0, 0,
     "Host names requests may carry, comma-separated, * = any (unset: bind address, localhost, "
     "this machine's names and addresses, public_url's host); others get 421"},
    {"callback_allow", K_STR, F(callback_allow), 0, 0,
     "addresses a subscriber callback may reach though private or loopback, comma-separated "
     "(\"\" = public addresses only)"},
    {"cors_origins", K_STR, F(cors_origins), 0, 0,
     "origins whose pages may call the API from a browser (CORS), comma-separated "
     "scheme://host[:port], * = any (unset: none)"},
    {"trusted_proxy", K_ADDR, F(trusted_proxy), 0, 0,
     "address of the reverse proxy whose X-Packd-Owner is honoured"},
    {"executor", K_EXEC, F(executor), 0, 0,
     "where jobs run: local (forked workers) | slurm (sbatch; docs/scale-out.md)"},
    {"slurm_partition", K_STR, F(slurm_partition), 0, 0, "sbatch --partition (unset: default)"},
    {"slurm_account", K_STR, F(slurm_account), 0, 0, "sbatch --account (unset: default)"},
    {"slurm_qos", K_STR, F(slurm_qos), 0, 0, "sbatch --qos (unset: default)"},
    {"slurm_options", K_STR, F(slurm_options), 0, 0,
     "more sbatch options, split at blanks (e.g. --constraint=avx2)"},
    {"slurm_packd", K_STR, F(slurm_packd), 0, 0,
     "path of packd on the compute nodes (unset: this binary's path)"},
    {"slurm_mem_mb", K_INT, F(slurm_mem_mb), 0, 1e8,
     "memory of each job in MB, of each rank for an fe2 job of several (0: the partition's "
     "default)"},
    {"slurm_mpi", K_STR, F(slurm_mpi), 0, 0,
     "srun --mpi plugin that starts the MPI ranks of an fe2 job asking for several "
     "(srun --mpi=list on a node)"},
    {"slurm_max_jobs", K_INT, F(slurm_max_jobs), 1, 1e6,
     "jobs submitted to Slurm and not yet ended, at most"},
    {"slurm_local_below_s", K_DOUBLE, F(slurm_local_below_s), 0, 1e9,
     "jobs with limits.wall_time_s at most this run on local workers (0: none)"},
#undef F
};

const char *pk_log_level_name(pk_log_level l)
{
    return l >= PK_LOG_DEBUG && l <= PK_LOG_ERROR ? level_names[l] : "info";
}

const char *pk_executor_kind_name(pk_executor_kind k)
{
    return k == PK_EXECUTOR_SLURM ? "slurm" : "local";
}

void pk_config_defaults(pk_config *c)
{
    memset(c, 0, sizeof *c);
    snprintf(c->bind, sizeof c->bind, "127.0.0.1");
    c->port = 8080;
    snprintf(c->data, sizeof c->data, "var");
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    c->workers = n > 0 ? (int)n : 1;
    c->job_threads = 1; /* the workers take the cores already */
    c->max_body_bytes = 16L << 20;
    c->input_max_bytes = 1L << 30;
    c->max_particles = 20000000;
    c->max_wall_time_s = 86400;
    c->max_queued = 1000;
    c->max_queued_per_owner = 100;
    c->max_attempts = 3;
    c->grace_s = 30;
    c->http_threads = 4;
    c->max_connections = 4096;
    c->max_connections_per_ip = 128;
    c->idle_timeout_s = 20;
    c->head_timeout_s = 10;
    c->body_timeout_s = 120;
    c->body_min_rate = 65536;
    c->sync_wait_s = 10;
    c->checkpoint_interval_s = 30;
    c->log_level = PK_LOG_INFO;
    c->slurm_max_jobs = 1000;
    snprintf(c->slurm_mpi, sizeof c->slurm_mpi, "pmix"); /* Debian's OpenMPI starts under it */
}

static const struct key *find_key(const char *name)
{
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++)
        if (!strcmp(keys[i].name, name))
            return &keys[i];
    return NULL;
}

int pk_config_set(pk_config *c, const char *key, const char *value, char *err, size_t errlen)
{
    const struct key *k = find_key(key);
    if (!k) {
        snprintf(err, errlen, "unknown key '%s'", key);
        return -1;
    }
    char *field = (char *)c + k->off;
    if (k->type == K_STR) {
        if (!*value || strlen(value) >= k->size) {
            snprintf(err, errlen, "%s: empty or too long", key);
            return -1;
        }
        memcpy(field, value, strlen(value) + 1);
        return 0;
    }
    const char *const *names = names_of(k->type);
    if (names) {
        for (int i = 0; names[i]; i++)
            if (!strcmp(value, names[i])) {
                *(int *)field = i;
                return 0;
            }
        snprintf(err, errlen, "%s: '%s' is not one of", key, value);
        for (int i = 0; names[i]; i++)
            snprintf(err + strlen(err), errlen - strlen(err), " %s", names[i]);
        return -1;
    }
    if (k->type == K_ADDR) { /* an IPv4 or IPv6 address, kept as inet_ntop prints it */
        unsigned char a[16];
        int fam = strchr(value, ':') ? AF_INET6 : AF_INET;
        if (inet_pton(fam, value, a) != 1 || !inet_ntop(fam, a, field, (socklen_t)k->size)) {
            snprintf(err, errlen, "%s: '%s' is not an IP address", key, value);
            return -1;
        }
        return 0;
    }
    char *end;
    errno = 0;
    double v = strtod(value, &end);
    if (end == value || *end || errno || !isfinite(v) || v < k->lo || v > k->hi ||
        (k->type != K_DOUBLE && v != floor(v))) {
        snprintf(err, errlen, "%s: '%s' is not a%s number in [%g, %g]", key, value,
                 k->type == K_DOUBLE ? "" : "n integer", k->lo, k->hi);
        return -1;
    }
    if (k->type == K_INT)
        *(int *)field = (int)v;
    else if (k->type == K_LONG)
        *(long *)field = (long)v;
    else
        *(double *)field = v;
    return 0;
}

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    char *e = s + strlen(s);
    while (e > s && isspace((unsigned char)e[-1]))
        *--e = 0;
    return s;
}

int pk_config_load_file(pk_config *c, const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return -1;
    }
    char line[2048], msg[512];
    int lineno = 0, rc = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = 0;
        char *s = trim(line);
        if (!*s)
            continue;
        char *eq = strchr(s, '=');
        if (!eq) {
            snprintf(err, errlen, "%s:%d: expected 'key = value'", path, lineno);
            rc = -1;
            break;
        }
        *eq = 0;
        char *key = trim(s), *value = trim(eq + 1);
        size_t vl = strlen(value);
        if (vl >= 2 && value[0] == '"' && value[vl - 1] == '"') {
            value[vl - 1] = 0;
            value++;
        }
        if (pk_config_set(c, key, value, msg, sizeof msg) != 0) {
            snprintf(err, errlen, "%s:%d: %s", path, lineno, msg);
            rc = -1;
            break;
        }
    }
    fclose(f);
    if (rc == 0)
        snprintf(c->config_file, sizeof c->config_file, "%s", path);
    return rc;
}

int pk_config_load_env(pk_config *c, char *err, size_t errlen)
{
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++) {
        char var[64], msg[512];
        size_t j = 0;
        j += (size_t)snprintf(var, sizeof var, "PACKD_");
        for (const char *p = keys[i].name; *p && j + 1 < sizeof var; p++)
            var[j++] = (char)toupper((unsigned char)*p);
        var[j] = 0;
        const char *v = getenv(var);
        if (v && pk_config_set(c, keys[i].name, v, msg, sizeof msg) != 0) {
            snprintf(err, errlen, "%s: %s", var, msg);
            return -1;
        }
    }
    return 0;
}

/* "--max-body-bytes" -> "max_body_bytes"; NULL if not a flag. */
static const char *flag_key(const char *arg, char *buf, size_t n)
{
    if (strncmp(arg, "--", 2) != 0 || strlen(arg + 2) >= n)
        return NULL;
    size_t i = 0;
    for (const char *p = arg + 2; *p; p++)
        buf[i++] = *p == '-' ? '_' : *p;
    buf[i] = 0;
    return buf;
}

int pk_config_from_args(pk_config *c, int argc, char **argv, char *err, size_t errlen)
{
    pk_config_defaults(c);
    const char *file = getenv("PACKD_CONFIG");
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help"))
            return 1;
        if (!strcmp(argv[i], "--config")) {
            if (i + 1 >= argc) {
                snprintf(err, errlen, "--config needs a file");
                return -1;
            }
            file = argv[++i];
        }
    }
    if (file && *file && pk_config_load_file(c, file, err, errlen) != 0)
        return -1;
    if (pk_config_load_env(c, err, errlen) != 0)
        return -1;
    for (int i = 1; i < argc; i++) {
        char kb[64], msg[512];
        if (!strcmp(argv[i], "--config")) {
            i++;
            continue;
        }
        const char *key = flag_key(argv[i], kb, sizeof kb);
        if (!key || !find_key(key)) {
            snprintf(err, errlen, "unknown option '%s'", argv[i]);
            return -1;
        }
        if (i + 1 >= argc) {
            snprintf(err, errlen, "%s needs a value", argv[i]);
            return -1;
        }
        if (pk_config_set(c, key, argv[++i], msg, sizeof msg) != 0) {
            snprintf(err, errlen, "%s", msg);
            return -1;
        }
    }
    return 0;
}

void pk_config_print_keys(void *file)
{
    pk_config d;
    pk_config_defaults(&d);
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++) {
        const struct key *k = &keys[i];
        const char *field = (const char *)&d + k->off;
        char def[128];
        switch (k->type) {
        case K_STR: snprintf(def, sizeof def, "%s", field); break;
        case K_INT: snprintf(def, sizeof def, "%d", *(const int *)field); break;
        case K_LONG: snprintf(def, sizeof def, "%ld", *(const long *)field); break;
        case K_DOUBLE: snprintf(def, sizeof def, "%g", *(const double *)field); break;
        case K_LEVEL:
        case K_AUTH:
        case K_EXEC: snprintf(def, sizeof def, "%s", names_of(k->type)[*(const int *)field]); break;
        case K_ADDR: snprintf(def, sizeof def, "%s", *field ? field : "none"); break;
        }
        char flag[64];
        size_t j = 0;
        for (const char *p = k->name; *p && j + 1 < sizeof flag; p++)
            flag[j++] = *p == '_' ? '-' : *p;
        flag[j] = 0;
        fprintf(file, "  --%-22s %s (default %s)\n", flag, k->help, def);
    }
}
