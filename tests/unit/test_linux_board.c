/*
 * test_linux_board.c - the Linux program's ports: the EEPROM file, the log's
 * rate limit, the simulated CAN controller and the shared transmit queue.
 */
#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "can_port.h"
#include "co_port.h"
#include "control.h"
#include "dst.h"
#include "jd.h"

#include "harness.h"

/* The log goes to a temporary file the tests read back. */
static FILE *log_f;

static void log_start(void)
{
    log_f = tmpfile();
    lp_log_open(log_f);
}

/* Everything logged since log_start(), NUL-terminated (static buffer). */
static const char *log_text(void)
{
    static char buf[16384];
    fflush(log_f);
    long end = ftell(log_f);
    rewind(log_f);
    size_t n = fread(buf, 1, sizeof(buf) - 1u, log_f);
    buf[n] = '\0';
    fseek(log_f, end, SEEK_SET);
    return buf;
}

static void log_stop(void)
{
    lp_log_open(NULL);
    fclose(log_f);
    log_f = NULL;
}

static void write_file(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f != NULL) {
        CHECK_EQ(fwrite(data, 1, len, f), len);
        fclose(f);
    }
}

static bool file_equals(const char *path, const void *data, size_t len)
{
    uint8_t buf[4096];
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        return false;
    }
    size_t n = fread(buf, 1, sizeof(buf), f);
    fclose(f);
    return n == len && memcmp(buf, data, len) == 0;
}

static void test_eeprom_file(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof(path), "%s/eeprom.bin", dir);
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    lp_port_t p = {.nvm = &n};
    char err[600];
    log_start();
    /* A new file: nothing is created until the first save. */
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, sizeof(err)), 0);
    CHECK(access(path, F_OK) != 0);
    CHECK(strstr(log_text(), "the first save creates it") != NULL);
    CHECK_EQ(mem[0], 0xFF);
    /* Its size (co_port.h: no size query, a byte beyond is refused). */
    uint8_t again_byte;
    CHECK(co_port_nvm_read(&p, sizeof(mem) - 1u, &again_byte, 1));
    CHECK(!co_port_nvm_read(&p, sizeof(mem), &again_byte, 1));
    CHECK(co_port_nvm_write(&p, 10, "abc", 3));
    struct stat st;
    CHECK(stat(path, &st) == 0 && st.st_size == (off_t)sizeof(mem));
    CHECK(!co_port_nvm_write(&p, sizeof(mem) - 1u, "abc", 3)); /* out of range */
    char tmp[300];
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    CHECK(access(tmp, F_OK) != 0); /* no temporary left behind */
    uint8_t again[CO_STORE_NVM_SIZE];
    lp_nvm_t n2;
    CHECK_EQ(lp_nvm_open(&n2, "--nvm", path, again, sizeof(again), err, sizeof(err)), 0);
    CHECK(memcmp(&again[10], "abc", 3) == 0);
    CHECK_EQ(again[9], 0xFF);
    /* A short file reads as erased beyond its end, and stays short on disk. */
    CHECK(truncate(path, 11) == 0);
    CHECK_EQ(lp_nvm_open(&n2, "--nvm", path, again, sizeof(again), err, sizeof(err)), 0);
    CHECK_EQ(again[10], 'a');
    CHECK_EQ(again[11], 0xFF);
    CHECK(stat(path, &st) == 0 && st.st_size == 11);
    uint8_t b;
    lp_port_t p2 = {.nvm = &n2};
    CHECK(!co_port_nvm_read(&p2, sizeof(again), &b, 1));
    /* Through a symbolic link: the file it points to is written, the link stays. */
    char link[300];
    snprintf(link, sizeof(link), "%s/link.bin", dir);
    CHECK(symlink(path, link) == 0);
    CHECK_EQ(lp_nvm_open(&n2, "--nvm", link, again, sizeof(again), err, sizeof(err)), 0);
    CHECK(co_port_nvm_write(&p2, 0, "z", 1));
    CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode));
    CHECK(stat(path, &st) == 0 && st.st_size == (off_t)sizeof(again));
    unlink(link);
    unlink(path);
    rmdir(dir);
    log_stop();
}

/* --nvm given something that is not a regular file: refused at once. */
static void test_eeprom_not_a_file(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char fifo[300];
    snprintf(fifo, sizeof(fifo), "%s/fifo", dir);
    CHECK(mkfifo(fifo, 0600) == 0);
    char missing[300];
    snprintf(missing, sizeof(missing), "%s/no/such/dir/e.bin", dir);
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    char err[600];
    log_start();
    /* A FIFO: would block in open() for ever (this test would hang). */
    CHECK_EQ(lp_nvm_open(&n, "--nvm", fifo, mem, sizeof(mem), err, sizeof(err)), -2);
    CHECK(strstr(err, "a FIFO, not a regular file") != NULL);
    /* A device (/dev/null, /dev/zero): a save would replace it by a
     * regular file (as root). /dev/zero, as /dev/null may itself have been
     * replaced on a machine where the old program ran as root. */
    struct stat st;
    CHECK(stat("/dev/zero", &st) == 0 && S_ISCHR(st.st_mode));
    CHECK_EQ(lp_nvm_open(&n, "--nvm", "/dev/zero", mem, sizeof(mem), err, sizeof(err)), -2);
    CHECK(strstr(err, "a character device") != NULL);
    CHECK_EQ(lp_nvm_open(&n, "--nvm", dir, mem, sizeof(mem), err, sizeof(err)), -2);
    CHECK(strstr(err, "a directory") != NULL);
    CHECK_EQ(lp_nvm_open(&n, "--nvm", missing, mem, sizeof(mem), err, sizeof(err)), -2);
    CHECK(strstr(err, "does not exist") != NULL);
    CHECK(strstr(log_text(), "created") == NULL);
    unlink(fifo);
    rmdir(dir);
    log_stop();
}

/* A symbolic link to nothing (into a missing directory): refused, with
 * the option's name (the first save replaced the link by a file). */
static void test_eeprom_link_to_nothing(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char link[300];
    char to[300];
    snprintf(link, sizeof(link), "%s/e.nvm", dir);
    snprintf(to, sizeof(to), "%s/gone/e.nvm", dir);
    CHECK(symlink(to, link) == 0);
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    char err[600];
    log_start();
    CHECK_EQ(lp_nvm_open(&n, "--nvm-dir D:", link, mem, sizeof(mem), err, sizeof(err)), -2);
    char want[800];
    snprintf(want, sizeof(want),
             "--nvm-dir D: %s: a symbolic link to %s, which does not exist "
             "(create the file, or give the path without the link)",
             link, to);
    if (strcmp(err, want) != 0) {
        FAIL(err);
    }
    struct stat st;
    CHECK(lstat(link, &st) == 0 && S_ISLNK(st.st_mode));
    unlink(link);
    rmdir(dir);
    log_stop();
}

/* One EEPROM file, one user: a second hold on the same resolved path is
 * refused (another name for it too), given back at unlock; RAM needs none. */
static void test_eeprom_lock(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[300];
    char other[300];
    snprintf(path, sizeof(path), "%s/e.nvm", dir);
    snprintf(other, sizeof(other), "%s/./e.nvm", dir);
    uint8_t mem[CO_STORE_NVM_SIZE];
    uint8_t mem2[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    lp_nvm_t n2;
    char err[600];
    log_start();
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_lock(&n, "--nvm", path, err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_open(&n2, "--nvm", other, mem2, sizeof(mem2), err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_lock(&n2, "--nvm", other, err, sizeof(err)), -2);
    CHECK(strstr(err, "is in use by another canopen-sensor process") != NULL);
    lp_nvm_unlock(&n);
    CHECK_EQ(lp_nvm_lock(&n2, "--nvm", other, err, sizeof(err)), 0);
    lp_nvm_unlock(&n2);
    lp_nvm_t ram;
    CHECK_EQ(lp_nvm_open(&ram, "--nvm", NULL, mem, sizeof(mem), err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_lock(&ram, "--nvm", NULL, err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_lock(&ram, "--nvm", NULL, err, sizeof(err)), 0);
    rmdir(dir);
    log_stop();
}

/* The hold file's line for process pid (start: its start time) of the kernel
 * boot (NULL: this one), as nvm_file.h describes it. */
static void hold_line(char *buf, size_t len, const char *boot, long pid, unsigned long long start)
{
    char mine[64] = "";
    FILE *f = fopen("/proc/sys/kernel/random/boot_id", "r");
    CHECK(f != NULL);
    if (f != NULL) {
        CHECK(fgets(mine, sizeof(mine), f) != NULL);
        fclose(f);
    }
    mine[strcspn(mine, "\n")] = '\0';
    struct stat st;
    CHECK_EQ(stat("/proc/self/ns/pid", &st), 0);
    snprintf(buf, len, "canopen-hold 1 boot=%s pidns=%llu pid=%ld start=%llu by=tools/emu\n",
             boot != NULL ? boot : mine, (unsigned long long)st.st_ino, pid, start);
}

/* This process's start time, field 22 of /proc/self/stat. */
static unsigned long long own_start(void)
{
    char buf[1024] = "";
    FILE *f = fopen("/proc/self/stat", "r");
    CHECK(f != NULL);
    if (f != NULL) {
        CHECK(fgets(buf, sizeof(buf), f) != NULL);
        fclose(f);
    }
    const char *p = strrchr(buf, ')');
    for (int field = 2; p != NULL && field < 22; field++) {
        p = strchr(p + 1, ' ');
    }
    return p != NULL ? strtoull(p + 1, NULL, 10) : 0u;
}

/* The hold file's mtime set age seconds back. */
static void age_file(const char *path, long age)
{
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    struct timespec t[2] = {{.tv_sec = now.tv_sec - age}, {.tv_sec = now.tv_sec - age}};
    CHECK_EQ(utimensat(AT_FDCWD, path, t, 0), 0);
}

static long file_age(const char *path)
{
    struct stat st;
    struct timespec now;
    clock_gettime(CLOCK_REALTIME, &now);
    return stat(path, &st) == 0 ? (long)(now.tv_sec - st.st_mtim.tv_sec) : -1;
}

/* Try to hold path with the hold file holding line (mtime age s back);
 * returns lp_nvm_lock's result, err its message, the hold given back. */
static int lock_over(const char *path, const char *lock, const char *line, long age, char *err,
                     unsigned errlen)
{
    write_file(lock, line, strlen(line));
    age_file(lock, age);
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, errlen), 0);
    int r = lp_nvm_lock(&n, "--nvm", path, err, errlen);
    if (r == 0) {
        char ours[200];
        hold_line(ours, sizeof(ours), NULL, (long)getpid(), own_start());
        /* ours names tools/emu; the file canopen-sensor: compare up to by= */
        CHECK(file_equals(lock, n.hold, strlen(n.hold)));
        CHECK(strncmp(n.hold, ours, (size_t)(strstr(ours, " by=") - ours)) == 0);
        lp_nvm_unlock(&n);
        CHECK(access(lock, F_OK) != 0); /* given back: gone */
    } else {
        CHECK(file_equals(lock, line, strlen(line))); /* a live hold is left alone */
        (void)unlink(lock);
    }
    return r;
}

/* The hold file (nvm_file.h): made at lock, renewed, removed at unlock;
 * another's refused while it lives, taken over once it is stale: on this
 * kernel by its process being gone (a PID used again has another start
 * time), from another kernel by its lease running out. */
static void test_eeprom_hold_file(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[300];
    char lock[310];
    char line[200];
    char err[900];
    snprintf(path, sizeof(path), "%s/e.nvm", dir);
    snprintf(lock, sizeof(lock), "%s/e.nvm.lock", dir);
    log_start();

    /* Made at lock, with this process in it; renewed once a second. */
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, sizeof(err)), 0);
    CHECK_EQ(lp_nvm_lock(&n, "--nvm", path, err, sizeof(err)), 0);
    CHECK(file_equals(lock, n.hold, strlen(n.hold)));
    hold_line(line, sizeof(line), NULL, (long)getpid(), own_start());
    CHECK(strncmp(n.hold, line, (size_t)(strstr(line, " by=") - line)) == 0);
    CHECK(strstr(n.hold, " by=canopen-sensor\n") != NULL);
    age_file(lock, 100);
    CHECK_EQ(lp_nvm_renew(&n, 5000u), LP_NVM_RENEW_US); /* first call: renewed now */
    CHECK(file_age(lock) >= 0 && file_age(lock) < 5);
    age_file(lock, 100);
    CHECK_EQ(lp_nvm_renew(&n, 5000u + LP_NVM_RENEW_US - 1u), 1u); /* not due yet */
    CHECK(file_age(lock) >= 100);
    CHECK_EQ(lp_nvm_renew(&n, 5000u + LP_NVM_RENEW_US), LP_NVM_RENEW_US);
    CHECK(file_age(lock) < 5);
    /* Someone took it (judged stale): logged once, never touched again. */
    hold_line(line, sizeof(line), "other-kernel", 42, 7u);
    write_file(lock, line, strlen(line));
    age_file(lock, 100);
    (void)lp_nvm_renew(&n, 5000u + 2u * LP_NVM_RENEW_US);
    (void)lp_nvm_renew(&n, 5000u + 3u * LP_NVM_RENEW_US);
    CHECK(file_age(lock) >= 100);
    const char *lost = strstr(log_text(), "is gone or another's");
    CHECK(lost != NULL && strstr(lost + 1, "is gone or another's") == NULL);
    lp_nvm_unlock(&n);
    CHECK(file_equals(lock, line, strlen(line))); /* another's stays */
    (void)unlink(lock);
    CHECK_EQ(lp_nvm_renew(&n, 0u), UINT32_MAX); /* nothing held */

    /* This kernel: a live holder (this very process) refused, ... */
    hold_line(line, sizeof(line), NULL, (long)getpid(), own_start());
    CHECK_EQ(lock_over(path, lock, line, 100, err, sizeof(err)), -2);
    char want[1500];
    snprintf(want, sizeof(want),
             "--nvm %s: EEPROM file %s is in use by tools/emu, pid %ld of this kernel (hold "
             "file %s; two users would overwrite each other's saves)",
             path, path, (long)getpid(), lock);
    CHECK(strcmp(err, want) == 0);
    /* ... its PID with another start time (used again) taken over, ... */
    hold_line(line, sizeof(line), NULL, (long)getpid(), own_start() + 1u);
    CHECK_EQ(lock_over(path, lock, line, 0, err, sizeof(err)), 0);
    /* ... and an ended process's at once, however fresh. */
    pid_t child = fork();
    if (child == 0) {
        _exit(0);
    }
    CHECK(child > 0);
    CHECK_EQ(waitpid(child, NULL, 0), child);
    hold_line(line, sizeof(line), NULL, (long)child, own_start());
    CHECK_EQ(lock_over(path, lock, line, 0, err, sizeof(err)), 0);
    snprintf(want, sizeof(want),
             "stale hold file %s removed (tools/emu, pid %ld of this kernel, "
             "which has ended)",
             lock, (long)child);
    CHECK(strstr(log_text(), want) != NULL);

    /* Another kernel: alive while renewed within the lease. */
    hold_line(line, sizeof(line), "6d3a0c51-other-kernel", 42, 7u);
    CHECK_EQ(lock_over(path, lock, line, LP_NVM_LEASE_S - 2, err, sizeof(err)), -2);
    CHECK(strstr(err, "in use by tools/emu, pid 42 of another kernel (boot id 6d3a0c51), "
                      "renewed ") != NULL);
    CHECK_EQ(lock_over(path, lock, line, LP_NVM_LEASE_S + 2, err, sizeof(err)), 0);
    /* A line that does not parse: its age alone. */
    CHECK_EQ(lock_over(path, lock, "junk\n", 0, err, sizeof(err)), -2);
    CHECK(strstr(err, "in use by an unknown holder, renewed 0 s ago") != NULL);
    CHECK_EQ(lock_over(path, lock, "", 0, err, sizeof(err)), -2);
    CHECK_EQ(lock_over(path, lock, "junk\n", LP_NVM_LEASE_S + 2, err, sizeof(err)), 0);

    /* Nothing is left in the directory: no hold file, no helper of one. */
    CHECK(rmdir(dir) == 0);
    log_stop();
}

/* got is want, or both are shown. */
#define CHECK_STR(got, want) check_str((got), (want), __LINE__)
static void check_str(const char *got, const char *want, int line)
{
    if (strcmp(got, want) != 0) {
        fprintf(stderr, "line %d: got \"%s\", want \"%s\"\n", line, got, want);
    }
    CHECK(strcmp(got, want) == 0);
}

/* The control socket's line function for the tests: "ok LINE". */
static void echo_line(void *ctx, const char *line, char *reply, size_t len)
{
    (void)ctx;
    snprintf(reply, len, "ok %s", line);
}

/* A client of the test's control socket at path, connected and accepted
 * at time now; returns its fd, *slot the slot it got (-1: refused). */
static int ctl_client(ctl_t *c, const char *path, uint32_t now, int *slot)
{
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof(sa.sun_path), "%s", path);
    CHECK_EQ(connect(fd, (const struct sockaddr *)&sa, sizeof(sa)), 0);
    *slot = ctl_accept(c, now);
    return fd;
}

/* What the server sent fd, up to its close (the client's socket read to
 * its end, or what is there now when it is still open). */
static const char *ctl_heard(int fd)
{
    static char buf[512];
    ssize_t n = recv(fd, buf, sizeof(buf) - 1u, MSG_DONTWAIT);
    buf[n > 0 ? n : 0] = '\0';
    return buf;
}

/* The server closed fd: its end (ECONNRESET when bytes it had not read
 * were left: a unix socket closed with them says so). */
static bool ctl_closed(int fd)
{
    char b;
    ssize_t r = recv(fd, &b, 1, MSG_DONTWAIT);
    return r == 0 || (r < 0 && errno == ECONNRESET);
}

/* 16 connections that say nothing locked every other client out for as
 * long as they stayed: a client silent for CTL_IDLE_US is closed, and a
 * newcomer finding every slot taken gets the slot of the client silent
 * longest if that one has been silent for CTL_EVICT_US. Time is the
 * loop's wrapping clock, here near its wrap. */
static void test_control_silent_clients(void)
{
    char dir[] = "/tmp/co-ctl-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char spec[120];
    char path[100];
    snprintf(path, sizeof(path), "%s/s", dir);
    snprintf(spec, sizeof(spec), "unix:%s", path);
    static ctl_t c;
    char err[200];
    c.fd = -1;                                /* as loop_open leaves it without --control */
    CHECK_EQ(ctl_expire(&c, 0u), UINT32_MAX); /* never opened: its zeros are no clients */
    CHECK_EQ(ctl_open(&c, spec, err, sizeof(err)), 0);
    const uint32_t t0 = UINT32_MAX - 20000000u; /* the clock wraps 20 s later */
    int fd[CTL_CLIENTS];
    int slot;
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        fd[k] = ctl_client(&c, path, t0, &slot);
        CHECK_EQ(slot, (int)k);
    }
    CHECK_EQ(ctl_expire(&c, t0 + CTL_IDLE_US - 1u), 1u); /* nobody yet, the first in 1 us */
    /* Full, every client silent for less than CTL_EVICT_US: refused. */
    int late = ctl_client(&c, path, t0 + CTL_EVICT_US - 1u, &slot);
    CHECK_EQ(slot, -1);
    CHECK_STR(ctl_heard(late), "error: too many control clients\n");
    CHECK(ctl_closed(late));
    close(late);
    /* Client 0 sends half a line at t0 + 2 s (a byte is a sign of life,
     * a whole line or not), ... */
    CHECK_EQ(send(fd[0], "ab", 2, MSG_NOSIGNAL), 2);
    CHECK(ctl_read(&c, 0, echo_line, NULL, t0 + 2000000u));
    CHECK_STR(ctl_heard(fd[0]), "");
    /* ... client 2 takes an answer at t0 + 29 s (as one that waited for
     * the kernel's room: put there by hand), ... */
    memcpy(c.cl[2].out, "ok x\n", 5);
    c.cl[2].olen = 5;
    CHECK(ctl_read(&c, 2, echo_line, NULL, t0 + 29000000u));
    CHECK_STR(ctl_heard(fd[2]), "ok x\n");
    /* ... and client 3 talks at t0 + 30 s: alive from then. */
    CHECK_EQ(send(fd[3], "get\n", 4, MSG_NOSIGNAL), 4);
    CHECK(ctl_read(&c, 3, echo_line, NULL, t0 + 30000000u));
    CHECK_STR(ctl_heard(fd[3]), "ok get\n");
    /* Later: the client silent longest (1; 0, 2 and 3 spoke) gives its
     * slot up to a newcomer. */
    CHECK_EQ(send(fd[1], "half a li", 9, MSG_NOSIGNAL), 9); /* not read yet: no sign of life */
    int newer = ctl_client(&c, path, t0 + 31000000u, &slot);
    CHECK_EQ(slot, 1);
    CHECK_STR(ctl_heard(fd[1]),
              "error: silent for 31 s: closed (every slot taken: a new client has it)\n");
    CHECK(ctl_closed(fd[1]));
    close(fd[1]);
    fd[1] = newer;
    /* A minute after: the silent ones closed; 0, 2, 3 and the newcomer
     * stay, the next of them (0, at t0 + 2 s) due in 1 s. */
    CHECK_EQ(ctl_expire(&c, t0 + CTL_IDLE_US + 1000000u), 1000000u);
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        if (k <= 3u) {
            CHECK(c.cl[k].fd >= 0);
            CHECK(!ctl_closed(fd[k]));
        } else {
            CHECK(c.cl[k].fd < 0);
            CHECK_STR(ctl_heard(fd[k]), "error: silent for 61 s: closed\n");
            CHECK(ctl_closed(fd[k]));
        }
    }
    /* 0, 2 and 3 closed at t0 + 90 s; the newcomer (t0 + 31 s) due in 1 s. */
    CHECK_EQ(ctl_expire(&c, t0 + 90000000u), 1000000u);
    CHECK(c.cl[0].fd < 0 && c.cl[2].fd < 0 && c.cl[3].fd < 0 && c.cl[1].fd >= 0);
    CHECK_STR(ctl_heard(fd[0]), "error: silent for 88 s: closed\n");
    CHECK_EQ(send(fd[1], "x\n", 2, MSG_NOSIGNAL), 2);
    CHECK(ctl_read(&c, 1, echo_line, NULL, t0 + 90500000u));
    CHECK_EQ(ctl_expire(&c, t0 + 91000000u), CTL_IDLE_US - 500000u);
    ctl_close(&c);
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        close(fd[k]);
    }
    CHECK(rmdir(dir) == 0);
}

/* A corrupt file stays byte for byte as it is until a save. */
static void test_eeprom_corrupt_untouched(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof(path), "%s/eeprom.bin", dir);
    uint8_t junk[100];
    for (unsigned i = 0; i < sizeof(junk); i++) {
        junk[i] = (uint8_t)(i * 37u + 11u);
    }
    write_file(path, junk, sizeof(junk));
    log_start();
    _Alignas(max_align_t) unsigned char inst[sizeof(product_any_t)];
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    char err[600];
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, sizeof(err)), 0);
    lp_port_t port;
    memset(&port, 0, sizeof(port));
    port.fd = -1;
    port.nvm = &n;
    port.link = LP_LINK_DOWN; /* nothing to send frames to: bus-off */
    void *ports[1] = {&port};
    co_node_t *nodes[1];
    jd1xxx.create(&jd1xxx, inst, ports, nodes);
    co_node_start(nodes[0], 0);
    co_node_poll(nodes[0], 1000);
    CHECK(file_equals(path, junk, sizeof(junk)));
    char tmp[300];
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    CHECK(access(tmp, F_OK) != 0);
    unlink(path);
    rmdir(dir);
    log_stop();
}

/* A save that cannot be written: false (0x06060000 over SDO), the cause
 * logged, the file and the mirror as they were. The temporary name is
 * taken by a directory, which stops root as well. */
static void test_eeprom_save_fails(void)
{
    char dir[] = "/tmp/co-nvm-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[256];
    snprintf(path, sizeof(path), "%s/eeprom.bin", dir);
    uint8_t old[CO_STORE_NVM_SIZE];
    memset(old, 0x5A, sizeof(old));
    write_file(path, old, sizeof(old));
    char tmp[300];
    snprintf(tmp, sizeof(tmp), "%s.tmp", path);
    CHECK(mkdir(tmp, 0700) == 0);
    log_start();
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    char err[600];
    CHECK_EQ(lp_nvm_open(&n, "--nvm", path, mem, sizeof(mem), err, sizeof(err)), 0);
    lp_port_t p = {.nvm = &n};
    CHECK(!co_port_nvm_write(&p, 4, "new", 3));
    CHECK(strstr(log_text(), "save failed") != NULL);
    CHECK(strstr(log_text(), "Is a directory") != NULL);
    CHECK(file_equals(path, old, sizeof(old)));
    uint8_t b[3];
    CHECK(co_port_nvm_read(&p, 4, b, 3) && memcmp(b, "ZZZ", 3) == 0);
    /* The way clear again: the save works. */
    CHECK(rmdir(tmp) == 0);
    CHECK(co_port_nvm_write(&p, 4, "new", 3));
    CHECK(co_port_nvm_read(&p, 4, b, 3) && memcmp(b, "new", 3) == 0);
    memcpy(&old[4], "new", 3);
    CHECK(file_equals(path, old, sizeof(old)));
    unlink(path);
    rmdir(dir);
    log_stop();
}

static void test_rate_limit(void)
{
    lp_rate_t r = {0};
    uint32_t t0 = 0xFFFFFF00u; /* across the 32-bit wrap */
    CHECK(lp_rate_allow(&r, t0, 2u));
    CHECK(lp_rate_allow(&r, t0 + 10u, 2u));
    CHECK(!lp_rate_allow(&r, t0 + 20u, 2u));
    CHECK_EQ(lp_rate_wait(&r, t0 + 20u), LP_RATE_US - 20u);
    CHECK(!lp_rate_allow(&r, t0 + LP_RATE_US - 1u, 2u));
    CHECK_EQ(lp_rate_wait(&r, t0 + LP_RATE_US), 0);
    CHECK(lp_rate_allow(&r, t0 + LP_RATE_US, 2u));
}

/* Frames the port wrote, read from the other end of a socket pair. */
static int read_frames(int fd, struct can_frame *out, int max)
{
    int k = 0;
    while (k < max && read(fd, &out[k], sizeof(out[k])) == (ssize_t)sizeof(out[k])) {
        k++;
    }
    return k;
}

/* Flush port p through tx (the loop's end of a pass), then what reached fd. */
static int sent_frames(lp_tx_t *tx, lp_port_t *p, int fd, struct can_frame *out, int max)
{
    (void)lp_tx_flush(tx, p, 1);
    return read_frames(fd, out, max);
}

/*
 * The simulated controller on a JD: bus-off sends nothing (not even the
 * heartbeat), the controller is back after 128 x 11 bits at its bit rate,
 * then EMCY 8140h "recovered from bus-off". The port sends into a socket
 * pair instead of a CAN socket.
 */
static void test_sim_bus_off(void)
{
    int sv[2];
    CHECK(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0, sv) == 0);
    log_start();
    _Alignas(max_align_t) unsigned char inst[sizeof(product_any_t)];
    uint8_t mem[CO_STORE_NVM_SIZE];
    lp_nvm_t n;
    char err[600];
    CHECK_EQ(lp_nvm_open(&n, "--nvm", NULL, mem, sizeof(mem), err, sizeof(err)), 0);
    lp_tx_t tx;
    memset(&tx, 0, sizeof(tx));
    tx.fd = sv[0]; /* a connected socket: no addresses */
    lp_port_t p;
    memset(&p, 0, sizeof(p));
    p.fd = -1;
    p.nvm = &n;
    p.iface = "pair";
    void *ports[1] = {&p};
    co_node_t *nodes[1];
    co_node_t *node;
    jd2xxx.create(&jd2xxx, inst, ports, nodes);
    node = nodes[0];
    uint32_t t = 0xFFFF0000u; /* the recovery deadline crosses the 32-bit wrap */
    co_node_start(node, t);
    struct can_frame f[64];
    CHECK(sent_frames(&tx, &p, sv[1], f, 64) >= 1); /* boot-up */
    /* 0x1017 := 10 ms heartbeat over SDO */
    co_frame_t req = {.id = 0x600u + node->node_id, .dlc = 8, .data = {0x2B, 0x17, 0x10, 0, 10, 0}};
    co_node_receive(node, &req, t);
    co_node_poll(node, t);
    CHECK_EQ(sent_frames(&tx, &p, sv[1], f, 64), 1);
    CHECK_EQ(f[0].data[0], 0x60);
    uint32_t kbps = product_kbps(&jd2xxx, node->bitrate);
    CHECK(kbps != 0u);
    uint32_t recovery = (LP_BUSOFF_RECOVERY_BITS * 1000u + kbps - 1u) / kbps;
    lp_sim_can(&p, CO_CAN_BUSOFF, t, 50000u, recovery);
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    co_node_set_can_state(node, lp_can_state(&p));
    /* 50 ms unusable bus, then the recovery: nothing is sent. */
    uint32_t end = t + 50000u + recovery;
    for (; co_time_before(t, end - 1000u); t += 1000u) {
        uint32_t d = lp_poll(&p, t);
        CHECK(d != CO_NEVER && d <= end - t);
        co_node_set_can_state(node, lp_can_state(&p));
        co_node_poll(node, t);
    }
    CHECK_EQ(sent_frames(&tx, &p, sv[1], f, 64), 0);
    /* The stack sends nothing while bus-off; the port would not either. */
    co_frame_t hb = {.id = 0x700u + node->node_id, .dlc = 1};
    unsigned long off = p.tx_off;
    CHECK(!co_port_can_send(&p, &hb));
    CHECK_EQ(p.tx_off, off + 1u);
    CHECK_EQ(sent_frames(&tx, &p, sv[1], f, 64), 0);
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    (void)lp_poll(&p, end - 1u);
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    CHECK_EQ(lp_poll(&p, end), CO_NEVER);
    CHECK_EQ(lp_can_state(&p), CO_CAN_ACTIVE);
    co_node_set_can_state(node, lp_can_state(&p));
    co_node_poll(node, end);
    int k = sent_frames(&tx, &p, sv[1], f, 64);
    bool emcy = false;
    for (int i = 0; i < k; i++) {
        emcy |= f[i].can_id == 0x80u + node->node_id && f[i].data[0] == 0x40 &&
                f[i].data[1] == 0x81;
    }
    CHECK(emcy);
    CHECK(strstr(log_text(), "back from bus-off") != NULL);
    /* `can active` during a long bus-off (longer than the port's cap of
     * half the clock): only the recovery is left. */
    lp_sim_can(&p, CO_CAN_BUSOFF, end, 3600000000u, recovery);
    (void)lp_poll(&p, end + 0x7FFFFFF0u);
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    lp_sim_can(&p, CO_CAN_ACTIVE, end + 10u, 0, recovery);
    (void)lp_poll(&p, end + 10u + recovery - 1u);
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    (void)lp_poll(&p, end + 10u + recovery);
    CHECK_EQ(lp_can_state(&p), CO_CAN_ACTIVE);
    /* Passive and warning stay until changed; a link down is bus-off. */
    lp_sim_can(&p, CO_CAN_PASSIVE, end, 0, recovery);
    (void)lp_poll(&p, end + 100000000u);
    CHECK_EQ(lp_can_state(&p), CO_CAN_PASSIVE);
    p.link = LP_LINK_DOWN;
    CHECK_EQ(lp_can_state(&p), CO_CAN_BUSOFF);
    p.link = LP_LINK_UP;
    lp_sim_can(&p, CO_CAN_ACTIVE, end, 0, recovery);
    CHECK_EQ(lp_can_state(&p), CO_CAN_ACTIVE);
    close(sv[0]);
    close(sv[1]);
    log_stop();
}

/*
 * The shared sending socket (lp_tx_t): frames wait in their ports' queues
 * until lp_tx_flush, then go out each port's in order, ports in order; a
 * full kernel queue (a socket pair with the least send buffer)
 * keeps the rest for the next flush, nothing lost or reordered; a port
 * that left the bus meanwhile loses its queue; a socket that refuses for
 * good loses the frame, logged, and the flush ends.
 */
static void test_tx_flush(void)
{
    int sv[2];
    CHECK(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0, sv) == 0);
    int small = 1; /* the kernel's least: a few datagrams in flight */
    CHECK(setsockopt(sv[0], SOL_SOCKET, SO_SNDBUF, &small, sizeof(small)) == 0);
    log_start();
    lp_tx_t tx;
    memset(&tx, 0, sizeof(tx));
    tx.fd = sv[0];
    tx.addressed = false;
    lp_port_t p[2];
    memset(p, 0, sizeof(p));
    for (unsigned i = 0; i < 2u; i++) {
        p[i].fd = -1;
        p[i].node = i;
        p[i].iface = "pair";
    }
    for (unsigned k = 0; k < 12u; k++) {
        co_frame_t f = {.id = (uint16_t)(0x181u + k), .dlc = 1, .data = {(uint8_t)k}};
        CHECK(co_port_can_send(&p[0], &f));
        f.id = (uint16_t)(0x281u + k);
        CHECK(co_port_can_send(&p[1], &f));
    }
    struct can_frame got[64];
    CHECK_EQ(read_frames(sv[1], got, 64), 0); /* nothing before the flush */
    CHECK_EQ(p[0].txn + p[1].txn, 24u);
    unsigned seen = 0;
    unsigned flushes = 0;
    uint16_t ids[24];
    while (flushes++ < 20u) {
        unsigned left = lp_tx_flush(&tx, p, 2);
        CHECK_EQ(left, p[0].txn + p[1].txn);
        int n = read_frames(sv[1], got, 64);
        for (int k = 0; k < n && seen < 24u; k++) {
            ids[seen++] = (uint16_t)got[k].can_id;
        }
        if (left == 0u) {
            break;
        }
        CHECK(n > 0); /* each flush got something through */
    }
    CHECK(flushes > 1u); /* the peer's queue was full at least once */
    CHECK_EQ(seen, 24u);
    CHECK_EQ(tx.frames, 24u);
    /* each port's frames in order (the two ports interleave by flush) */
    unsigned next0 = 0;
    unsigned next1 = 0;
    for (unsigned k = 0; k < seen; k++) {
        if (ids[k] < 0x281u) {
            CHECK_EQ(ids[k], 0x181u + next0++);
        } else {
            CHECK_EQ(ids[k], 0x281u + next1++);
        }
    }
    CHECK_EQ(next0, 12u);
    CHECK_EQ(next1, 12u);
    /* A port whose link went down after it queued: its frames are lost
     * (counted), the other port's go out. */
    co_frame_t f = {.id = 0x701, .dlc = 1};
    CHECK(co_port_can_send(&p[0], &f));
    CHECK(co_port_can_send(&p[1], &f));
    p[0].link = LP_LINK_DOWN;
    CHECK_EQ(lp_tx_flush(&tx, p, 2), 0);
    CHECK_EQ(p[0].tx_off, 1u);
    CHECK_EQ(read_frames(sv[1], got, 64), 1);
    p[0].link = LP_LINK_UP;
    /* The peer is gone: each frame is refused for good, lost and logged. */
    close(sv[1]);
    CHECK(co_port_can_send(&p[0], &f));
    CHECK(co_port_can_send(&p[1], &f));
    CHECK_EQ(lp_tx_flush(&tx, p, 2), 0);
    CHECK(strstr(log_text(), "node 0: CAN write on pair failed") != NULL);
    CHECK(strstr(log_text(), "node 1: CAN write on pair failed") != NULL);
    close(sv[0]);
    log_stop();
}

int main(void)
{
    RUN(test_eeprom_file);
    RUN(test_eeprom_not_a_file);
    RUN(test_eeprom_link_to_nothing);
    RUN(test_eeprom_lock);
    RUN(test_eeprom_hold_file);
    RUN(test_control_silent_clients);
    RUN(test_eeprom_corrupt_untouched);
    RUN(test_eeprom_save_fails);
    RUN(test_rate_limit);
    RUN(test_sim_bus_off);
    RUN(test_tx_flush);
    return h_finish();
}
