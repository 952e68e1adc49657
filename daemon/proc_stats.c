/* proc_stats.c — /proc/self as numbers; contract in proc_stats.h. */
#include "proc_stats.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* Boot time, seconds since the epoch ("btime" of /proc/stat); -1 unknown. */
static double boot_time(void)
{
    FILE *f = fopen("/proc/stat", "r");
    char line[256];
    double bt = -1;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "btime ", 6)) {
            bt = strtod(line + 6, NULL);
            break;
        }
    if (f)
        fclose(f);
    return bt;
}

static long long open_fds(void)
{
    DIR *d = opendir("/proc/self/fd");
    if (!d)
        return -1;
    long long n = 0;
    struct dirent *e;
    while ((e = readdir(d)))
        if (e->d_name[0] != '.')
            n++;
    closedir(d);
    return n - 1; /* the directory's own descriptor */
}

/* The soft "Max open files" of /proc/self/limits; -1 unlimited or unknown. */
static long long max_fds(void)
{
    FILE *f = fopen("/proc/self/limits", "r");
    char line[256];
    long long n = -1;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "Max open files", 14)) {
            char *end;
            n = strtoll(line + 14, &end, 10);
            if (end == line + 14)
                n = -1;
            break;
        }
    if (f)
        fclose(f);
    return n;
}

int pk_proc_stats_read(pk_proc_stats *s)
{
    *s = (pk_proc_stats){-1, -1, -1, -1, -1, -1};
    s->open_fds = open_fds();
    s->max_fds = max_fds();
    FILE *f = fopen("/proc/self/stat", "r");
    char text[1024];
    size_t len = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f)
        fclose(f);
    text[len] = 0;
    /* the fields after the command name, which may hold spaces and ')' */
    char *p = strrchr(text, ')');
    if (!p)
        return -1;
    unsigned long long utime = 0, stime = 0, start = 0, vsize = 0;
    long long rss = 0;
    /* proc(5) fields 3..24: state ... utime(14) stime(15) ... starttime(22) vsize(23) rss(24) */
    if (sscanf(p + 1,
               " %*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu %*d %*d %*d %*d %*d %*d"
               " %llu %llu %lld",
               &utime, &stime, &start, &vsize, &rss) != 5)
        return -1;
    double tick = (double)sysconf(_SC_CLK_TCK);
    double bt = boot_time();
    s->cpu_s = (double)(utime + stime) / tick;
    if (bt >= 0)
        s->start_time_s = bt + (double)start / tick;
    s->vsize_bytes = (long long)vsize;
    s->rss_bytes = rss * (long long)sysconf(_SC_PAGESIZE);
    return 0;
}
