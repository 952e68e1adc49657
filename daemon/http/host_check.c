/* host_check.c — the allowed Host names.  Contract: daemon/http/host_check.h. */
#include "host_check.h"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#define MAX_NAMES 64
#define NAME_LEN 256

/* The list built from the configuration it was built for (rebuilt when
 * allowed_hosts, bind or public_url change, e.g. on SIGHUP). */
static struct {
    pthread_mutex_t mu;
    char key[sizeof((pk_config *)0)->allowed_hosts + 64 + 256];
    char names[MAX_NAMES][NAME_LEN];
    int n, any, built;
} L = {.mu = PTHREAD_MUTEX_INITIALIZER};

static void add(const char *s, size_t len)
{
    while (len && (*s == ' ' || *s == '\t'))
        s++, len--;
    while (len && (s[len - 1] == ' ' || s[len - 1] == '\t'))
        len--;
    if (len == 1 && *s == '*')
        L.any = 1;
    if (!len || len >= NAME_LEN || L.n == MAX_NAMES)
        return;
    memcpy(L.names[L.n], s, len);
    L.names[L.n++][len] = 0;
}

/* The host of a URL "scheme://host[:port]/..." */
static void add_url_host(const char *url)
{
    const char *p = strstr(url, "://");
    if (!p)
        return;
    p += 3;
    size_t n = *p == '[' ? strcspn(p, "]") + 1 : strcspn(p, ":/");
    add(*p == '[' ? p + 1 : p, *p == '[' ? n - 2 : n);
}

static void build(const pk_config *cfg)
{
    L.n = L.any = 0;
    if (cfg->allowed_hosts[0]) {
        for (const char *p = cfg->allowed_hosts; *p;) {
            size_t n = strcspn(p, ",");
            add(p, n);
            p += n + (p[n] == ',');
        }
        return;
    }
    if (strcmp(cfg->bind, "0.0.0.0") != 0)
        add(cfg->bind, strlen(cfg->bind));
    add("localhost", 9);
    add("127.0.0.1", 9);
    add("::1", 3);
    char host[NAME_LEN];
    if (gethostname(host, sizeof host) == 0) {
        host[sizeof host - 1] = 0;
        add(host, strlen(host));
        add(host, strcspn(host, ".")); /* the short name */
    }
    struct ifaddrs *ifs;
    if (getifaddrs(&ifs) == 0) {
        for (struct ifaddrs *i = ifs; i; i = i->ifa_next) {
            char a[INET6_ADDRSTRLEN];
            const struct sockaddr *sa = i->ifa_addr;
            if (sa && sa->sa_family == AF_INET &&
                inet_ntop(AF_INET, &((const struct sockaddr_in *)sa)->sin_addr, a, sizeof a))
                add(a, strlen(a));
            else if (sa && sa->sa_family == AF_INET6 &&
                     inet_ntop(AF_INET6, &((const struct sockaddr_in6 *)sa)->sin6_addr, a,
                               sizeof a))
                add(a, strlen(a));
        }
        freeifaddrs(ifs);
    }
    add_url_host(cfg->public_url);
}

int pk_host_allowed(const pk_config *cfg, const char *host)
{
    if (!host)
        return 1;
    /* the name without its port: "name:8080", "[::1]:8080" */
    char name[NAME_LEN];
    size_t n = host[0] == '[' ? strcspn(host + 1, "]") : strcspn(host, ":");
    const char *start = host[0] == '[' ? host + 1 : host;
    if (n >= sizeof name)
        return 0;
    memcpy(name, start, n);
    name[n] = 0;
    if (n && name[n - 1] == '.') /* the absolute form "localhost." */
        name[n - 1] = 0;
    char key[sizeof L.key];
    snprintf(key, sizeof key, "%s|%s|%s", cfg->allowed_hosts, cfg->bind, cfg->public_url);
    pthread_mutex_lock(&L.mu);
    if (!L.built || strcmp(key, L.key) != 0) {
        build(cfg);
        snprintf(L.key, sizeof L.key, "%s", key);
        L.built = 1;
    }
    int ok = L.any;
    for (int i = 0; i < L.n && !ok; i++)
        ok = !strcasecmp(L.names[i], name);
    pthread_mutex_unlock(&L.mu);
    return ok;
}
