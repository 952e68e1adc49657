/* test_config.c — daemon/config.c: defaults, file syntax and errors with
 * line numbers, environment overrides, flag precedence (exact values: no
 * tolerance). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "daemon/http/auth.h"
#include "check.h"
#include "daemon/config.h"

static char path[] = "/tmp/pk_config_XXXXXX";

static void write_file(const char *text)
{
    FILE *f = fopen(path, "w");
    fputs(text, f);
    fclose(f);
}

static void test_defaults(void)
{
    pk_config c;
    pk_config_defaults(&c);
    CHECK(!strcmp(c.bind, "127.0.0.1") && c.port == 8080 && !strcmp(c.data, "var"));
    CHECK(c.workers >= 1 && c.log_level == PK_LOG_INFO && c.max_attempts == 3);
}

static void test_file(void)
{
    pk_config c;
    char err[512];
    pk_config_defaults(&c);
    write_file(
        "# comment\n\nport = 9000   # trailing comment\nbind=0.0.0.0\ndata = \"/srv/packd\"\n"
        "workers = 4\nmax_wall_time_s = 3600.5\nlog_level = debug\n");
    CHECK(pk_config_load_file(&c, path, err, sizeof err) == 0);
    CHECK(c.port == 9000 && !strcmp(c.bind, "0.0.0.0") && !strcmp(c.data, "/srv/packd"));
    CHECK(c.workers == 4 && c.max_wall_time_s == 3600.5 && c.log_level == PK_LOG_DEBUG);
    CHECK(!strcmp(c.config_file, path));
}

static void test_file_errors(void)
{
    pk_config c;
    char err[512];
    pk_config_defaults(&c);
    write_file("port = 9000\nno equals sign\n");
    CHECK(pk_config_load_file(&c, path, err, sizeof err) == -1);
    CHECK_MSG(strstr(err, ":2:") != NULL, "%s", err);
    write_file("colour = blue\n");
    CHECK(pk_config_load_file(&c, path, err, sizeof err) == -1 && strstr(err, "unknown key"));
    const char *bad[] = {"port = 70000\n", "port = 80.5\n",      "workers = -1\n",
                         "port = 8x\n",    "log_level = loud\n", "max_wall_time_s = nan\n"};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        write_file(bad[i]);
        CHECK_MSG(pk_config_load_file(&c, path, err, sizeof err) == -1, "%s accepted", bad[i]);
    }
    CHECK(pk_config_load_file(&c, "/nonexistent/packd.conf", err, sizeof err) == -1);
}

static void test_precedence(void)
{
    pk_config c;
    char err[512];
    write_file("port = 9000\nworkers = 2\nmax_queued = 7\n");
    setenv("PACKD_PORT", "9100", 1);
    setenv("PACKD_WORKERS", "3", 1);
    char *argv[] = {"serve", "--config", path, "--port", "9200", "--max-queued-per-owner",
                    "5",     NULL};
    CHECK(pk_config_from_args(&c, 7, argv, err, sizeof err) == 0);
    CHECK(c.port == 9200);              /* flag over env over file */
    CHECK(c.workers == 3);              /* env over file */
    CHECK(c.max_queued == 7);           /* file over default */
    CHECK(c.max_queued_per_owner == 5); /* dashes map to underscores */
    setenv("PACKD_WORKERS", "many", 1);
    CHECK(pk_config_from_args(&c, 7, argv, err, sizeof err) == -1 && strstr(err, "PACKD_WORKERS"));
    unsetenv("PACKD_PORT");
    unsetenv("PACKD_WORKERS");
    char *bad[] = {"serve", "--colour", "blue", NULL};
    CHECK(pk_config_from_args(&c, 3, bad, err, sizeof err) == -1);
    char *missing[] = {"serve", "--port", NULL};
    CHECK(pk_config_from_args(&c, 2, missing, err, sizeof err) == -1);
    char *help[] = {"serve", "--help", NULL};
    CHECK(pk_config_from_args(&c, 2, help, err, sizeof err) == 1);
}

/* The documented example in deploy/ parses and sets every key it shows. */
static void test_example_file(void)
{
    const char *src = getenv("PACKD_SRC");
    char file[1024], err[512];
    snprintf(file, sizeof file, "%s/deploy/packd.conf.example", src ? src : ".");
    pk_config c;
    pk_config_defaults(&c);
    CHECK_MSG(pk_config_load_file(&c, file, err, sizeof err) == 0, "%s", err);
    CHECK(!strcmp(c.data, "/var/lib/packd") && c.workers == 4 && c.grace_s == 30);
}

/* auth = auto|on|off and trusted_proxy; auto is on exactly off loopback. */
static void test_auth_keys(void)
{
    pk_config c;
    char err[256];
    pk_config_defaults(&c);
    CHECK(c.auth == PK_AUTH_AUTO && c.trusted_proxy[0] == 0);
    CHECK(!pk_auth_required(&c, NULL)); /* 127.0.0.1: the make run default stays open */
    const char *why = NULL;
    CHECK(pk_config_set(&c, "bind", "10.1.2.3", err, sizeof err) == 0 &&
          pk_auth_required(&c, &why) && why);
    CHECK(pk_config_set(&c, "bind", "0.0.0.0", err, sizeof err) == 0 && pk_auth_required(&c, NULL));
    CHECK(pk_config_set(&c, "bind", "127.8.0.1", err, sizeof err) == 0 &&
          !pk_auth_required(&c, NULL));
    CHECK(pk_config_set(&c, "bind", "::1", err, sizeof err) == 0 && !pk_auth_required(&c, NULL));
    CHECK(pk_config_set(&c, "auth", "on", err, sizeof err) == 0 && c.auth == PK_AUTH_ON &&
          pk_auth_required(&c, NULL));
    CHECK(pk_config_set(&c, "bind", "0.0.0.0", err, sizeof err) == 0);
    CHECK(pk_config_set(&c, "auth", "off", err, sizeof err) == 0 && !pk_auth_required(&c, NULL));
    CHECK(pk_config_set(&c, "auth", "yes", err, sizeof err) == -1 && strstr(err, "auto on off"));
    CHECK(pk_config_set(&c, "trusted_proxy", "10.0.0.7", err, sizeof err) == 0 &&
          !strcmp(c.trusted_proxy, "10.0.0.7"));
    CHECK(pk_config_set(&c, "trusted_proxy", "0:0::1", err, sizeof err) == 0 &&
          !strcmp(c.trusted_proxy, "::1"));
    CHECK(pk_config_set(&c, "trusted_proxy", "proxy.lab", err, sizeof err) == -1);
    CHECK(pk_config_set(&c, "trusted_proxy", "10.0.0.256", err, sizeof err) == -1);
    setenv("PACKD_AUTH", "on", 1);
    CHECK(pk_config_load_env(&c, err, sizeof err) == 0 && c.auth == PK_AUTH_ON);
    unsetenv("PACKD_AUTH");
}

int main(void)
{
    int fd = mkstemp(path);
    if (fd >= 0)
        close(fd);
    unsetenv("PACKD_CONFIG");
    RUN(test_defaults);
    RUN(test_file);
    RUN(test_file_errors);
    RUN(test_precedence);
    RUN(test_example_file);
    RUN(test_auth_keys);
    unlink(path);
    return check_summary();
}
