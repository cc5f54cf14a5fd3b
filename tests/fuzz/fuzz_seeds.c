/*
 * fuzz_seeds.c - writes the seed corpus of the fuzz harnesses (committed in
 * tests/fuzz/corpus/; tools/fuzz --seeds rewrites it): short sessions of
 * every product family built from the example frames of the manuals that
 * the unit tests check (tests/unit/test_*_manual.c), plus the situations
 * the invariants are about (guarding, stores with power cuts, stored images,
 * the clock's wrap, LSS, segmented and block transfer).
 *
 * Usage: fuzz_seeds DIR   writes DIR/node/<name> and DIR/flash_ee/<name>.
 * The input formats are in fuzz_format.h (node) and fuzz_flash_ee.c.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_format.h"

/* Product numbers (FZ_PRODUCT_IDS order). */
enum {
    P_X730_XY30 = 3,
    P_X730_Z360 = 7,
    P_X710_XY10 = 8,
    P_X710_Z360 = 15,
    P_GSH = 16,
    P_GSH_RED = 17,
    P_JD1 = 18,
    P_JD2 = 19,
    P_INX = 20,
    P_INY = 21,
};

typedef struct seed {
    uint8_t b[4096];
    size_t n;
} seed_t;

static void b8(seed_t *s, unsigned v)
{
    if (s->n < sizeof(s->b)) {
        s->b[s->n++] = (uint8_t)v;
    }
}

static void b16(seed_t *s, unsigned v)
{
    b8(s, v & 0xFFu);
    b8(s, v >> 8);
}

static void b32(seed_t *s, uint32_t v)
{
    b16(s, v & 0xFFFFu);
    b16(s, v >> 16);
}

/* Bytes written as hex text ("2B 17 10 00 14 00 00 00"). */
static void hex(seed_t *s, const char *h)
{
    while (*h != '\0') {
        char *end;
        unsigned long v = strtoul(h, &end, 16);
        if (end == h) {
            h++;
            continue;
        }
        b8(s, (unsigned)v);
        h = end;
    }
}

/* Header without stored images; clock 0 = 1 s, 1 = just before the wrap. */
static void begin(seed_t *s, unsigned product, unsigned clock, unsigned images)
{
    s->n = 0;
    b8(s, product);
    b8(s, clock);
    if (clock == 1u || clock == 3u) {
        b16(s, 300); /* 300 ms before the wrap */
    }
    b8(s, images);
}

static void op(seed_t *s, unsigned code, unsigned node)
{
    b8(s, code | (node << 7));
}

/* An SDO request to the node, the 8 bytes given. */
static void sdo(seed_t *s, unsigned node, const char *req)
{
    op(s, FZ_OP_SDO_RAW, node);
    b8(s, 0); /* DLC 8 */
    hex(s, req);
}

static void nmt(seed_t *s, unsigned cmd)
{
    op(s, FZ_OP_NMT, 0);
    b8(s, cmd); /* 0 start, 1 stop, 2 pre-operational, 3 reset node, 4 reset communication */
    b8(s, 0);   /* all nodes */
}

static void ms(seed_t *s, unsigned count)
{
    op(s, FZ_OP_ADVANCE, 0);
    b16(s, count);
    b8(s, 3); /* ms */
}

static void long_us(seed_t *s, uint32_t count, unsigned times)
{
    op(s, FZ_OP_ADVANCE_LONG, 0);
    b32(s, count);
    b8(s, times - 1u);
}

static void sync_(seed_t *s)
{
    op(s, FZ_OP_SYNC, 0);
    b8(s, 0);
    b8(s, 0);
}

static void guard(seed_t *s)
{
    op(s, FZ_OP_GUARD_RTR, 0);
    b8(s, 0);
}

static void pdo_rtr(seed_t *s)
{
    op(s, FZ_OP_PDO_RTR, 0);
    b8(s, 0);
}

static void save(seed_t *s, unsigned node)
{
    op(s, FZ_OP_STORE, node);
    b8(s, 0); /* 0x1010 sub 1 "save" */
}

/* Inputs of each product (product_t.inputs): the angles first. */
static unsigned n_inputs(unsigned product)
{
    switch (product) {
    case P_X730_Z360:
    case P_X710_Z360:
    case P_INX:
        return 1;
    case P_GSH:
    case P_GSH_RED:
    case P_JD2:
        return 3;
    default:
        return 2;
    }
}

/* Angles in millidegrees for the first inputs (limit 3600 deg: the value
 * is (u32 % (2 x 3600000 + 1)) - 3600000); the others stay. */
static void inputs(seed_t *s, unsigned product, unsigned n, const int32_t *mdeg)
{
    op(s, FZ_OP_INPUTS, 0);
    for (unsigned i = 0; i < n_inputs(product); i++) {
        if (i < n) {
            b8(s, 1);
            b32(s, (uint32_t)(mdeg[i] + 3600000));
        } else {
            b8(s, 0);
        }
    }
}

static void power_cycle(seed_t *s)
{
    op(s, FZ_OP_POWER_CYCLE, 0);
}

/* A "save" that loses power after budget EEPROM bytes. */
static void cut_save(seed_t *s, unsigned budget)
{
    op(s, FZ_OP_POWER_CUT, 0);
    b16(s, budget);
    op(s, FZ_OP_STORE, 0);
    b8(s, 0);
}

static const char *g_dir;

static void put(const char *harness, const char *name, const seed_t *s)
{
    char path[512];
    snprintf(path, sizeof(path), "%s/%s/%s", g_dir, harness, name);
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(s->b, 1, s->n, f) != s->n || fclose(f) != 0) {
        fprintf(stderr, "fuzz_seeds: cannot write %s\n", path);
        exit(1);
    }
}

/* ---- the node harness ------------------------------------------------------- */

/* The DST X730 manual's requests (tests/unit/test_dst_manual.c). */
static const char *const dst_manual[] = {
    "40 00 10 00 00 00 00 00", "40 00 18 00 00 00 00 00", "2B 17 10 00 14 00 00 00",
    "2B 00 18 05 14 00 00 00", "2F 00 18 02 F0 00 00 00", "2F 00 18 02 FD 00 00 00",
    "2F 00 40 00 02 00 00 00", "2B 14 60 00 64 00 00 00", "2F 11 60 00 03 00 00 00",
    "2B 00 60 00 64 00 00 00", "23 14 10 00 85 00 00 00", "22 01 20 00 01 00 00 00",
    "40 10 60 00 00 00 00 00", "40 01 40 00 00 00 00 00", "00 02 00 00 00 00 00 00",
};

static const char *const pf_manual[] = {
    "40 00 18 02 00 00 00 00", "2F 00 18 02 F0 00 00 00", "2F 00 18 02 FF 00 00 00",
    "2B 14 60 00 38 FF 00 00", "2B 12 60 00 00 00 00 00", "2F 11 60 00 02 00 00 00",
    "40 10 60 00 00 00 00 00", "40 13 60 00 00 00 00 00", "2B 00 60 00 0A 00 00 00",
    "40 01 20 00 00 00 00 00",
};

static const char *const gsh_manual[] = {
    "40 00 12 01 00 00 00 00", "40 00 18 01 00 00 00 00", "40 00 1A 01 00 00 00 00",
    "40 04 60 00 00 00 00 00", "40 00 68 00 00 00 00 00", "40 FF 67 00 00 00 00 00",
    "2B 00 18 05 E8 03 00 00", "2F 00 18 02 01 00 00 00", "23 00 10 00 00 00 00 00",
    "40 18 10 02 00 00 00 00",
};

static const char *const jd_manual[] = {
    "40 00 10 00 00 00 00 00", "22 00 18 03 E8 03 00 00", "22 00 60 00 64 00 00 00",
    "22 11 60 00 01 00 00 00", "40 10 60 00 00 00 00 00", "40 12 60 00 00 00 00 00",
    "22 00 31 00 0A 00 00 00", "40 03 10 01 00 00 00 00", "40 00 22 00 00 00 00 00",
    "22 17 10 00 E8 03 00 00",
};

static void manual(seed_t *s, unsigned node, const char *const *req, unsigned n)
{
    for (unsigned i = 0; i < n; i++) {
        sdo(s, node, req[i]);
        if (i % 4u == 3u) {
            ms(s, 50);
        }
    }
}

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

static void node_seeds(void)
{
    seed_t s;
    static const int32_t tilt[2] = {12500, -3000};

    /* Every product boots, answers the manual's requests, runs, saves. */
    static const struct {
        unsigned product;
        const char *name;
        const char *const *req;
        unsigned n;
    } fam[] = {
        {P_X730_XY30, "dst-x730-xy30-manual", dst_manual, COUNT(dst_manual)},
        {P_X730_Z360, "dst-x730-z360-manual", dst_manual, COUNT(dst_manual)},
        {P_X710_XY10, "dst-x710-xy10-manual", dst_manual, COUNT(dst_manual)},
        {P_X710_Z360, "dst-x710-z360-manual", dst_manual, COUNT(dst_manual)},
        {P_INX, "inx360d-manual", pf_manual, COUNT(pf_manual)},
        {P_INY, "iny360d-manual", pf_manual, COUNT(pf_manual)},
        {P_GSH, "gsh-a-manual", gsh_manual, COUNT(gsh_manual)},
        {P_GSH_RED, "gsh-a-redundant-manual", gsh_manual, COUNT(gsh_manual)},
        {P_JD1, "jd1xxx-manual", jd_manual, COUNT(jd_manual)},
        {P_JD2, "jd2xxx-manual", jd_manual, COUNT(jd_manual)},
    };
    for (unsigned i = 0; i < COUNT(fam); i++) {
        begin(&s, fam[i].product, 0, 0);
        inputs(&s, fam[i].product, 2, tilt);
        manual(&s, 0, fam[i].req, fam[i].n);
        nmt(&s, 0);
        ms(&s, 300);
        sync_(&s);
        pdo_rtr(&s);
        save(&s, 0);
        power_cycle(&s);
        sdo(&s, 0, "40 17 10 00 00 00 00 00");
        put("node", fam[i].name, &s);
    }

    /* The second node of the redundant GSH-A on its own. */
    begin(&s, P_GSH_RED, 0, 0);
    manual(&s, 1, gsh_manual, COUNT(gsh_manual));
    sdo(&s, 1, "2F 01 30 00 15 00 00 00");
    save(&s, 1);
    nmt(&s, 3);
    put("node", "gsh-a-redundant-node2", &s);

    /* Heartbeat across the 32-bit microsecond wrap, then a long sleep. */
    begin(&s, P_X730_XY30, 1, 0);
    sdo(&s, 0, "2B 17 10 00 14 00 00 00");
    nmt(&s, 0);
    ms(&s, 1000);
    long_us(&s, 0xF0000000u, 2);
    ms(&s, 100);
    put("node", "dst-heartbeat-wrap", &s);

    /* Power cuts during a save: at its start, in the middle, at its end. */
    static const unsigned cuts[3] = {0, 30, 59};
    for (unsigned i = 0; i < 3u; i++) {
        char name[64];
        begin(&s, P_X730_XY30, 0, 0);
        sdo(&s, 0, "2B 17 10 00 64 00 00 00");
        save(&s, 0);
        sdo(&s, 0, "2B 17 10 00 2C 01 00 00");
        cut_save(&s, cuts[i]);
        snprintf(name, sizeof(name), "dst-power-cut-%u", cuts[i]);
        put("node", name, &s);
    }
    begin(&s, P_JD2, 0, 0);
    sdo(&s, 0, "22 00 60 00 64 00 00 00");
    op(&s, FZ_OP_POWER_CUT, 0);
    b16(&s, 100);
    sdo(&s, 0, "23 00 23 00 55 AA AA 55"); /* save with reset */
    put("node", "jd2-power-cut-save-reset", &s);
    begin(&s, P_INY, 0, 0);
    op(&s, FZ_OP_POWER_CUT, 0);
    b16(&s, 40);
    sdo(&s, 0, "2B 17 10 00 E8 03 00 00"); /* stored at once */
    put("node", "iny360d-power-cut-autosave", &s);

    /* Node guarding and life guarding (P+F, JD), the event, the recovery. */
    begin(&s, P_INX, 0, 0);
    sdo(&s, 0, "2B 0C 10 00 64 00 00 00"); /* guard time 100 ms */
    sdo(&s, 0, "2F 0D 10 00 03 00 00 00"); /* life time factor 3 */
    nmt(&s, 0);
    for (unsigned i = 0; i < 4u; i++) {
        guard(&s);
        ms(&s, 100);
    }
    ms(&s, 400);
    guard(&s);
    put("node", "inx360d-life-guarding", &s);
    begin(&s, P_JD2, 3, 0);
    sdo(&s, 0, "22 0C 10 00 E8 03 00 00"); /* 1 s */
    sdo(&s, 0, "22 0D 10 00 05 00 00 00");
    nmt(&s, 0);
    guard(&s);
    long_us(&s, 4000000u, 1);
    guard(&s);
    long_us(&s, 6000000u, 1);
    put("node", "jd2-life-guarding-wrap", &s);

    /* Heartbeat consumer (JD): a producer, then silence. */
    begin(&s, P_JD2, 0, 0);
    sdo(&s, 0, "23 16 10 01 F4 01 05 00"); /* node 5, 500 ms */
    op(&s, FZ_OP_HEARTBEAT, 0);
    b8(&s, 0x85);
    b8(&s, 2);
    ms(&s, 400);
    op(&s, FZ_OP_HEARTBEAT, 0);
    b8(&s, 0x85);
    b8(&s, 2);
    ms(&s, 1000);
    put("node", "jd2-heartbeat-consumer", &s);

    /* LSS (JD): switch selective, configure, store, Fastscan, inquiries. */
    for (unsigned kind = 0; kind < 4u; kind++) {
        char name[64];
        begin(&s, kind % 2u == 0u ? P_JD2 : P_JD1, 0, 0);
        op(&s, FZ_OP_LSS_SEQUENCE, 0);
        b8(&s, kind);
        b8(&s, 0x20); /* node-ID 32 */
        b8(&s, 3);
        nmt(&s, 4);
        op(&s, FZ_OP_LSS_SEQUENCE, 0);
        b8(&s, 1);
        b8(&s, 0x82); /* node-ID 0xFF: unconfigured */
        b8(&s, 0);
        nmt(&s, 4);
        snprintf(name, sizeof(name), "jd-lss-%u", kind);
        put("node", name, &s);
    }

    /* Segmented and block transfers (JD, P+F, GSH-A). */
    static const unsigned xfer_products[3] = {P_JD2, P_INY, P_GSH};
    for (unsigned i = 0; i < 3u; i++) {
        char name[64];
        begin(&s, xfer_products[i], 0, 0);
        op(&s, FZ_OP_SDO_SEG_READ, 0); /* 0x1008, the device name */
        b8(&s, FZ_TARGET_RAW);
        b16(&s, 0x1008);
        b8(&s, 0);
        b8(&s, 4);
        b8(&s, 0);
        op(&s, FZ_OP_SDO_BLK_READ, 0);
        b8(&s, FZ_TARGET_RAW);
        b16(&s, 0x1008);
        b8(&s, 0);
        b8(&s, 0);
        b8(&s, 9);
        b8(&s, 1);
        b8(&s, 0);
        b8(&s, 9);
        op(&s, FZ_OP_SDO_SEG_WRITE, 0); /* 0x1017 = 1000 */
        b8(&s, FZ_TARGET_RAW);
        b16(&s, 0x1017);
        b8(&s, 0);
        b8(&s, FZ_VAL_U16);
        b16(&s, 1000);
        b8(&s, 0);
        b8(&s, 0);
        b8(&s, 0);
        op(&s, FZ_OP_SDO_BLK_WRITE, 0); /* 0x1017 = 500 */
        b8(&s, FZ_TARGET_RAW);
        b16(&s, 0x1017);
        b8(&s, 0);
        b8(&s, FZ_VAL_U16);
        b16(&s, 500);
        b8(&s, 0);
        b8(&s, 0);
        b8(&s, 0);
        snprintf(name, sizeof(name), "transfers-%u", xfer_products[i]);
        put("node", name, &s);
    }

    /* TPDO mapping changed (P+F): invalidate, remap, validate, request. */
    begin(&s, P_INY, 0, 0);
    sdo(&s, 0, "23 00 18 01 81 01 00 80");
    sdo(&s, 0, "2F 00 1A 00 00 00 00 00");
    sdo(&s, 0, "23 00 1A 01 10 00 20 60");
    sdo(&s, 0, "2F 00 1A 00 01 00 00 00");
    sdo(&s, 0, "23 00 18 01 81 01 00 00");
    sdo(&s, 0, "2F 00 18 02 FD 00 00 00");
    nmt(&s, 0);
    pdo_rtr(&s);
    put("node", "iny360d-remap", &s);

    /* Event-driven PDOs with an inhibit time, after a long quiet spell (JD). */
    begin(&s, P_JD2, 0, 0);
    sdo(&s, 0, "22 00 18 01 8A 01 00 80");
    sdo(&s, 0, "22 00 18 03 E8 03 00 00");
    sdo(&s, 0, "22 00 18 02 FE 00 00 00");
    sdo(&s, 0, "22 00 18 01 8A 01 00 00");
    sdo(&s, 0, "22 00 18 05 00 00 00 00");
    nmt(&s, 0);
    ms(&s, 20);
    long_us(&s, 0x90000000u, 1);
    inputs(&s, P_JD2, 2, tilt);
    ms(&s, 200);
    put("node", "jd2-event-inhibit-quiet", &s);

    /* Stored images at power-on: changed entries, garbage, a flipped byte. */
    static const unsigned img_products[4] = {P_X730_XY30, P_JD2, P_INX, P_GSH_RED};
    for (unsigned i = 0; i < 4u; i++) {
        char name[64];
        begin(&s, img_products[i], 0, 3);
        b8(&s, (FZ_IMG_ENTRIES << 3) | 0u); /* PARA slot 0 */
        b8(&s, 5);
        b8(&s, 0);
        b8(&s, 2);
        b8(&s, 7);
        b32(&s, 0x3E8u);
        b8(&s, 20);
        b32(&s, 2u);
        b8(&s, (FZ_IMG_FLIPPED << 3) | 4u); /* PARA slot 1, newer, broken */
        b8(&s, 6);
        b8(&s, 0);
        b8(&s, 0);
        b8(&s, 30);
        b8(&s, 0x10);
        b8(&s, (FZ_IMG_RAW << 3) | 2u); /* LSS slot 0: garbage */
        b8(&s, 0);
        b8(&s, 0);
        b8(&s, 28);
        hex(&s,
            "43 6F 50 53 DE AD BE EF 01 00 00 00 01 00 00 00 02 00 00 03 00 00 00 00 0A 03 FF FF");
        sdo(&s, 0, "40 00 10 00 00 00 00 00");
        nmt(&s, 0);
        ms(&s, 200);
        snprintf(name, sizeof(name), "stored-image-%u", img_products[i]);
        put("node", name, &s);
    }

    /* The CAN controller: passive, bus-off, back; a full transmit queue. */
    begin(&s, P_JD2, 0, 0);
    sdo(&s, 0, "22 17 10 00 64 00 00 00");
    op(&s, FZ_OP_CAN_STATE, 0);
    b8(&s, 2);
    ms(&s, 300);
    op(&s, FZ_OP_CAN_STATE, 0);
    b8(&s, 3);
    ms(&s, 300);
    op(&s, FZ_OP_CAN_STATE, 0);
    b8(&s, 0);
    op(&s, FZ_OP_TX_FULL, 0);
    b8(&s, 1);
    sdo(&s, 0, "40 00 10 00 00 00 00 00");
    op(&s, FZ_OP_TX_FULL, 0);
    b8(&s, 0);
    ms(&s, 300);
    put("node", "jd2-can-states", &s);

    /* Faults and inputs at the limits (DST error behaviour, P+F EMCYs). */
    begin(&s, P_X730_XY30, 0, 0);
    sdo(&s, 0, "2F 00 40 00 02 00 00 00");
    nmt(&s, 0);
    static const int32_t beyond[2] = {40000, -3600000};
    inputs(&s, P_X730_XY30, 2, beyond);
    ms(&s, 500);
    op(&s, FZ_OP_FAULTS, 0);
    b8(&s, 1);
    ms(&s, 100);
    nmt(&s, 0);
    put("node", "dst-limits-faults", &s);
    begin(&s, P_INY, 0, 0);
    nmt(&s, 0);
    op(&s, FZ_OP_FAULTS, 0);
    b8(&s, 7);
    ms(&s, 100);
    op(&s, FZ_OP_FAULTS, 0);
    b8(&s, 0);
    ms(&s, 100);
    put("node", "iny360d-faults", &s);

    /* Restore defaults ("load"), group saves (JD), an EEPROM that fails. */
    begin(&s, P_JD2, 0, 0);
    sdo(&s, 0, "22 00 30 00 1F 00 00 00");
    sdo(&s, 0, "23 10 10 04 73 61 76 65");
    sdo(&s, 0, "23 11 10 02 6C 6F 61 64");
    nmt(&s, 3);
    op(&s, FZ_OP_NVM_READ_FAIL, 0);
    b8(&s, 1);
    power_cycle(&s);
    put("node", "jd2-groups-load-nvm-fail", &s);
}

/* ---- the flash EEPROM harness ------------------------------------------------ */

static void flash_seeds(void)
{
    seed_t s;
    /* Product, page size (0..6: 64 << n), pages - 1, contents, then ops. */
    static const struct {
        unsigned product, page, pages, contents;
        const char *name;
    } cfg[] = {
        {P_X730_XY30, 4, 3, 0, "dst-1k-erased"},   {P_X730_XY30, 4, 7, 2, "dst-1k-records"},
        {P_X710_XY10, 2, 3, 0, "dst-256-erased"},  {P_JD2, 5, 3, 0, "jd2-2k-erased"},
        {P_JD2, 6, 9, 3, "jd2-4k-zeros"},          {P_INX, 4, 3, 2, "inx-1k-records"},
        {P_GSH_RED, 4, 7, 0, "gsh-red-1k-erased"}, {P_GSH_RED, 2, 7, 2, "gsh-red-256-records"},
        {P_JD1, 1, 3, 0, "jd1-128-too-small"},     {P_X730_Z360, 0, 3, 0, "dst-64-too-small"},
    };
    for (unsigned i = 0; i < COUNT(cfg); i++) {
        s.n = 0;
        b8(&s, cfg[i].product);
        b8(&s, cfg[i].page);
        b8(&s, cfg[i].pages);
        b8(&s, cfg[i].contents);
        if (cfg[i].contents == 2u) {
            b8(&s, 1); /* one byte changed */
            b16(&s, 30);
            b8(&s, 0x04);
        }
        b8(&s, 0); /* a write: heartbeat-ish entry */
        b8(&s, 8);
        b32(&s, 1000);
        b8(&s, 1); /* a full save, cut at every step */
        b8(&s, 0);
        b8(&s, 0); /* another write */
        b8(&s, 20);
        b32(&s, 2);
        b8(&s, 2); /* a save cut at step 17 */
        b8(&s, 0);
        b16(&s, 17);
        b8(&s, 3); /* a plain save, a power cycle */
        b8(&s, 0);
        b8(&s, 1); /* a "load", cut at every step */
        b8(&s, 2);
        put("flash_ee", cfg[i].name, &s);
    }
    /* Arbitrary page sizes and contents, the emulation's own API. */
    s.n = 0;
    b8(&s, P_X730_XY30);
    b8(&s, 7);
    b16(&s, 999); /* 1000-byte pages */
    b8(&s, 3);
    b8(&s, 1);
    b16(&s, 64); /* 64 bytes of the input as flash contents */
    for (unsigned i = 0; i < 64u; i++) {
        b8(&s, i * 7u);
    }
    b8(&s, 5);
    b8(&s, 1); /* write */
    b16(&s, 0);
    b8(&s, 8);
    hex(&s, "43 6F 50 53 00 00 00 00");
    b8(&s, 5);
    b8(&s, 0); /* read across a slot */
    b16(&s, 190);
    b8(&s, 4);
    b8(&s, 1);
    b8(&s, 0);
    put("flash_ee", "odd-geometry-api", &s);
    s.n = 0;
    b8(&s, P_JD2);
    b8(&s, 7);
    b16(&s, 192); /* 193: odd */
    b8(&s, 3);
    b8(&s, 0);
    b8(&s, 1);
    b8(&s, 0);
    put("flash_ee", "odd-page-size", &s);
    /* The node-ID commit of the DSTs and the JD's save with reset. */
    s.n = 0;
    b8(&s, P_X710_Z360);
    b8(&s, 4);
    b8(&s, 3);
    b8(&s, 0);
    b8(&s, 1);
    b8(&s, 5);
    b8(&s, 0x20);
    b8(&s, 4);
    put("flash_ee", "dst-node-id-commit", &s);
    s.n = 0;
    b8(&s, P_JD1);
    b8(&s, 4);
    b8(&s, 3);
    b8(&s, 0);
    b8(&s, 1);
    b8(&s, 4);
    b8(&s, 1);
    b8(&s, 8); /* a group save (sub 3), cut at every step */
    put("flash_ee", "jd1-save-reset-groups", &s);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: fuzz_seeds DIR (writes DIR/node/* and DIR/flash_ee/*)\n");
        return 2;
    }
    g_dir = argv[1];
    node_seeds();
    flash_seeds();
    return 0;
}
