/*
 * control.c - the control socket (control.h).
 */
#include "control.h"

#include "co_common.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

/* A unix path that exists: a socket that refuses connections is stale
 * (its process died without removing it) and may go; anything else stays
 * and the start is refused, so that a second program never steals a
 * running one's socket nor a file is deleted. */
static int unix_path_free(const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (lstat(path, &st) != 0) {
        return 0;
    }
    if (!S_ISSOCK(st.st_mode)) {
        snprintf(err, errlen, "--control unix:%s: the path exists and is not a socket", path);
        return -2;
    }
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof(sa.sun_path), "%s", path);
    int r = fd < 0 ? -1 : connect(fd, (const struct sockaddr *)&sa, sizeof(sa));
    int e = errno;
    if (fd >= 0) {
        close(fd);
    }
    if (r == 0 || e != ECONNREFUSED) {
        snprintf(err, errlen, "--control unix:%s: a socket in use (another canopen-sensor?)", path);
        return -2;
    }
    unlink(path); /* stale */
    return 0;
}

/* PORT of tcp:PORT, 1..65535 (decimal digits only), or 0. */
static long tcp_port(const char *port)
{
    size_t digits = strspn(port, "0123456789"); /* no sign, no blanks */
    long p = digits == 0u || digits > 5u || port[digits] != '\0' ? 0 : strtol(port, NULL, 10);
    return p >= 1 && p <= 65535 ? p : 0;
}

bool ctl_spec_ok(const char *spec, char *err, size_t errlen)
{
    struct sockaddr_un sa;
    if (strncmp(spec, "unix:", 5) == 0) {
        const char *path = spec + 5;
        if (path[0] == '\0' || strlen(path) >= sizeof(sa.sun_path)) {
            snprintf(err, errlen, "--control unix:%s: empty or longer than %zu bytes", path,
                     sizeof(sa.sun_path) - 1u);
            return false;
        }
        return true;
    }
    if (strncmp(spec, "tcp:", 4) == 0) {
        if (tcp_port(spec + 4) == 0) {
            snprintf(err, errlen, "--control tcp:%s: not a port 1..65535", spec + 4);
            return false;
        }
        return true;
    }
    snprintf(err, errlen, "--control %s: give unix:PATH or tcp:PORT", spec);
    return false;
}

static int open_unix(ctl_t *c, const char *path, char *err, size_t errlen)
{
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    int r = unix_path_free(path, err, errlen);
    if (r != 0) {
        return r;
    }
    snprintf(sa.sun_path, sizeof(sa.sun_path), "%s", path);
    c->fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (c->fd < 0 || bind(c->fd, (const struct sockaddr *)&sa, sizeof(sa)) != 0 ||
        listen(c->fd, 8) != 0) {
        snprintf(err, errlen, "--control unix:%s: %s", path, strerror(errno));
        return errno == ENOENT || errno == EACCES || errno == EADDRINUSE ? -2 : -1;
    }
    snprintf(c->path, sizeof(c->path), "%s", path);
    return 0;
}

static int open_tcp(ctl_t *c, const char *port, char *err, size_t errlen)
{
    long p = tcp_port(port);
    struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons((uint16_t)p)};
    sa.sin_addr.s_addr = htonl(INADDR_LOOPBACK); /* localhost only: no password */
    c->fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1;
    if (c->fd < 0 || setsockopt(c->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one)) != 0 ||
        bind(c->fd, (const struct sockaddr *)&sa, sizeof(sa)) != 0 || listen(c->fd, 8) != 0) {
        snprintf(err, errlen, "--control tcp:%s: %s", port, strerror(errno));
        return errno == EADDRINUSE || errno == EACCES ? -2 : -1;
    }
    return 0;
}

int ctl_open(ctl_t *c, const char *spec, char *err, size_t errlen)
{
    memset(c, 0, sizeof(*c));
    c->fd = -1;
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        c->cl[k].fd = -1;
    }
    if (!ctl_spec_ok(spec, err, errlen)) {
        return -2;
    }
    return strncmp(spec, "unix:", 5) == 0 ? open_unix(c, spec + 5, err, errlen)
                                          : open_tcp(c, spec + 4, err, errlen);
}

/* One answer line; a client that cannot take it at once is dropped. */
static bool reply(ctl_client_t *k, const char *text)
{
    char out[CMD_REPLY_MAX + 1u];
    size_t len = cmd_answer_line(text, out);
    return send(k->fd, out, len, MSG_NOSIGNAL | MSG_DONTWAIT) == (ssize_t)len;
}

static void drop(ctl_client_t *k)
{
    close(k->fd);
    k->fd = -1;
    k->lines = (cmd_lines_t){0};
}

/* Client k told why (if it can take the line at once) and closed. */
static void close_silent(ctl_client_t *k, uint32_t now, const char *why)
{
    char text[96];
    snprintf(text, sizeof(text), "error: silent for %lu s: closed%s",
             (unsigned long)((now - k->last) / 1000000u), why);
    (void)reply(k, text);
    drop(k);
}

int ctl_accept(ctl_t *c, uint32_t now)
{
    int fd = accept4(c->fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) {
        return -1;
    }
    unsigned quiet = 0; /* the client silent longest */
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        if (c->cl[k].fd < 0) {
            quiet = k;
            break;
        }
        if (now - c->cl[k].last > now - c->cl[quiet].last) {
            quiet = k;
        }
    }
    ctl_client_t *cl = &c->cl[quiet];
    if (cl->fd >= 0 && now - cl->last >= CTL_EVICT_US) {
        close_silent(cl, now, " (every slot taken: a new client has it)");
    }
    if (cl->fd < 0) {
        memset(cl, 0, sizeof(*cl));
        cl->fd = fd;
        cl->last = now;
        return (int)quiet;
    }
    ctl_client_t tmp = {.fd = fd};
    (void)reply(&tmp, "error: too many control clients");
    close(fd);
    return -1;
}

uint32_t ctl_expire(ctl_t *c, uint32_t now)
{
    uint32_t wait = UINT32_MAX;
    if (c->fd < 0) {
        return wait; /* never opened: the slots are not clients */
    }
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        ctl_client_t *cl = &c->cl[k];
        if (cl->fd < 0) {
            continue;
        }
        if (now - cl->last >= CTL_IDLE_US) {
            close_silent(cl, now, "");
        } else {
            wait = co_min_u32(wait, CTL_IDLE_US - (now - cl->last));
        }
    }
    return wait;
}

/* A complete line of client k: answered into its buffer. */
static void line_done(ctl_client_t *k, ctl_line_fn fn, void *ctx)
{
    char out[CMD_REPLY_MAX + 1u];
    char err[64];
    const char *line = cmd_lines_take(&k->lines, err, sizeof(err));
    if (line == NULL) {
        snprintf(out, sizeof(out), "error: %s", err);
    } else {
        out[0] = '\0';
        fn(ctx, line, out, sizeof(out));
    }
    k->olen += cmd_answer_line(out, k->out + k->olen); /* room was checked (out_room) */
}

/* Hand waiting answers to the kernel (what it takes is the client's sign
 * of life at now); false when the client is gone. */
static bool flush_out(ctl_client_t *k, uint32_t now)
{
    while (k->olen > 0u) {
        ssize_t n = send(k->fd, k->out, k->olen, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
            return true;
        }
        if (n <= 0) {
            return false;
        }
        memmove(k->out, k->out + n, k->olen - (size_t)n);
        k->olen -= (size_t)n;
        k->last = now;
    }
    return true;
}

/* Room for one more answer. */
static bool out_room(const ctl_client_t *k)
{
    return CTL_OUT - k->olen >= CMD_REPLY_MAX + 1u;
}

/* Look at the read bytes while their answers fit. */
static void take_input(ctl_client_t *cl, ctl_line_fn fn, void *ctx)
{
    while (cl->ipos < cl->ilen && out_room(cl)) {
        if (cmd_lines_put(&cl->lines, cl->in[cl->ipos++])) {
            line_done(cl, fn, ctx);
        }
    }
}

bool ctl_read(ctl_t *c, unsigned k, ctl_line_fn fn, void *ctx, uint32_t now)
{
    if (k >= CTL_CLIENTS || c->cl[k].fd < 0) {
        return false;
    }
    ctl_client_t *cl = &c->cl[k];
    if (!flush_out(cl, now)) {
        drop(cl);
        return false;
    }
    take_input(cl, fn, ctx); /* what an earlier call left */
    if (cl->ipos >= cl->ilen && out_room(cl)) {
        ssize_t n = recv(cl->fd, cl->in, sizeof(cl->in), MSG_DONTWAIT);
        if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
            n = -1;
        } else if (n <= 0) {
            drop(cl); /* gone: a partial line is discarded */
            return false;
        }
        if (n > 0) {
            cl->last = now;
            cl->ipos = 0;
            cl->ilen = (size_t)n;
            take_input(cl, fn, ctx);
        }
    }
    if (!flush_out(cl, now)) {
        drop(cl);
        return false;
    }
    /* The kernel took answers: the lines that waited for room go on
     * (at most the CTL_IN bytes read; the loop ends when those are done
     * or the kernel is full, then EPOLLOUT brings the client back). */
    while (cl->ipos < cl->ilen && out_room(cl)) {
        take_input(cl, fn, ctx);
        if (!flush_out(cl, now)) {
            drop(cl);
            return false;
        }
    }
    return true;
}

uint32_t ctl_events(const ctl_t *c, unsigned k)
{
    const ctl_client_t *cl = &c->cl[k];
    uint32_t ev = 0;
    if (cl->ipos >= cl->ilen && out_room(cl)) {
        ev |= EPOLLIN;
    }
    if (cl->olen > 0u) {
        ev |= EPOLLOUT;
    }
    return ev;
}

/*
 * Whether c->path still leads to our listening socket: a user may have
 * removed it and started another program on the path meanwhile, whose
 * socket must stay. Not told by the device and inode recorded at bind:
 * tmpfs gives a freed inode number to the next file at once. Instead a
 * connection is made through the path: it arrives here or not (a unix
 * connect completes at once while the backlog has room). Connections
 * waiting from before are taken first, so that what arrives after the
 * probe came through the path now. (Between this and the unlink another
 * program could still take the path: a window of microseconds that no
 * call closes.)
 */
static bool path_is_ours(const ctl_t *c)
{
    int in;
    while ((in = accept4(c->fd, NULL, NULL, SOCK_CLOEXEC)) >= 0) {
        close(in); /* a client that came too late */
    }
    struct sockaddr_un sa = {.sun_family = AF_UNIX};
    snprintf(sa.sun_path, sizeof(sa.sun_path), "%s", c->path);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    bool ours = false;
    if (fd >= 0 && connect(fd, (const struct sockaddr *)&sa, sizeof(sa)) == 0) {
        in = accept4(c->fd, NULL, NULL, SOCK_CLOEXEC);
        ours = in >= 0;
        if (in >= 0) {
            close(in);
        }
    }
    if (fd >= 0) {
        close(fd);
    }
    return ours;
}

void ctl_close(ctl_t *c)
{
    if (c->fd < 0) {
        return; /* never opened (the clients' slots may be all zero) */
    }
    for (unsigned k = 0; k < CTL_CLIENTS; k++) {
        if (c->cl[k].fd >= 0) {
            drop(&c->cl[k]);
        }
    }
    if (c->path[0] != '\0' && path_is_ours(c)) {
        unlink(c->path);
    }
    close(c->fd);
    c->fd = -1;
}
