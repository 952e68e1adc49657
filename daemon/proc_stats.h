/* proc_stats.h — this process as the kernel accounts it (proc(5):
 * /proc/self/stat, /proc/stat, /proc/self/fd, /proc/self/limits): what the
 * standard process_* metrics of /metrics report. */
#ifndef PK_PROC_STATS_H
#define PK_PROC_STATS_H

typedef struct pk_proc_stats {
    double start_time_s;   /* when the process started, seconds since the epoch */
    double cpu_s;          /* user + system CPU seconds */
    long long rss_bytes;   /* resident set size */
    long long vsize_bytes; /* virtual memory size */
    long long open_fds;    /* open file descriptors */
    long long max_fds;     /* soft limit of open files; -1: unlimited */
} pk_proc_stats;

/* Fill s from /proc; 0, or -1 when /proc/self/stat cannot be read (the
 * fields not read are -1). */
int pk_proc_stats_read(pk_proc_stats *s);

#endif
