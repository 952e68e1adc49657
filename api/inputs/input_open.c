/* input_open.c — open a job's input file without trusting it (regular files
 * only, size-limited).  Contract: api/inputs/input_open.h. */
#include "input_open.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static const char *kind(mode_t m)
{
    return S_ISDIR(m) ? "a directory"
        : S_ISFIFO(m) ? "a FIFO"
        : S_ISCHR(m)  ? "a character device"
        : S_ISBLK(m)  ? "a block device"
        : S_ISSOCK(m) ? "a socket"
                      : "not a regular file";
}

int pk_input_open(const char *path, long long max_bytes, char *err, size_t errlen)
{
    if (max_bytes <= 0 || max_bytes > PK_INPUT_MAX_BYTES)
        max_bytes = PK_INPUT_MAX_BYTES;
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        int e = errno; /* callers tell a missing file from a refused one */
        snprintf(err, errlen, "cannot open %s: %s", path, strerror(e));
        errno = e;
        return -1;
    }
    struct stat st;
    if (fstat(fd, &st) != 0) {
        snprintf(err, errlen, "cannot stat %s: %s", path, strerror(errno));
        close(fd);
        return -1;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "%s: %s, not a regular file", path, kind(st.st_mode));
        close(fd);
        errno = EINVAL;
        return -1;
    }
    if ((long long)st.st_size > max_bytes) {
        snprintf(err, errlen, "%s: %lld bytes, over the input limit of %lld", path,
                 (long long)st.st_size, max_bytes);
        close(fd);
        errno = EFBIG;
        return -1;
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl >= 0)
        fcntl(fd, F_SETFL, fl & ~O_NONBLOCK);
    return fd;
}

FILE *pk_input_fopen(const char *path, long long max_bytes, char *err, size_t errlen)
{
    int fd = pk_input_open(path, max_bytes, err, errlen);
    if (fd < 0)
        return NULL;
    FILE *f = fdopen(fd, "r");
    if (!f) {
        snprintf(err, errlen, "cannot read %s: %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

int pk_input_check(const char *path, const char *pointer, const char *rule, pk_schema_errors *errs)
{
    char err[256];
    int fd = pk_input_open(path, 0, err, sizeof err);
    if (fd < 0) {
        pk_schema_errors_add(errs, pointer, rule, "%s", err);
        return -1;
    }
    close(fd);
    return 0;
}
