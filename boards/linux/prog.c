/*
 * prog.c - program download in the Linux program; see prog.h. The port
 * functions of co_port.h's "Program download" are here.
 */
#include "prog.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "can_port.h"
#include "co_sdo.h"
#include "log.h"

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static const co_od_entry_t loader_entries[] = {CO_PROGDL_LOADER_ENTRIES};

int lp_prog_build(lp_prog_t *g, const co_node_cfg_t *base, char *err, unsigned errlen)
{
    const co_od_t *od = base->od;
    if (od->count + COUNT(loader_entries) > LP_PROG_MAX_ENTRIES) {
        snprintf(err, errlen, "--program-download: the dictionary has %u entries, more than %u",
                 od->count, (unsigned)(LP_PROG_MAX_ENTRIES - COUNT(loader_entries)));
        return -1;
    }
    unsigned n = 0;
    bool put = false;
    for (uint16_t i = 0; i <= od->count; i++) {
        const co_od_entry_t *e = i < od->count ? &od->entries[i] : NULL;
        if (e != NULL && e->index >= 0x1F50u && e->index <= 0x1F57u) {
            snprintf(err, errlen, "--program-download: the dictionary has %04Xh already", e->index);
            return -1;
        }
        if (!put && (e == NULL || e->index > 0x1F57u)) { /* the table is sorted */
            memcpy(&g->entries[n], loader_entries, sizeof(loader_entries));
            n += COUNT(loader_entries);
            put = true;
        }
        if (e != NULL) {
            g->entries[n++] = *e;
        }
    }
    g->od.entries = g->entries;
    g->od.count = (uint16_t)n;
    /* 100Ah reads g->version (lp_prog_open fills it in): the product's
     * text while the build's own program runs, the image's program ID
     * after it when an image does. */
    g->version_base[0] = '\0';
    g->version_entry = NULL;
    for (unsigned i = 0; i < n; i++) {
        co_od_entry_t *e = &g->entries[i];
        if (e->index == 0x100Au && e->sub == 0u && e->type == CO_T_VSTR &&
            e->size < sizeof(g->version_base)) {
            memcpy(g->version_base, e->cdata, e->size);
            g->version_base[e->size] = '\0';
            memcpy(g->version, g->version_base, e->size + 1u); /* until lp_prog_open */
            e->cdata = g->version;
            g->version_entry = e;
        }
    }
    unsigned s = 0;
    for (const co_service_t *const *sv = base->services; sv != NULL && *sv != NULL; sv++) {
        if (s + 2u > COUNT(g->services)) {
            snprintf(err, errlen, "--program-download: the product has too many services");
            return -1;
        }
        g->services[s++] = *sv;
    }
    g->services[s++] = &co_progdl_service;
    g->services[s] = NULL;
    g->cfg = *base;
    g->cfg.od = &g->od;
    g->cfg.services = g->services;
    /* An image is more than the 4 bytes of an expedited transfer. */
    g->cfg.sdo_segmented = co_sdo_segmented;
    g->cfg.sdo_block = co_sdo_block;
    g->cfg.sdo_domain = co_progdl_domain;
    return 0;
}

/* 100Ah after a change of what runs (nothing to do without one). */
static void set_version(lp_prog_t *g)
{
    if (g->version_entry == NULL) {
        return;
    }
    if (g->own) {
        snprintf(g->version, sizeof(g->version), "%s", g->version_base);
    } else if (g->pd.state == CO_PROGDL_NO_PROGRAM) {
        snprintf(g->version, sizeof(g->version), "%s, no program", g->version_base);
    } else {
        snprintf(g->version, sizeof(g->version), "%s, program %08lX", g->version_base,
                 (unsigned long)g->pd.program_id);
    }
    g->version_entry->size = (uint8_t)strlen(g->version);
}

/* A node's numeric entry (0 when it has none: the product's table always
 * has 1000h and 1018h:1-2). */
static uint32_t node_value(co_node_t *node, uint16_t index, uint8_t sub)
{
    const co_od_entry_t *e = co_node_entry(node, index, sub);
    uint32_t v = 0;
    if (e == NULL || co_od_get(node, e, &v) != CO_OK) {
        return 0;
    }
    return v;
}

/* co_port_prog_check's answer for g's product; the stack checks the
 * identity itself, lp_prog_open here as a bootloader does. */
static uint8_t fits(const lp_prog_t *g, const co_image_hdr_t *h)
{
    if (h->board != CO_IMAGE_BOARD_LINUX || strcmp(h->id, g->prod_id) != 0) {
        return CO_PROGDL_FORMAT;
    }
    if (h->length > LP_PROG_MAX_LEN || h->load_addr != 0u) {
        return CO_PROGDL_ADDRESS;
    }
    return CO_PROGDL_OK;
}

/* Why FILE.prog (open as fd, size bytes) is no program this node runs,
 * or NULL when it is one (*h its header). */
static const char *check_installed(const lp_prog_t *g, int fd, off_t size, co_image_hdr_t *h)
{
    uint8_t buf[4096];
    if (size == 0) {
        return "empty (cleared)";
    }
    if (size < (off_t)CO_IMAGE_HDR_SIZE ||
        pread(fd, buf, CO_IMAGE_HDR_SIZE, 0) != CO_IMAGE_HDR_SIZE || !co_image_parse(buf, h)) {
        return "not an image";
    }
    if (fits(g, h) != CO_PROGDL_OK) {
        return "another product's or board's image";
    }
    if ((off_t)h->length != size) {
        return "its length is not the header's";
    }
    co_node_t *node = g->nodes[0];
    if (h->device_type != node_value(node, 0x1000, 0) || h->vendor != node_value(node, 0x1018, 1) ||
        h->product != node_value(node, 0x1018, 2)) {
        return "another identity (1000h, 1018h:1-2)";
    }
    uint32_t crc = co_crc32(0, buf + CO_IMAGE_CRC_FROM, CO_IMAGE_HDR_SIZE - CO_IMAGE_CRC_FROM);
    for (off_t at = CO_IMAGE_HDR_SIZE; at < size;) {
        ssize_t r = pread(fd, buf, sizeof(buf), at);
        if (r <= 0) {
            return "unreadable";
        }
        crc = co_crc32(crc, buf, (uint32_t)r);
        at += r;
    }
    return crc == h->crc ? NULL : "CRC error";
}

int lp_prog_open(lp_prog_t *g, const char *prod_id, const char *nvm_real, co_node_t *const nodes[],
                 unsigned n, char *err, unsigned errlen)
{
    g->fd = -1;
    g->prod_id = prod_id;
    g->nnodes = n;
    for (unsigned i = 0; i < n; i++) {
        g->nodes[i] = nodes[i];
    }
    /* The first node runs the loader's copy of its configuration. The
     * product's create() made the node with its own (co_node_init keeps
     * the pointer and nothing else; the node has not started): the copy
     * differs only by the entries and services of program download. */
    nodes[0]->cfg = &g->cfg;
    if (snprintf(g->path, sizeof(g->path), "%s.prog", nvm_real) >= (int)sizeof(g->path) ||
        snprintf(g->tmp, sizeof(g->tmp), "%s.prog.tmp", nvm_real) >= (int)sizeof(g->tmp)) {
        snprintf(err, errlen, "--program-download: %s: the name is too long", nvm_real);
        return -1;
    }
    if (unlink(g->tmp) == 0) {
        lp_log("program download: %s removed (a download cut short)", g->tmp);
    } else if (errno != ENOENT) {
        snprintf(err, errlen, "--program-download: %s: %s", g->tmp, strerror(errno));
        return -1;
    }
    int fd = open(g->path, O_RDONLY | O_CLOEXEC);
    if (fd < 0 && errno == ENOENT) {
        g->own = true;
        co_progdl_init(&g->pd, CO_PROGDL_STARTED, CO_PROGRAM_ID);
        lp_log("program download: no %s: the build's own program runs (1F56h:1 %08lX)", g->path,
               (unsigned long)CO_PROGRAM_ID);
        set_version(g);
        return 0;
    }
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "--program-download: %s: %s", g->path,
                 fd < 0 ? strerror(errno) : "not a regular file");
        if (fd >= 0) {
            close(fd);
        }
        return -1;
    }
    co_image_hdr_t h;
    const char *why = check_installed(g, fd, st.st_size, &h);
    close(fd);
    g->own = false;
    if (why != NULL) {
        co_progdl_init(&g->pd, CO_PROGDL_NO_PROGRAM, 0);
        lp_log("program download: %s: %s: no valid program (1F51h:1 reads 3), waiting for a "
               "download",
               g->path, why);
    } else {
        co_progdl_init(&g->pd, CO_PROGDL_STARTED, h.program_id);
        lp_log("program download: %s: program %08lX of %lu bytes runs", g->path,
               (unsigned long)h.program_id, (unsigned long)h.length);
    }
    set_version(g);
    return 0;
}

bool lp_prog_running(const lp_prog_t *g)
{
    return co_progdl_state(&g->pd) == CO_PROGDL_STARTED;
}

void lp_prog_close(lp_prog_t *g)
{
    if (g->fd >= 0) {
        close(g->fd);
        g->fd = -1;
    }
}

/* ---- co_port.h, program download ---------------------------------------- */

static lp_prog_t *prog_of(void *port)
{
    return ((lp_port_t *)port)->prog;
}

/* The directory of g's files on disk: a rename in it is durable once it
 * is. False when it could not be (logged). */
static bool sync_dir(const lp_prog_t *g)
{
    char dir[sizeof(g->path)];
    snprintf(dir, sizeof(dir), "%s", g->path);
    char *slash = strrchr(dir, '/');
    if (slash == NULL) {
        snprintf(dir, sizeof(dir), ".");
    } else {
        slash[slash == dir ? 1 : 0] = '\0';
    }
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    bool ok = dfd >= 0 && fsync(dfd) == 0;
    if (!ok) {
        lp_log("program download: %s: fsync: %s", dir, strerror(errno));
    }
    if (dfd >= 0) {
        close(dfd);
    }
    return ok;
}

/* The download's file made durable and renamed FILE.prog. */
static bool install_tmp(lp_prog_t *g)
{
    bool ok = fsync(g->fd) == 0;
    const char *step = "fsync";
    if (close(g->fd) != 0 && ok) {
        ok = false;
        step = "close";
    }
    g->fd = -1;
    if (ok && rename(g->tmp, g->path) != 0) {
        ok = false;
        step = "rename";
    }
    if (!ok) {
        lp_log("program download: %s: %s: %s", g->tmp, step, strerror(errno));
        return false;
    }
    return sync_dir(g);
}

struct co_progdl *co_port_progdl(void *port)
{
    return &prog_of(port)->pd;
}

uint8_t co_port_prog_check(void *port, const co_image_hdr_t *h)
{
    return fits(prog_of(port), h);
}

bool co_port_prog_clear(void *port)
{
    lp_prog_t *g = prog_of(port);
    lp_prog_close(g);
    /* FILE.prog replaced by an empty file: no valid program, also for a
     * process killed from now until the commit. */
    g->fd = open(g->tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (g->fd < 0) {
        lp_log("program download: clear: %s: %s", g->tmp, strerror(errno));
        return false;
    }
    if (!install_tmp(g)) {
        return false;
    }
    g->own = false;
    lp_log("program download: cleared (%s empty: no valid program)", g->path);
    return true;
}

bool co_port_prog_write(void *port, uint32_t at, const void *buf, uint32_t len)
{
    lp_prog_t *g = prog_of(port);
    if (at == 0u) {
        lp_prog_close(g);
        g->fd = open(g->tmp, O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (g->fd < 0) {
            lp_log("program download: %s: %s", g->tmp, strerror(errno));
            return false;
        }
    }
    /* Not fsync'ed piece by piece: a restart never reads the temporary
     * file (it removes it), so only the whole image must be durable, and
     * is, before it is renamed (co_port_prog_commit). */
    const uint8_t *b = buf;
    while (len > 0u && g->fd >= 0) {
        ssize_t w = pwrite(g->fd, b, len, (off_t)at);
        if (w <= 0) {
            lp_log("program download: %s: write: %s", g->tmp, strerror(errno));
            return false;
        }
        b += w;
        at += (uint32_t)w;
        len -= (uint32_t)w;
    }
    return g->fd >= 0;
}

bool co_port_prog_read(void *port, uint32_t at, void *buf, uint32_t len)
{
    lp_prog_t *g = prog_of(port);
    return g->fd >= 0 && pread(g->fd, buf, len, (off_t)at) == (ssize_t)len;
}

bool co_port_prog_commit(void *port, const co_image_hdr_t *h)
{
    lp_prog_t *g = prog_of(port);
    if (g->fd < 0 || !install_tmp(g)) {
        return false;
    }
    lp_log("program download: program %08lX of %lu bytes installed in %s (stopped until started)",
           (unsigned long)h->program_id, (unsigned long)h->length, g->path);
    return true;
}

void co_port_prog_start(void *port)
{
    lp_prog_t *g = prog_of(port);
    /* The installed program runs from now: the device resets into it and
     * boots up (every node of the instance), as an MCU's bootloader
     * starts its application. */
    set_version(g); /* the service set the state: started */
    for (unsigned i = 0; i < g->nnodes; i++) {
        co_node_request_reset(g->nodes[i], CO_RESET_NODE);
    }
    lp_log("program download: program %08lX started: reset node", (unsigned long)g->pd.program_id);
}

void co_port_prog_stop(void *port)
{
    lp_prog_t *g = prog_of(port);
    lp_log("program download: program %08lX stopped (no samples, PDOs or EMCY until started)",
           (unsigned long)g->pd.program_id);
}
