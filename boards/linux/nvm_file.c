/*
 * nvm_file.c - the EEPROM as a file; see nvm_file.h.
 */
#include "nvm_file.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <unistd.h>

#include "log.h"

/* Write all of len bytes; false with errno set (a short write: ENOSPC). */
static bool write_all(int fd, const struct iovec *iov, int cnt)
{
    struct iovec v[3];
    memcpy(v, iov, (size_t)cnt * sizeof(v[0]));
    int i = 0;
    while (i < cnt) {
        ssize_t n = writev(fd, &v[i], cnt - i);
        if (n < 0) {
            if (errno == EINTR) {
                continue;
            }
            return false;
        }
        if (n == 0) {
            errno = ENOSPC;
            return false;
        }
        size_t left = (size_t)n;
        while (i < cnt && left >= v[i].iov_len) {
            left -= v[i].iov_len;
            i++;
        }
        if (i < cnt) {
            v[i].iov_base = (char *)v[i].iov_base + left;
            v[i].iov_len -= left;
        }
    }
    return true;
}

/*
 * The file with len bytes at addr replaced by buf: written whole to a
 * temporary file beside it, fsync, rename, fsync of the directory, so the
 * file is never half-written, whatever happens to the process. The mirror
 * is changed only when all of that worked, so it always equals the file.
 * The cause of a failure is logged (strerror).
 */
static bool commit(lp_nvm_t *n, uint32_t addr, const void *buf, uint32_t len)
{
    if (n->path == NULL) {
        memcpy(n->mem + addr, buf, len);
        return true;
    }
    char tmp[sizeof(n->real) + 8];
    snprintf(tmp, sizeof(tmp), "%s.tmp", n->real);
    /* O_NOFOLLOW: a symbolic link at the temporary name is an error, not
     * a way to write elsewhere. */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        lp_log("error: EEPROM file %s: save failed: cannot create %s: %s (the file keeps its "
               "previous contents)",
               n->real, tmp, strerror(errno));
        return false;
    }
    const struct iovec iov[3] = {
        {.iov_base = n->mem, .iov_len = addr},
        /* iov_base is not const, writev only reads it: const dropped through uintptr_t */
        /* NOLINTNEXTLINE(performance-no-int-to-ptr) */
        {.iov_base = (void *)(uintptr_t)buf, .iov_len = len},
        {.iov_base = n->mem + addr + len, .iov_len = n->size - addr - len},
    };
    const char *step = "write";
    bool ok = write_all(fd, iov, 3);
    if (ok && fsync(fd) != 0) {
        step = "fsync";
        ok = false;
    }
    int e = errno;
    if (close(fd) != 0 && ok) {
        step = "close";
        ok = false;
        e = errno;
    }
    if (ok && rename(tmp, n->real) != 0) {
        step = "rename";
        ok = false;
        e = errno;
    }
    if (!ok) {
        lp_log("error: EEPROM file %s: save failed (%s): %s (the file keeps its previous "
               "contents)",
               n->real, step, strerror(e));
        (void)unlink(tmp);
        return false;
    }
    /* The rename is durable once the directory is on disk too. */
    char dir[sizeof(n->real)];
    snprintf(dir, sizeof(dir), "%s", n->real);
    int dfd = open(dirname(dir), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
        (void)fsync(dfd);
        close(dfd);
    }
    memcpy(n->mem + addr, buf, len);
    return true;
}

static const char *file_kind(mode_t m)
{
    return S_ISDIR(m)    ? "a directory"
           : S_ISFIFO(m) ? "a FIFO"
           : S_ISCHR(m)  ? "a character device"
           : S_ISBLK(m)  ? "a block device"
           : S_ISSOCK(m) ? "a socket"
                         : "not a regular file";
}

int lp_nvm_open(lp_nvm_t *n, const char *opt, const char *path, uint8_t *mem, uint32_t size,
                char *err, unsigned errlen)
{
    memset(n, 0, sizeof(*n));
    n->mem = mem;
    n->size = size;
    memset(mem, 0xFF, size);
    if (path == NULL) {
        lp_log("no --nvm file: parameters live in RAM and are lost at exit");
        return 0;
    }
    /* Look before opening anything: open() of a FIFO blocks, and a save
     * would replace a device or a FIFO by a regular file. */
    struct stat st;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode)) {
            snprintf(err, errlen, "%s %s: %s, not a regular file", opt, path,
                     file_kind(st.st_mode));
            return -2;
        }
        if (realpath(path, n->real) == NULL) {
            snprintf(err, errlen, "%s %s: %s", opt, path, strerror(errno));
            return -2;
        }
    } else if (errno == ENOENT && lstat(path, &st) == 0 && S_ISLNK(st.st_mode)) {
        /* A link to nothing: the first save would replace the link by a
         * file (rename over it), not create what it names. Refused. */
        char to[256];
        ssize_t tl = readlink(path, to, sizeof(to) - 1u);
        to[tl > 0 ? tl : 0] = '\0';
        snprintf(err, errlen,
                 "%s %s: a symbolic link to %s, which does not exist (create the "
                 "file, or give the path without the link)",
                 opt, path, to);
        return -2;
    } else if (errno == ENOENT) {
        /* A new file: its directory must exist (the first save creates the file). */
        char d[sizeof(n->real)];
        char b[sizeof(n->real)];
        if (snprintf(d, sizeof(d), "%s", path) >= (int)sizeof(d)) {
            snprintf(err, errlen, "%s %s: path too long", opt, path);
            return -2;
        }
        snprintf(b, sizeof(b), "%s", path);
        const char *dir = dirname(d);
        const char *base = basename(b);
        struct stat ds;
        char rdir[PATH_MAX];
        if (stat(dir, &ds) != 0 || !S_ISDIR(ds.st_mode) || realpath(dir, rdir) == NULL) {
            snprintf(err, errlen, "%s %s: directory %s does not exist", opt, path, dir);
            return -2;
        }
        if (strcmp(base, "/") == 0 || strcmp(base, ".") == 0 || strcmp(base, "..") == 0 ||
            snprintf(n->real, sizeof(n->real), "%s/%s", strcmp(rdir, "/") == 0 ? "" : rdir, base) >=
                (int)sizeof(n->real)) {
            snprintf(err, errlen, "%s %s: not a file name", opt, path);
            return -2;
        }
        n->path = n->real;
        lp_log("EEPROM file %s does not exist yet: factory defaults; the first save creates it",
               n->real);
        return 0;
    } else {
        snprintf(err, errlen, "%s %s: %s", opt, path, strerror(errno));
        return -2;
    }
    n->path = n->real;
    /* O_NONBLOCK: should the path have become a FIFO since stat(), open
     * returns at once; fstat then refuses it. */
    int fd = open(n->real, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        snprintf(err, errlen, "%s %s: cannot read: %s", opt, path, strerror(errno));
        return -1;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        snprintf(err, errlen, "%s %s: not a regular file", opt, path);
        return -2;
    }
    size_t got = 0;
    while (got < size) {
        ssize_t r = read(fd, mem + got, size - got);
        if (r < 0 && errno == EINTR) {
            continue;
        }
        if (r < 0) {
            int e = errno;
            close(fd);
            memset(mem, 0xFF, size);
            snprintf(err, errlen, "%s %s: cannot read: %s", opt, path, strerror(e));
            return -1;
        }
        if (r == 0) {
            break;
        }
        got += (size_t)r;
    }
    close(fd);
    if (got < size) {
        /* A shorter file reads as erased beyond its end, like a fresh chip;
         * the file itself is left alone until a save. */
        memset(mem + got, 0xFF, size - got);
        lp_log("EEPROM file %s has %zu of %u bytes; the rest reads as erased", n->real, got, size);
    } else if (st.st_size > (off_t)size) {
        lp_log("EEPROM file %s has %lld bytes, more than the %u used; the rest is ignored (and "
               "left out at the next save)",
               n->real, (long long)st.st_size, size);
    }
    return 0;
}

int lp_nvm_lock(lp_nvm_t *n, const char *opt, const char *path, char *err, unsigned errlen)
{
    n->lock_fd = -1;
    if (n->path == NULL) {
        return 0;
    }
    /* Not flock() on the file, as tools/emu does for its flash: every save
     * replaces the file (a new inode, whose lock nobody holds), and the
     * first save creates it. The name is held instead: an abstract unix
     * socket (no file on disk; gone with the process, however it ends)
     * named by a hash (FNV-1a, 64 bits) of the resolved path. */
    uint64_t h = 0xCBF29CE484222325u;
    for (const char *c = n->real; *c != '\0'; c++) {
        h = (h ^ (uint8_t)*c) * 0x100000001B3u;
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    int len = snprintf(sa.sun_path + 1, sizeof(sa.sun_path) - 1u, "canopen-sensor/nvm/%016llx",
                       (unsigned long long)h);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    socklen_t salen = (socklen_t)(offsetof(struct sockaddr_un, sun_path) + 1u + (size_t)len);
    if (fd < 0 || bind(fd, (const struct sockaddr *)&sa, salen) != 0) {
        int e = errno;
        if (fd >= 0) {
            close(fd);
        }
        if (e == EADDRINUSE) {
            snprintf(err, errlen,
                     "%s %s: EEPROM file %s is in use by another canopen-sensor "
                     "process (two users would overwrite each other's saves)",
                     opt, path, n->real);
            return -2;
        }
        snprintf(err, errlen, "%s %s: cannot hold the file: %s", opt, path, strerror(e));
        return -1;
    }
    n->lock_fd = fd;
    return 0;
}

void lp_nvm_unlock(lp_nvm_t *n)
{
    if (n->lock_fd > 0) {
        close(n->lock_fd);
    }
    n->lock_fd = -1;
}

bool lp_nvm_read(const lp_nvm_t *n, uint32_t addr, void *buf, uint32_t len)
{
    if (addr > n->size || len > n->size - addr) {
        return false;
    }
    memcpy(buf, n->mem + addr, len);
    return true;
}

bool lp_nvm_write(lp_nvm_t *n, uint32_t addr, const void *buf, uint32_t len)
{
    if (addr > n->size || len > n->size - addr) {
        return false;
    }
    return commit(n, addr, buf, len);
}
