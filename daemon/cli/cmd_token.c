/* cmd_token.c — `packd token add NAME [--admin] | list | revoke NAME`: the
 * bearer tokens of the job service (daemon/store/tokens.h).  The data directory
 * comes from the same settings as `packd serve` (--data, --config,
 * PACKD_DATA, PACKD_CONFIG), and a running daemon sees a change at once. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"
#include "daemon/config.h"
#include "daemon/store/tokens.h"

static const struct {
    const char *name, *args, *help;
} subs[] = {
    {"add", "NAME [--admin]",
     "Make a token acting as NAME (the owner of the jobs and uploads it sends) and print it once\n"
     "on stdout; only its SHA-256 is stored.  --admin: the token sees and dismisses every owner's\n"
     "jobs and reads /metrics.  Clients send it as `Authorization: Bearer TOKEN`; by convention\n"
     "they read it from the environment variable PACKD_TOKEN."},
    {"list", "", "Print each token's name, admin flag, creation and last use (never the token)."},
    {"revoke", "NAME",
     "Delete NAME's token: requests with it get 401 from now on.  NAME's jobs stay;\n"
     "`packd token add NAME` again gives NAME a new token to them."},
};

static int usage(FILE *f, int sub)
{
    for (size_t i = 0; i < sizeof subs / sizeof *subs; i++) {
        if (sub >= 0 && (size_t)sub != i)
            continue;
        fprintf(f, "usage: packd token %s%s%s [--config FILE] [--data DIR]\n", subs[i].name,
                *subs[i].args ? " " : "", subs[i].args);
        if (sub >= 0)
            fprintf(f, "%s\n", subs[i].help);
    }
    if (sub >= 0)
        fprintf(f,
                "The database is DIR/queue.db of `packd serve --data DIR` (same --config, "
                "PACKD_DATA).\n");
    return f == stderr ? 64 : 0;
}

static void iso_time(double t, char *out, size_t n)
{
    time_t s = (time_t)t;
    struct tm tm;
    if (gmtime_r(&s, &tm))
        strftime(out, n, "%Y-%m-%dT%H:%M:%SZ", &tm);
    else
        snprintf(out, n, "-");
}

static int list(pk_tokens *t)
{
    json_t *a = pk_tokens_list(t);
    printf("%-24s %-5s %-20s %s\n", "NAME", "ADMIN", "CREATED", "LAST_USED");
    size_t i;
    json_t *row;
    json_array_foreach (a, i, row) {
        char created[32], used[32] = "never";
        iso_time(json_number_value(json_object_get(row, "created")), created, sizeof created);
        json_t *lu = json_object_get(row, "last_used");
        if (json_is_number(lu))
            iso_time(json_number_value(lu), used, sizeof used);
        printf("%-24s %-5s %-20s %s\n", json_string_value(json_object_get(row, "name")),
               json_is_true(json_object_get(row, "admin")) ? "yes" : "no", created, used);
    }
    json_decref(a);
    return 0;
}

int cmd_token(int argc, char **argv)
{
    if (argc < 2)
        return usage(stderr, -1);
    int sub = -1;
    for (size_t i = 0; i < sizeof subs / sizeof *subs; i++)
        if (!strcmp(argv[1], subs[i].name))
            sub = (int)i;
    if (sub < 0)
        return usage(strcmp(argv[1], "-h") && strcmp(argv[1], "--help") ? stderr : stdout, -1);
    /* NAME and --admin here; the rest are `packd serve` settings (for data). */
    const char *name = NULL;
    int admin = 0;
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    int nrest = 0;
    rest[nrest++] = argv[0];
    for (int i = 2; i < argc; i++) {
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help")) {
            free(rest);
            return usage(stdout, sub);
        }
        if (!strcmp(argv[i], "--admin") && sub == 0)
            admin = 1;
        else if (argv[i][0] != '-' && !name && sub != 1)
            name = argv[i];
        else if (argv[i][0] == '-' && i + 1 < argc)
            rest[nrest++] = argv[i], rest[nrest++] = argv[++i];
        else
            rest[nrest++] = argv[i]; /* refused below with the option's name */
    }
    pk_config cfg;
    char err[1200];
    int rc = pk_config_from_args(&cfg, nrest, rest, err, sizeof err);
    free(rest);
    if (rc != 0 || (sub != 1 && !name)) {
        fprintf(stderr, "packd token %s: %s\n", subs[sub].name, rc ? err : "needs a NAME");
        return usage(stderr, sub);
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/queue.db", cfg.data);
    if (mkdir(cfg.data, 0750) != 0 && errno != EEXIST) {
        fprintf(stderr, "packd token: %s: %s\n", cfg.data, strerror(errno));
        return 2;
    }
    pk_tokens *t = pk_tokens_open(path, err, sizeof err);
    if (!t) {
        fprintf(stderr, "packd token: %s\n", err);
        return 2;
    }
    rc = 0;
    if (sub == 0) {
        char token[PK_TOKEN_LEN + 1];
        if (pk_tokens_add(t, name, admin, token, err, sizeof err) != 0) {
            fprintf(stderr, "packd token add: %s\n", err);
            rc = 1;
        } else {
            printf("%s\n", token);
            fprintf(stderr,
                    "packd token add: %s token for '%s' in %s — shown this once; keep it as "
                    "PACKD_TOKEN\n",
                    admin ? "an admin" : "a", name, path);
        }
    } else if (sub == 1) {
        rc = list(t);
    } else {
        int n = pk_tokens_revoke(t, name);
        if (n < 0)
            fprintf(stderr, "packd token revoke: the database refused the change\n");
        else if (n == 0)
            fprintf(stderr, "packd token revoke: no token named '%s'\n", name);
        else
            fprintf(stderr, "packd token revoke: '%s' revoked\n", name);
        rc = n < 0 ? 2 : n == 0 ? 1 : 0;
    }
    pk_tokens_close(t);
    return rc;
}
