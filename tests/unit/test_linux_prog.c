/*
 * test_linux_prog.c - program download in the Linux program (prog.h):
 * the loader's dictionary on a product, its program area as files beside
 * the EEPROM file, and a process killed at each point of an update. The
 * node runs with the program's own port (can_port.c, nvm_file.c, prog.c),
 * its frames going into a socket pair, driven over SDO as a master drives
 * it (CiA 302-3): the flow of tests/integration/test_progdl.py, which
 * needs vcan, on the machine's clock-free unit harness.
 */
#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include "can_port.h"
#include "co_image.h"
#include "co_port.h"
#include "dst.h"
#include "jd.h"
#include "prog.h"

#include "harness.h"

/* One device: a product instance with its EEPROM file and program area,
 * its port sending into a socket pair. Powered by dev_on, "killed" by
 * dev_off: nothing is finished or flushed, as after SIGKILL. */
typedef struct box {
    const product_t *prod;
    _Alignas(max_align_t) unsigned char inst[sizeof(product_any_t)];
    uint8_t mem[PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE];
    lp_nvm_t nvm;
    lp_port_t port[PRODUCT_MAX_NODES];
    lp_tx_t tx;
    int sv[2];
    unsigned n;
    co_node_t *nodes[PRODUCT_MAX_NODES];
    co_node_t *node; /* nodes[0], the loader */
    lp_prog_t prog;
    uint32_t t;
    char err[600];
} box_t;

static char dir[] = "/tmp/co-prog-XXXXXX";
static char nvm_path[256];
static char prog_path[300];
static char tmp_path[300];

static void dev_on(box_t *d, const product_t *p)
{
    memset(d, 0, sizeof(*d));
    d->prod = p;
    CHECK(socketpair(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0, d->sv) == 0);
    d->n = p->nodes;
    CHECK_EQ(lp_nvm_open(&d->nvm, "--nvm", nvm_path, d->mem, d->n * CO_STORE_NVM_SIZE, d->err,
                         sizeof(d->err)),
             0);
    d->tx.fd = d->sv[0];
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned i = 0; i < d->n; i++) {
        d->port[i].fd = -1;
        d->port[i].node = i;
        d->port[i].nvm = &d->nvm;
        d->port[i].iface = "pair";
        ports[i] = &d->port[i];
    }
    p->create(p, d->inst, ports, d->nodes);
    d->node = d->nodes[0];
    CHECK_EQ(lp_prog_build(&d->prog, co_cfg(d->node), d->err, sizeof(d->err)), 0);
    CHECK_EQ(lp_prog_open(&d->prog, p->id, d->nvm.real, d->nodes, d->n, d->err, sizeof(d->err)), 0);
    d->t = 1000u;
    for (unsigned i = 0; i < d->n; i++) {
        d->port[i].prog = &d->prog;
        d->port[i].progdl = &d->prog.pd;
        co_node_start(d->nodes[i], d->t);
    }
}

static void dev_off(box_t *d)
{
    close(d->sv[0]);
    close(d->sv[1]);
    if (d->prog.fd >= 0) {
        close(d->prog.fd); /* the kernel's part of a kill */
    }
}

/* The frames the node sent since the last call (at most max). */
static int sent(box_t *d, struct can_frame *f, int max)
{
    (void)lp_tx_flush(&d->tx, d->port, d->n);
    int k = 0;
    while (k < max && read(d->sv[1], &f[k], sizeof(f[k])) == (ssize_t)sizeof(f[k])) {
        k++;
    }
    return k;
}

/* One request to the node, its poll, and the SDO answer (or the frame
 * with id want if given); returns false when none came. */
static bool request(box_t *d, uint32_t id, const uint8_t data[8], struct can_frame *answer)
{
    co_frame_t req = {.id = (uint16_t)id, .dlc = 8};
    memcpy(req.data, data, 8);
    d->t += 100u;
    co_node_receive(d->node, &req, d->t);
    co_node_poll(d->node, d->t);
    struct can_frame f[32];
    int k = sent(d, f, 32);
    for (int i = 0; i < k; i++) {
        if (f[i].can_id == 0x580u + co_node_id(d->node)) {
            *answer = f[i];
            return true;
        }
    }
    return false;
}

static uint32_t le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* Expedited upload of index:sub; the value, or the abort code with bit 63. */
static uint64_t sdo_read(box_t *d, uint16_t index, uint8_t sub)
{
    uint8_t r[8] = {0x40, (uint8_t)index, (uint8_t)(index >> 8), sub};
    struct can_frame a;
    if (!request(d, 0x600u + co_node_id(d->node), r, &a)) {
        return 1ull << 62;
    }
    if (a.data[0] == 0x80) {
        return (1ull << 63) | le32(a.data + 4);
    }
    return le32(a.data + 4);
}

/* Expedited download of a U8; 0 or the abort code. */
static uint32_t sdo_write_u8(box_t *d, uint16_t index, uint8_t sub, uint8_t v)
{
    uint8_t r[8] = {0x2F, (uint8_t)index, (uint8_t)(index >> 8), sub, v};
    struct can_frame a;
    if (!request(d, 0x600u + co_node_id(d->node), r, &a)) {
        return 0xFFFFFFFFu;
    }
    return a.data[0] == 0x60 ? 0u : le32(a.data + 4);
}

/* Segmented download of len bytes of buf into 1F50h:1, stopped after
 * `upto` bytes when upto < len (the master gone: nothing more is sent).
 * 0 or the abort code. */
static uint32_t download(box_t *d, const uint8_t *buf, uint32_t len, uint32_t upto)
{
    uint32_t id = 0x600u + co_node_id(d->node);
    uint8_t r[8] = {0x21, 0x50, 0x1F, 1};
    r[4] = (uint8_t)len;
    r[5] = (uint8_t)(len >> 8);
    r[6] = (uint8_t)(len >> 16);
    r[7] = (uint8_t)(len >> 24);
    struct can_frame a;
    if (!request(d, id, r, &a)) {
        return 0xFFFFFFFFu;
    }
    if (a.data[0] == 0x80) {
        return le32(a.data + 4);
    }
    uint8_t toggle = 0;
    for (uint32_t at = 0; at < len && at < upto; at += 7u) {
        uint32_t n = len - at < 7u ? len - at : 7u;
        uint8_t s[8] = {0};
        s[0] = (uint8_t)(toggle | ((7u - n) << 1) | (at + n == len ? 1u : 0u));
        memcpy(s + 1, buf + at, n);
        if (!request(d, id, s, &a)) {
            return 0xFFFFFFFFu;
        }
        if (a.data[0] == 0x80) {
            return le32(a.data + 4);
        }
        toggle ^= 0x10u;
    }
    return 0;
}

/* Polls until 1F57h:1 is not busy (bounded); its value. */
static uint32_t flash_status(box_t *d)
{
    uint64_t v = 0;
    for (int i = 0; i < 10000; i++) {
        d->t += 1000u;
        co_node_poll(d->node, d->t);
        v = sdo_read(d, 0x1F57, 1);
        if ((v & 1u) == 0u) {
            return (uint32_t)v;
        }
    }
    FAIL("1F57h:1 stays busy");
    return (uint32_t)v;
}

static void put32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

/* An image for the Linux program of product p (its identity read from
 * node), program ID pid, with a payload of n bytes; its length. */
static uint32_t make_image(uint8_t *img, const product_t *p, co_node_t *node, uint32_t pid,
                           uint32_t n)
{
    uint32_t len = CO_IMAGE_HDR_SIZE + n;
    memset(img, 0, CO_IMAGE_HDR_SIZE);
    memcpy(img, "COIM", 4);
    img[4] = CO_IMAGE_HDR_SIZE;
    img[6] = CO_IMAGE_VERSION;
    put32(img + 8, len);
    put32(img + 16, CO_IMAGE_BOARD_LINUX);
    uint32_t v = 0;
    CHECK_EQ(co_od_get(node, co_node_entry(node, 0x1000, 0), &v), CO_OK);
    put32(img + 20, v);
    CHECK_EQ(co_od_get(node, co_node_entry(node, 0x1018, 1), &v), CO_OK);
    put32(img + 24, v);
    CHECK_EQ(co_od_get(node, co_node_entry(node, 0x1018, 2), &v), CO_OK);
    put32(img + 28, v);
    put32(img + 36, pid);
    memcpy(img + 48, p->id, strlen(p->id));
    for (uint32_t i = 0; i < n; i++) {
        img[CO_IMAGE_HDR_SIZE + i] = (uint8_t)(i * 7u + 3u);
    }
    put32(img + 12, co_crc32(0, img + CO_IMAGE_CRC_FROM, len - CO_IMAGE_CRC_FROM));
    return len;
}

static off_t file_size(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 ? st.st_size : -1;
}

static bool file_is(const char *path, const uint8_t *data, uint32_t len)
{
    static uint8_t buf[8192];
    int fd = open(path, O_RDONLY);
    if (fd < 0) {
        return false;
    }
    ssize_t n = read(fd, buf, sizeof(buf));
    close(fd);
    return n == (ssize_t)len && memcmp(buf, data, len) == 0;
}

/* 100Ah as uploaded (segmented when longer than 4 bytes), into out. */
static void read_version(box_t *d, char *out, size_t cap)
{
    uint32_t id = 0x600u + co_node_id(d->node);
    uint8_t r[8] = {0x40, 0x0A, 0x10, 0};
    struct can_frame a;
    out[0] = '\0';
    if (!request(d, id, r, &a) || a.data[0] == 0x80) {
        FAIL("100Ah not read");
        return;
    }
    if ((a.data[0] & 0x02u) != 0u) { /* expedited */
        size_t n = 4u - ((a.data[0] >> 2) & 3u);
        memcpy(out, a.data + 4, n);
        out[n] = '\0';
        return;
    }
    size_t at = 0;
    uint8_t toggle = 0;
    for (;;) {
        uint8_t s[8] = {(uint8_t)(0x60u | toggle)};
        if (!request(d, id, s, &a) || (a.data[0] & 0xE0u) != 0u) {
            FAIL("100Ah segment");
            return;
        }
        size_t n = 7u - ((a.data[0] >> 1) & 7u);
        if (at + n < cap) {
            memcpy(out + at, a.data + 1, n);
            at += n;
        }
        out[at] = '\0';
        if ((a.data[0] & 1u) != 0u) {
            return;
        }
        toggle ^= 0x10u;
    }
}

/* NMT command cs to the node, and a poll. */
static void nmt(box_t *d, uint8_t cs)
{
    co_frame_t f = {.id = 0, .dlc = 2, .data = {cs, co_node_id(d->node)}};
    d->t += 100u;
    co_node_receive(d->node, &f, d->t);
    co_node_poll(d->node, d->t);
}

#define ABORT(code) ((1ull << 63) | (code))

static uint8_t img[4096];
static uint8_t img2[4096];

/* Stop, clear, download, verify, start on a DST X730 (expedited SDO only
 * in its manual: the loader's copy adds segmented and block): the node
 * boots up again as the new program, which a restart runs too. */
static void test_update(void)
{
    static box_t d;
    dev_on(&d, &dst_x730_xy30);
    struct can_frame f[32];
    CHECK(sent(&d, f, 32) >= 1); /* boot-up */
    nmt(&d, 0x80);
    /* Before any download: the build's own program. */
    CHECK(access(prog_path, F_OK) != 0);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), CO_PROGRAM_ID);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), 0);
    CHECK_EQ(sdo_read(&d, 0x1F50, 1), ABORT(0x06010001u));
    char v[100];
    read_version(&d, v, sizeof(v));
    CHECK(strcmp(v, "1.24") == 0);
    uint32_t len = make_image(img, &dst_x730_xy30, d.node, 0x01020304u, 1000);
    /* A download without a clear: refused, the program runs on. */
    CHECK_EQ(download(&d, img, len, len), 0x08000022u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    CHECK(access(prog_path, F_OK) != 0);
    /* Stop: the product's work halts; the node answers on. */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 0), 0);
    d.t += 100u;
    co_node_poll(d.node, d.t);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 0);
    CHECK(!lp_prog_running(&d.prog));
    unsigned before = d.port[0].txn;
    co_frame_t tpdo = {.id = (uint16_t)(0x180u + co_node_id(d.node)), .dlc = 8};
    CHECK(co_port_can_send(&d.port[0], &tpdo)); /* not made: nothing queued */
    CHECK_EQ(d.port[0].txn, before);
    /* Clear: FILE.prog empty (no valid program, also after a kill). */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
    CHECK_EQ(file_size(prog_path), 0);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 3);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0);
    CHECK_EQ(download(&d, img, len, len), 0);
    CHECK_EQ(flash_status(&d), 0);
    CHECK(file_is(prog_path, img, len));
    CHECK(access(tmp_path, F_OK) != 0);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0x01020304u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 0);
    /* Start: the answer, then a reset with its boot-up, as the new program. */
    (void)sent(&d, f, 32);
    uint8_t start[8] = {0x2F, 0x51, 0x1F, 1, 1};
    struct can_frame a;
    CHECK(request(&d, 0x600u + co_node_id(d.node), start, &a));
    CHECK_EQ(a.data[0], 0x60);
    bool boot = false;
    for (int i = 0; i < 5 && !boot; i++) {
        d.t += 1000u;
        co_node_poll(d.node, d.t);
        int k = sent(&d, f, 32);
        for (int j = 0; j < k; j++) {
            boot |= f[j].can_id == 0x700u + co_node_id(d.node) && f[j].len == 1 &&
                    f[j].data[0] == 0;
        }
    }
    CHECK(boot);
    CHECK(lp_prog_running(&d.prog));
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0x01020304u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    read_version(&d, v, sizeof(v));
    CHECK(strcmp(v, "1.24, program 01020304") == 0);
    dev_off(&d);
    /* Power again: the installed program runs. */
    dev_on(&d, &dst_x730_xy30);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0x01020304u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    dev_off(&d);
}

/* Stop and clear as a master does (pre-operational first); returns with
 * the node cleared. */
static void stop_clear(box_t *d)
{
    nmt(d, 0x80);
    CHECK_EQ(sdo_write_u8(d, 0x1F51, 1, 0), 0);
    d->t += 100u;
    co_node_poll(d->node, d->t);
    CHECK_EQ(sdo_write_u8(d, 0x1F51, 1, 3), 0);
}

/* The state a restart finds: no valid program, same identity, and ready
 * for a download (a clear first) that then completes. */
static void check_no_program_then_update(box_t *d, uint32_t pid)
{
    CHECK_EQ(sdo_read(d, 0x1F51, 1), 3);
    CHECK_EQ(sdo_read(d, 0x1F56, 1), 0);
    CHECK_EQ(sdo_read(d, 0x1F57, 1), CO_PROGDL_NO_VALID << 1);
    CHECK(!lp_prog_running(&d->prog));
    uint32_t dt = 0;
    CHECK_EQ(co_od_get(d->node, co_node_entry(d->node, 0x1000, 0), &dt), CO_OK);
    CHECK_EQ(sdo_read(d, 0x1000, 0), dt);
    CHECK(access(tmp_path, F_OK) != 0); /* a download's leftover is gone */
    uint32_t len = make_image(img2, d->prod, d->node, pid, 700);
    nmt(d, 0x80);
    CHECK_EQ(sdo_write_u8(d, 0x1F51, 1, 3), 0);
    CHECK_EQ(download(d, img2, len, len), 0);
    CHECK_EQ(flash_status(d), 0);
    CHECK_EQ(sdo_write_u8(d, 0x1F51, 1, 1), 0);
    for (int i = 0; i < 3; i++) { /* the start after the answer, then the reset */
        d->t += 1000u;
        co_node_poll(d->node, d->t);
    }
    CHECK_EQ(sdo_read(d, 0x1F56, 1), pid);
    CHECK_EQ(sdo_read(d, 0x1F51, 1), 1);
}

/*
 * A process killed at each point of an update (a JD2xxx, block-capable in
 * its manual): after the stop the old program comes back; from the clear
 * to the commit no valid program, whatever part of the image was written
 * (never a part of it run); after the commit the new one. Each time the
 * next update completes.
 */
static void test_killed(void)
{
    static box_t d;
    const product_t *p = &jd2xxx;
    unlink(prog_path);
    unlink(nvm_path);
    /* A program installed first (the "old" one). */
    dev_on(&d, p);
    uint32_t len = make_image(img, p, d.node, 0x11u, 2000);
    stop_clear(&d);
    CHECK_EQ(download(&d, img, len, len), 0);
    CHECK_EQ(flash_status(&d), 0);
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 1), 0);
    dev_off(&d);
    /* Killed after the stop: the old program. */
    dev_on(&d, p);
    nmt(&d, 0x80);
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 0), 0);
    dev_off(&d);
    dev_on(&d, p);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0x11u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    dev_off(&d);
    /* Killed after the clear, and at several points of the download. */
    static const uint32_t cut[] = {0, 7, 63, 64, 700, 1995, 2064};
    for (unsigned i = 0; i < sizeof(cut) / sizeof(cut[0]); i++) {
        dev_on(&d, p);
        if (sdo_read(&d, 0x1F51, 1) == 1) {
            stop_clear(&d);
        } else {
            nmt(&d, 0x80);
            CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
        }
        uint32_t n = make_image(img, p, d.node, 0x20u + i, 2000);
        if (cut[i] > 0u) {
            CHECK_EQ(download(&d, img, n, cut[i]), 0);
            /* Beyond the server's buffer the file holds a part of it. */
            CHECK(cut[i] < 2u * CO_SDO_BUF || cut[i] == n || access(tmp_path, F_OK) == 0);
        }
        dev_off(&d);
        dev_on(&d, p);
        if (cut[i] == n) { /* the whole image: the check ran at the next polls, or not */
            CHECK(sdo_read(&d, 0x1F51, 1) == 3 || sdo_read(&d, 0x1F56, 1) == 0x20u + i);
            dev_off(&d);
            continue;
        }
        check_no_program_then_update(&d, 0x30u + i);
        dev_off(&d);
    }
    /* Killed after the commit, before the start: the new program, whole. */
    dev_on(&d, p);
    stop_clear(&d);
    uint32_t n = make_image(img, p, d.node, 0x40u, 1500);
    CHECK_EQ(download(&d, img, n, n), 0);
    CHECK_EQ(flash_status(&d), 0);
    dev_off(&d);
    dev_on(&d, p);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0x40u);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
    CHECK(file_is(prog_path, img, n));
    dev_off(&d);
}

/*
 * Refusals after the clear: another product's image, a truncated one, a
 * wrong CRC, another board's: 08000020h with 1F57h status 2 or 3, the
 * device with no valid program and its identity, and the next download
 * completes. A damaged FILE.prog found at a start is no program.
 */
static void test_refused(void)
{
    static box_t d;
    const product_t *p = &dst_x730_xy30;
    unlink(prog_path);
    unlink(nvm_path);
    dev_on(&d, p);
    stop_clear(&d);
    uint32_t n;
    /* Another product (its ID, and its identity). */
    n = make_image(img, &jd2xxx, d.node, 5, 300);
    CHECK_EQ(download(&d, img, n, n), 0x08000020u);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), CO_PROGDL_FORMAT << 1);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 3);
    /* Another board. */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
    n = make_image(img, p, d.node, 5, 300);
    put32(img + 16, CO_IMAGE_BOARD_RV32_VIRT);
    put32(img + 12, co_crc32(0, img + CO_IMAGE_CRC_FROM, n - CO_IMAGE_CRC_FROM));
    CHECK_EQ(download(&d, img, n, n), 0x08000020u);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), CO_PROGDL_FORMAT << 1);
    /* Not an image at all. */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
    n = make_image(img, p, d.node, 5, 300);
    img[0] = 'X';
    CHECK_EQ(download(&d, img, n, n), 0x08000020u);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), CO_PROGDL_UNKNOWN << 1);
    /* Truncated: the transfer ends before the header's length. */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
    n = make_image(img, p, d.node, 5, 300);
    CHECK_EQ(download(&d, img, n - 10u, n - 10u), 0x08000020u);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), CO_PROGDL_FORMAT << 1);
    /* A wrong CRC. */
    CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 3), 0);
    n = make_image(img, p, d.node, 5, 300);
    img[200] ^= 1u;
    CHECK_EQ(download(&d, img, n, n), 0x08000020u);
    CHECK_EQ(sdo_read(&d, 0x1F57, 1), CO_PROGDL_FORMAT << 1);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 3);
    CHECK_EQ(file_size(prog_path), 0); /* nothing installed by a refusal */
    /* Killed now: no valid program, and the next update completes. */
    dev_off(&d);
    dev_on(&d, p);
    check_no_program_then_update(&d, 0x77u);
    dev_off(&d);
    /* FILE.prog damaged on disk (a byte of the payload): no program. */
    int fd = open(prog_path, O_RDWR);
    CHECK(fd >= 0);
    uint8_t b = 0;
    CHECK(pread(fd, &b, 1, 100) == 1);
    b ^= 0xFFu;
    CHECK(pwrite(fd, &b, 1, 100) == 1);
    close(fd);
    dev_on(&d, p);
    CHECK_EQ(sdo_read(&d, 0x1F51, 1), 3);
    CHECK_EQ(sdo_read(&d, 0x1F56, 1), 0);
    dev_off(&d);
}

/* Every product with the option: an update by segmented SDO ends in the
 * boot-up of each of its nodes (both of a two-node product) as the new
 * program. */
static void test_every_product(void)
{
    static box_t d;
    for (size_t i = 0; product_list[i] != NULL; i++) {
        const product_t *p = product_list[i];
        uint32_t pid = 0x500u + (uint32_t)i;
        unlink(prog_path);
        unlink(nvm_path);
        dev_on(&d, p);
        struct can_frame f[64];
        (void)sent(&d, f, 64);
        CHECK_EQ(sdo_read(&d, 0x1F56, 1), CO_PROGRAM_ID);
        stop_clear(&d);
        uint32_t n = make_image(img, p, d.node, pid, 500);
        CHECK_EQ(download(&d, img, n, n), 0);
        CHECK_EQ(flash_status(&d), 0);
        (void)sent(&d, f, 64);
        CHECK_EQ(sdo_write_u8(&d, 0x1F51, 1, 1), 0);
        unsigned booted = 0;
        for (int k = 0; k < 5; k++) {
            d.t += 1000u;
            for (unsigned j = 0; j < d.n; j++) {
                co_node_poll(d.nodes[j], d.t);
            }
            int m = sent(&d, f, 64);
            for (int j = 0; j < m; j++) {
                for (unsigned q = 0; q < d.n; q++) {
                    if (f[j].can_id == 0x700u + co_node_id(d.nodes[q]) && f[j].len == 1 &&
                        f[j].data[0] == 0) {
                        booted |= 1u << q;
                    }
                }
            }
        }
        if (booted != (1u << d.n) - 1u) {
            fprintf(stderr, "%s: boot-ups of nodes %#x\n", p->id, booted);
            FAIL("not every node booted up after the start");
        }
        CHECK_EQ(sdo_read(&d, 0x1F56, 1), pid);
        CHECK_EQ(sdo_read(&d, 0x1F51, 1), 1);
        dev_off(&d);
    }
}

/* The dictionary: the loader's entries put in order into the product's,
 * 100Ah reading the manual's text until an image runs; the product's own
 * configuration untouched. */
static void test_dictionary(void)
{
    static lp_prog_t g;
    char err[200];
    CHECK_EQ(lp_prog_build(&g, dst_x730_xy30.cfg, err, sizeof(err)), 0);
    CHECK_EQ(g.od.count, dst_x730_xy30.cfg->od->count + 8u);
    for (uint16_t i = 1; i < g.od.count; i++) {
        const co_od_entry_t *a = &g.od.entries[i - 1u];
        const co_od_entry_t *b = &g.od.entries[i];
        CHECK(a->index < b->index || (a->index == b->index && a->sub < b->sub));
    }
    CHECK(co_od_find(&g.od, 0x1F50, 1, NULL) != NULL);
    CHECK(co_od_find(dst_x730_xy30.cfg->od, 0x1F50, 1, NULL) == NULL);
    CHECK(g.cfg.sdo_segmented != NULL && g.cfg.sdo_block != NULL && g.cfg.sdo_domain != NULL);
    CHECK(dst_x730_xy30.cfg->sdo_segmented == NULL);
    CHECK(co_cfg_has_service(&g.cfg, &co_progdl_service));
    CHECK(!co_cfg_has_service(dst_x730_xy30.cfg, &co_progdl_service));
    CHECK(g.version_entry != NULL && strcmp(g.version, "1.24") == 0);
    /* A table that has the objects already is refused. */
    static lp_prog_t g2;
    CHECK_EQ(lp_prog_build(&g2, &g.cfg, err, sizeof(err)), -1);
    CHECK(strstr(err, "1F50h already") != NULL);
}

int main(void)
{
    CHECK(mkdtemp(dir) != NULL);
    snprintf(nvm_path, sizeof(nvm_path), "%s/eeprom.nvm", dir);
    snprintf(prog_path, sizeof(prog_path), "%s.prog", nvm_path);
    snprintf(tmp_path, sizeof(tmp_path), "%s.prog.tmp", nvm_path);
    FILE *log = tmpfile();
    lp_log_open(log);
    RUN(test_dictionary);
    RUN(test_update);
    RUN(test_killed);
    RUN(test_refused);
    RUN(test_every_product);
    lp_log_open(NULL);
    fclose(log);
    unlink(prog_path);
    unlink(tmp_path);
    unlink(nvm_path);
    char lock[300];
    snprintf(lock, sizeof(lock), "%s.lock", nvm_path);
    unlink(lock);
    rmdir(dir);
    return h_finish();
}
