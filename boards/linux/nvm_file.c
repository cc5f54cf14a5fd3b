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
#include <time.h>
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

/* ---- The hold: one file, one user ----------------------------------------
 *
 * Two holds, since neither alone reaches every other user:
 *  - an abstract unix socket named by a hash of the resolved path: exact and
 *    gone with the process however it ends, but seen on this kernel only;
 *  - the hold file FILE.lock (nvm_file.h), which every kernel sharing the
 *    directory sees: each User-Mode Linux of tools/vcan-run is a kernel of
 *    its own on the host's files through hostfs, which passes no flock()
 *    and creates files without O_EXCL on the host. It is made whole under
 *    a name of our own and then link()ed to FILE.lock, which the host does
 *    atomically (EEXIST for the second), so it never exists half-written.
 */

/* The hold file's and its helpers' names: FILE.lock, FILE.lock.<tag>. */
static bool lock_name(const lp_nvm_t *n, const char *suffix, char *buf, size_t len)
{
    return snprintf(buf, len, "%s.lock%s", n->real, suffix) < (int)len;
}

/* The first line of path (at most len - 1 bytes, its newline kept), and its
 * mtime; false when it cannot be read (errno set: ENOENT when gone). */
static bool read_line(const char *path, char *buf, size_t len, struct timespec *mtime)
{
    int fd = open(path, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        return false;
    }
    struct stat st;
    ssize_t r = -1;
    if (fstat(fd, &st) == 0) {
        *mtime = st.st_mtim;
        r = read(fd, buf, len - 1u);
    }
    int e = errno;
    close(fd);
    errno = e;
    if (r < 0) {
        return false;
    }
    buf[r] = '\0';
    char *nl = strchr(buf, '\n');
    if (nl != NULL) {
        nl[1] = '\0';
    }
    return true;
}

/* Where a PID is this kernel's: its boot id and our PID namespace. */
typedef struct {
    char boot[40];
    unsigned long long pidns;
} kernel_t;

static void this_kernel(kernel_t *k)
{
    struct timespec unused;
    if (!read_line("/proc/sys/kernel/random/boot_id", k->boot, sizeof(k->boot), &unused)) {
        k->boot[0] = '\0';
    }
    k->boot[strcspn(k->boot, "\n")] = '\0';
    struct stat st;
    k->pidns = stat("/proc/self/ns/pid", &st) == 0 ? (unsigned long long)st.st_ino : 0u;
}

/* The start time of process pid (field 22 of /proc/PID/stat, clock ticks
 * since boot); 0 when there is no such process. The fields after the
 * command's name, which may hold blanks and ')', are counted from its
 * last ')'. */
static unsigned long long start_time(long pid)
{
    char path[64];
    char buf[1024];
    snprintf(path, sizeof(path), "/proc/%ld/stat", pid);
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        return 0u;
    }
    ssize_t r = read(fd, buf, sizeof(buf) - 1u);
    close(fd);
    if (r <= 0) {
        return 0u;
    }
    buf[r] = '\0';
    const char *p = strrchr(buf, ')');
    for (int field = 2; p != NULL && field < 22; field++) { /* p: before field+1 */
        p = strchr(p + 1, ' ');
    }
    return p != NULL ? strtoull(p + 1, NULL, 10) : 0u;
}

/* The number after key in line (" key=N"); false without one. */
static bool hold_field(const char *line, const char *key, unsigned long long *v)
{
    const char *p = strstr(line, key);
    if (p == NULL || p[strlen(key)] < '0' || p[strlen(key)] > '9') {
        return false;
    }
    char *end;
    errno = 0;
    *v = strtoull(p + strlen(key), &end, 10);
    return errno == 0 && (*end == ' ' || *end == '\n');
}

/* A holder as the hold file names it. */
typedef struct {
    bool ok; /* the line parsed */
    char boot[40];
    unsigned long long pidns, pid, start;
    char by[32];
} holder_t;

static holder_t parse_hold(const char *line)
{
    holder_t h = {.ok = false};
    const char *b = strstr(line, " boot=");
    const char *by = strstr(line, " by=");
    if (strncmp(line, "canopen-hold 1 ", 15) != 0 || b == NULL || by == NULL ||
        !hold_field(line, " pidns=", &h.pidns) || !hold_field(line, " pid=", &h.pid) ||
        !hold_field(line, " start=", &h.start) || h.pid == 0u || h.pid > (unsigned)INT_MAX) {
        return h;
    }
    size_t bl = strcspn(b + 6, " \n");
    size_t yl = strcspn(by + 4, " \n");
    if (bl == 0u || bl >= sizeof(h.boot) || yl == 0u || yl >= sizeof(h.by)) {
        return h;
    }
    memcpy(h.boot, b + 6, bl);
    memcpy(h.by, by + 4, yl);
    h.ok = true;
    return h;
}

/*
 * Whether the hold file line (mtime mtime) is stale, and who holds it, in
 * who (for the refusal). A holder of this kernel and PID namespace is
 * alive while its PID runs with the start time recorded (a PID used again
 * has another); any other, while the file has been touched within
 * LP_NVM_LEASE_S by the wall clock (its renewals: nvm_file.h). A line
 * that does not parse is judged by its age alone.
 */
static bool hold_stale(const char *line, struct timespec mtime, char *who, size_t wholen)
{
    kernel_t k;
    this_kernel(&k);
    holder_t h = parse_hold(line);
    if (h.ok && k.boot[0] != '\0' && strcmp(h.boot, k.boot) == 0 && h.pidns == k.pidns) {
        bool gone = start_time((long)h.pid) != h.start;
        snprintf(who, wholen, "%s, pid %llu of this kernel%s", h.by, h.pid,
                 gone ? ", which has ended" : "");
        return gone;
    }
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    long long age = (long long)(now.tv_sec - mtime.tv_sec);
    if (h.ok) {
        snprintf(who, wholen, "%s, pid %llu of another kernel (boot id %.8s), renewed %lld s ago",
                 h.by, h.pid, h.boot, age);
    } else {
        snprintf(who, wholen, "an unknown holder, renewed %lld s ago", age);
    }
    return age > LP_NVM_LEASE_S;
}

/*
 * Remove the stale hold file whose line was stale_line: moved aside first
 * (to FILE.lock<aside_tag>; rename is atomic), then checked to be that one. Another starter may
 * have removed it and made its own meanwhile, which the move then took:
 * that one is put back (link, never over a newer one).
 */
static void remove_stale(const lp_nvm_t *n, const char *lock, const char *aside_tag,
                         const char *stale_line, const char *who)
{
    char aside[sizeof(n->real) + 80];
    char line[160];
    struct timespec mtime;
    if (!lock_name(n, aside_tag, aside, sizeof(aside)) || rename(lock, aside) != 0) {
        return; /* gone already: the next attempt sees what is there now */
    }
    if (read_line(aside, line, sizeof(line), &mtime) && strcmp(line, stale_line) == 0) {
        lp_log("EEPROM file %s: stale hold file %s removed (%s)", n->real, lock, who);
    } else {
        (void)link(aside, lock);
    }
    (void)unlink(aside);
}

int lp_nvm_lock(lp_nvm_t *n, const char *opt, const char *path, char *err, unsigned errlen)
{
    n->lock_fd = -1;
    n->hold[0] = '\0';
    n->lost = false;
    if (n->path == NULL) {
        return 0;
    }
    /* The abstract socket: not flock() on the file, which every save
     * replaces (a new inode, whose lock nobody holds), and the first save
     * creates. Named by a hash (FNV-1a, 64 bits) of the resolved path. */
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

    kernel_t k;
    this_kernel(&k);
    long pid = (long)getpid();
    snprintf(n->hold, sizeof(n->hold),
             "canopen-hold 1 boot=%s pidns=%llu pid=%ld start=%llu by=canopen-sensor\n",
             k.boot[0] != '\0' ? k.boot : "unknown", k.pidns, pid, start_time(pid));
    char lock[sizeof(n->real) + 8];
    char mine[sizeof(n->real) + 80];
    char tag[64]; /* our helpers' names: no other starter's, on any kernel */
    char stale_tag[80];
    snprintf(tag, sizeof(tag), ".%.8s-%ld", k.boot, pid);
    snprintf(stale_tag, sizeof(stale_tag), ".stale%s", tag);
    if (!lock_name(n, "", lock, sizeof(lock)) || !lock_name(n, tag, mine, sizeof(mine))) {
        snprintf(err, errlen, "%s %s: path too long for its hold file", opt, path);
        lp_nvm_unlock(n);
        return -2;
    }
    const char *fail = NULL;
    int e = 0;
    char who[160] = "another process";
    /* A few attempts: each either holds, is refused, or removed a stale hold. */
    for (int attempt = 0; attempt < 4 && fail == NULL; attempt++) {
        int t = open(mine, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0644);
        size_t hl = strlen(n->hold);
        if (t < 0 || write(t, n->hold, hl) != (ssize_t)hl) {
            e = errno;
            fail = "cannot make";
            if (t >= 0) {
                close(t);
                (void)unlink(mine);
            }
            break;
        }
        close(t);
        int r = link(mine, lock);
        e = errno;
        if (r != 0 && (e == EPERM || e == EOPNOTSUPP || e == EMLINK)) {
            /* No hard links here (FAT, some FUSE): the name alone, with
             * O_EXCL; a reader that finds it empty for a moment takes it
             * as held (a fresh hold file that does not parse). */
            int x = open(lock, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
            r = x >= 0 ? 0 : -1;
            e = errno;
            if (x >= 0) {
                r = write(x, n->hold, hl) == (ssize_t)hl ? 0 : -1;
                close(x);
            }
        }
        (void)unlink(mine);
        if (r == 0) {
            n->renewed = 0u;
            return 0;
        }
        if (e != EEXIST) {
            fail = "cannot create";
            break;
        }
        char line[160];
        struct timespec mtime;
        if (!read_line(lock, line, sizeof(line), &mtime)) {
            continue; /* removed meanwhile: try again */
        }
        if (!hold_stale(line, mtime, who, sizeof(who))) {
            break;
        }
        remove_stale(n, lock, stale_tag, line, who);
    }
    n->hold[0] = '\0';
    if (fail != NULL && (e == EROFS || e == EACCES || e == EPERM || e == ENOSPC || e == EDQUOT)) {
        /* A directory nobody can write in now: no save can replace the
         * file either (its temporary file goes beside it), so no user can
         * overwrite another's; the start goes on, as a failed save does
         * (docs/running.md). */
        lp_log("warning: EEPROM file %s: no hold file (%s %s: %s): the file is held on this "
               "kernel only",
               n->real, fail, lock, strerror(e));
        return 0;
    }
    lp_nvm_unlock(n);
    if (fail != NULL) {
        snprintf(err, errlen, "%s %s: cannot hold the file: %s %s: %s", opt, path, fail, lock,
                 strerror(e));
        return -1;
    }
    snprintf(err, errlen,
             "%s %s: EEPROM file %s is in use by %s (hold file %s; two users would overwrite "
             "each other's saves)",
             opt, path, n->real, who, lock);
    return -2;
}

/* Whether the hold file is still ours (its line is n->hold). */
static bool still_ours(const lp_nvm_t *n, const char *lock)
{
    char line[160];
    struct timespec mtime;
    return read_line(lock, line, sizeof(line), &mtime) && strcmp(line, n->hold) == 0;
}

uint32_t lp_nvm_renew(lp_nvm_t *n, uint32_t now)
{
    if (n->hold[0] == '\0') {
        return UINT32_MAX;
    }
    if (n->renewed != 0u && now - n->renewed < LP_NVM_RENEW_US) {
        return LP_NVM_RENEW_US - (now - n->renewed);
    }
    n->renewed = now != 0u ? now : 1u; /* 0: never renewed */
    char lock[sizeof(n->real) + 8];
    if (lock_name(n, "", lock, sizeof(lock)) && still_ours(n, lock)) {
        (void)utimensat(AT_FDCWD, lock, NULL, AT_SYMLINK_NOFOLLOW);
    } else if (!n->lost) {
        n->lost = true;
        /* Another user found it stale: this process stood still for
         * longer than the lease, or the file was removed by hand. */
        lp_log("error: EEPROM file %s: its hold file %s is gone or another's: another user "
               "may write the file now",
               n->real, lock);
    }
    return LP_NVM_RENEW_US;
}

void lp_nvm_unlock(lp_nvm_t *n)
{
    char lock[sizeof(n->real) + 8];
    if (n->hold[0] != '\0' && lock_name(n, "", lock, sizeof(lock)) && still_ours(n, lock)) {
        (void)unlink(lock);
    }
    n->hold[0] = '\0';
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
