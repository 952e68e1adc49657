/* input_open.c — open a job's input file without trusting it (regular files
 * only, size-limited).  Contract: api/inputs/input_open.h. */
#define _GNU_SOURCE /* O_PATH */
#include "input_open.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <linux/openat2.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
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

#define OPEN_FLAGS (O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)

/* Without openat2: each directory of rest opened with O_NOFOLLOW. */
static int open_no_symlinks(int dir, const char *rest)
{
    char part[PATH_MAX];
    int fd = dup(dir);
    while (fd >= 0) {
        rest += strspn(rest, "/");
        size_t n = strcspn(rest, "/");
        if (n == 0 || n >= sizeof part) {
            close(fd);
            errno = ENOENT;
            return -1;
        }
        memcpy(part, rest, n);
        part[n] = 0;
        rest += n;
        int last = rest[strspn(rest, "/")] == 0;
        int next = !strcmp(part, "..")
            ? (errno = EXDEV, -1)
            : openat(fd, part, last ? OPEN_FLAGS | O_NOFOLLOW : O_PATH | O_DIRECTORY | O_NOFOLLOW);
        int e = errno;
        close(fd);
        errno = e;
        fd = next;
        if (last)
            return fd;
    }
    return -1;
}

/* path "<root>/./<rest>": rest opened beneath root. */
static int open_beneath(const char *path, const char *marker)
{
    char root[PATH_MAX];
    size_t n = (size_t)(marker - path);
    if (n >= sizeof root) {
        errno = ENAMETOOLONG;
        return -1;
    }
    memcpy(root, path, n);
    root[n] = 0;
    int dir = open(n ? root : "/", O_PATH | O_DIRECTORY | O_CLOEXEC);
    if (dir < 0)
        return -1;
    const char *rest = marker + strlen(PK_INPUT_BENEATH);
    struct open_how how = {.flags = OPEN_FLAGS, .resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS};
    int fd = (int)syscall(SYS_openat2, dir, rest, &how, sizeof how);
    if (fd < 0 && (errno == ENOSYS || errno == EPERM))
        fd = open_no_symlinks(dir, rest);
    int e = errno;
    close(dir);
    errno = e;
    return fd;
}

int pk_input_open(const char *path, long long max_bytes, char *err, size_t errlen)
{
    if (max_bytes <= 0 || max_bytes > PK_INPUT_MAX_BYTES)
        max_bytes = PK_INPUT_MAX_BYTES;
    const char *beneath = strstr(path, PK_INPUT_BENEATH);
    int fd = beneath ? open_beneath(path, beneath) : open(path, OPEN_FLAGS);
    if (fd < 0 && beneath && errno == EXDEV) {
        snprintf(err, errlen,
                 "%s: leads outside its directory (a symlink or \"..\" changed since "
                 "the job was accepted)",
                 path);
        errno = EXDEV;
        return -1;
    }
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
