/*
 * store.c - parameter store on the board's EEPROM emulation.
 * See co_store.h for the record format and the power-cut argument.
 */
#include "co_store.h"

#include <string.h>

#include "co_node.h"
#include "co_port.h"

#define STORE_MAGIC 0x53506F43u /* "CoPS" */
#define FLAG_DEFAULTS 0x01u

/* What one slot holds, from check_slot(). */
typedef struct slot_info {
    bool present; /* the magic is there */
    bool valid;   /* header, length, layout and CRC all check out */
    uint8_t flags;
    uint32_t seq;
    uint32_t writes;
    uint32_t len;
} slot_info_t;

/* The newest valid record of a class, from newest(). Only the fields its
 * callers use, not a whole slot_info_t: on the Cortex-M0 that answer costs
 * 128 bytes more code and 56 more of stack. */
typedef struct newest {
    int8_t k;     /* its slot, -1: none */
    bool present; /* some slot has the magic (a record, maybe a broken one) */
    bool hw;      /* a read failed */
    uint8_t flags;
    uint32_t seq;
    uint32_t writes;
    uint32_t len;
} newest_t;

uint32_t co_store_layout_hash(const co_node_t *node, co_cls_t cls)
{
    /* FNV-1a over (index, sub, size, offset) of every entry with RAM in cls.
     * Size and offset hash as 16-bit numbers (high bytes 0), as when the
     * entries held them so: sets stored by older firmware stay valid. */
    uint32_t h = 2166136261u;
    const co_od_t *od = co_cfg(node)->od;
    for (uint16_t i = 0; i < od->count; i++) {
        const co_od_entry_t *e = &od->entries[i];
        if (e->cls != cls) {
            continue;
        }
        uint8_t k[7] = {(uint8_t)e->index, (uint8_t)(e->index >> 8), e->sub, e->size, 0, e->off, 0};
        for (unsigned j = 0; j < sizeof(k); j++) {
            h = (h ^ k[j]) * 16777619u;
        }
    }
    return h ^ co_cfg(node)->ram_size[cls];
}

/* Not inlined: six callers; 24 bytes less in every MCU image. */
static CO_NOINLINE uint32_t slot_addr(const co_node_t *node, co_cls_t cls, unsigned copy)
{
    unsigned c = (cls == CO_CLS_PARA) ? 0u : 1u;
    return node->nvm_base + (c * 2u + copy) * CO_STORE_SLOT;
}

static bool stored_class(const co_node_t *node, co_cls_t cls)
{
    return (cls == CO_CLS_PARA || cls == CO_CLS_LSS) && co_cfg(node)->ram_size[cls] != 0u &&
           node->ram[cls] != NULL;
}

/* Read and verify one slot without touching any live value. The header
 * buffer is reused for the data and the CRC once the header is parsed. */
static slot_info_t check_slot(co_node_t *node, co_cls_t cls, unsigned copy, bool *hw_error)
{
    slot_info_t s = {0};
    uint32_t a = slot_addr(node, cls, copy);
    uint8_t h[CO_STORE_HDR];
    if (!co_port_nvm_read(node->port, a, h, sizeof(h))) {
        *hw_error = true;
        return s;
    }
    /* Erased NVM (0xFF: a new EEPROM, a blank file) holds nothing; anything
     * else in the magic's place is a record, maybe a broken one (random
     * bytes, zeros). A save writes the magic first, so a save cut short
     * leaves an erased magic only where it wrote nothing at all. */
    uint32_t magic = co_get_u32(&h[0]);
    s.present = magic != 0xFFFFFFFFu;
    if (magic != STORE_MAGIC) {
        return s;
    }
    s.seq = co_get_u32(&h[8]);
    s.writes = co_get_u32(&h[12]);
    s.len = co_get_u16(&h[16]);
    s.flags = h[18];
    bool defaults = (s.flags & FLAG_DEFAULTS) != 0u;
    uint32_t want = defaults ? 0u : co_cfg(node)->ram_size[cls];
    if (h[19] != (uint8_t)cls || s.len != want ||
        co_get_u32(&h[4]) != co_store_layout_hash(node, cls)) {
        return s;
    }
    uint32_t crc = co_crc32(0, h, sizeof(h));
    for (uint32_t at = 0; at < s.len; at += sizeof(h)) {
        uint32_t n = co_min_u32(sizeof(h), s.len - at);
        if (!co_port_nvm_read(node->port, a + CO_STORE_HDR + at, h, n)) {
            *hw_error = true;
            return s;
        }
        crc = co_crc32(crc, h, n);
    }
    if (!co_port_nvm_read(node->port, a + CO_STORE_HDR + s.len, h, 4)) {
        *hw_error = true;
        return s;
    }
    s.valid = co_get_u32(h) == crc;
    return s;
}

/* Both slots checked: the newest valid one. Not inlined, so that its
 * buffers are off the stack again before a caller writes a record. */
static CO_NOINLINE newest_t newest(co_node_t *node, co_cls_t cls)
{
    newest_t r = {.k = -1};
    for (unsigned copy = 0; copy < 2u; copy++) {
        slot_info_t s = check_slot(node, cls, copy, &r.hw);
        r.present = r.present || s.present;
        if (s.valid && (r.k < 0 || (int32_t)(s.seq - r.seq) > 0)) {
            r.k = (int8_t)copy;
            r.flags = s.flags;
            r.seq = s.seq;
            r.writes = s.writes;
            r.len = s.len;
        }
    }
    return r;
}

/* The slot a record of cls is written to next: the other than the newest
 * valid record's, slot 0 when there is none. */
static unsigned target(const newest_t *nw)
{
    return nw->k == 0 ? 1u : 0u;
}

/* Offer the slot the next save of cls writes to the board to erase ahead
 * (co_port_nvm_prepare). Only beside a valid record: the target then holds
 * an older record or a save cut short, which nothing reads again. With no
 * valid record (a blank or a corrupt set) nothing is erased, so that a
 * corrupt set stays reported as such after a power cycle; its save then
 * erases on its own path. Returns the newest record found, which
 * co_store_init needs too (one read of both slots). */
static newest_t prepare(co_node_t *node, co_cls_t cls)
{
    newest_t nw = newest(node, cls);
    if (nw.k >= 0 && !nw.hw) { /* a slot not read could hold the newest */
        co_port_nvm_prepare(node->port, slot_addr(node, cls, target(&nw)), CO_STORE_SLOT);
    }
    return nw;
}

void co_store_init(co_node_t *node)
{
    /* Every save counts once, in every class's newest record from then on:
     * the count is the largest of them (co_node_init() zeroed it). */
    for (unsigned cls = CO_CLS_PARA; cls <= CO_CLS_LSS; cls++) {
        if (stored_class(node, (co_cls_t)cls)) {
            /* The slot offered before the boot-up: nobody waits. */
            newest_t nw = prepare(node, (co_cls_t)cls);
            if (nw.k >= 0 && nw.writes > node->store.writes) {
                node->store.writes = nw.writes;
            }
        }
    }
}

/* Defaults: from the dictionary; the LSS struct's from the node config and
 * the node's factory node-ID; a product's own node-ID object (id_index)
 * gets the factory node-ID when one was set for this node. */
static void set_defaults(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi)
{
    co_od_defaults(node, cls, lo, hi);
    if (cls == CO_CLS_LSS) {
        co_lss_para_t *l = node->ram[CO_CLS_LSS];
        l->node_id = co_node_factory_id(node);
        l->bitrate = co_cfg(node)->default_bitrate;
    }
    uint16_t ix = co_cfg(node)->id_index;
    if (ix != 0u && node->factory_id != 0u && ix >= lo && ix <= hi) {
        const co_od_entry_t *e = co_node_entry(node, ix, 0);
        if (CO_CHECK(e != NULL && e->cls == CO_CLS_PARA) && cls == CO_CLS_PARA) {
            (void)co_od_store(node, e, (uint32_t)(node->factory_id - co_cfg(node)->id_offset));
        }
    }
}

/* Read the newest valid record's entries of class cls with index in
 * [lo, hi] into RAM, or their defaults. */
static co_store_status_t load(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi)
{
    newest_t nw = newest(node, cls);
    int k = nw.k;
    co_store_status_t st;
    if (k < 0) {
        st = nw.hw ? CO_STORE_HW : nw.present ? CO_STORE_CORRUPT : CO_STORE_BLANK;
    } else if ((nw.flags & FLAG_DEFAULTS) != 0u) {
        st = CO_STORE_DEFAULTS;
    } else {
        st = CO_STORE_OK;
    }
    uint32_t data = slot_addr(node, cls, (unsigned)k) + CO_STORE_HDR;
    if (st == CO_STORE_OK && lo == 0u && hi == 0xFFFFu) {
        /* Verified: now copy what was asked for, straight from NVM. */
        if (!co_port_nvm_read(node->port, data, node->ram[cls], nw.len)) {
            st = CO_STORE_HW;
        }
    } else if (st == CO_STORE_OK) {
        const co_od_t *od = co_cfg(node)->od;
        for (uint16_t i = 0; i < od->count && st == CO_STORE_OK; i++) {
            const co_od_entry_t *e = &od->entries[i];
            if (e->cls == cls && e->index >= lo && e->index <= hi &&
                !co_port_nvm_read(node->port, data + e->off, (uint8_t *)node->ram[cls] + e->off,
                                  e->size)) {
                st = CO_STORE_HW;
            }
        }
    }
    if (st != CO_STORE_OK) {
        set_defaults(node, cls, lo, hi);
    }
    return st;
}

/* A restored record passed its CRC, but its values must also pass what an
 * SDO write of each would (a set written by other firmware, or forged with
 * a valid CRC): each one that fails is set to its default and the set is
 * marked corrupt. The whole class is checked, also after a partial
 * restore: the rest holds values that passed before or came by SDO. */
void co_store_validate(co_node_t *node, co_cls_t cls)
{
    const co_od_t *od = co_cfg(node)->od;
    const co_od_entry_t *end = od->entries + od->count;
    for (const co_od_entry_t *e = od->entries; e < end; e++) {
        if (e->cls == cls && !co_od_validate(node, e)) {
            node->store.status[cls] = CO_STORE_CORRUPT;
        }
    }
}

co_store_status_t co_store_restore(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi)
{
    if (!stored_class(node, cls)) {
        return CO_STORE_BLANK;
    }
    /* A partial restore of a set a full one found wanting stays reported:
     * the values outside the range were not read again. */
    bool still_corrupt = !(lo == 0u && hi == 0xFFFFu) &&
                         node->store.status[cls] == CO_STORE_CORRUPT;
    co_store_status_t st = load(node, cls, lo, hi);
    node->store.status[cls] = (uint8_t)(st == CO_STORE_OK && still_corrupt ? CO_STORE_CORRUPT : st);
    return st;
}

void co_store_mark_corrupt(co_node_t *node, co_cls_t cls)
{
    if (CO_CHECK(cls == CO_CLS_PARA || cls == CO_CLS_LSS)) {
        node->store.status[cls] = CO_STORE_CORRUPT;
    }
}

void co_store_report_emcy(co_node_t *node)
{
    uint8_t st = node->nmt.state;
    if (st != CO_NMT_PREOP && st != CO_NMT_OPERATIONAL) {
        return; /* raised when EMCY may be sent again */
    }
    bool bad = false;
    for (unsigned cls = CO_CLS_PARA; cls <= CO_CLS_LSS; cls++) {
        uint8_t s = node->store.status[cls];
        bad = bad || s == CO_STORE_CORRUPT || s == CO_STORE_HW;
    }
    (void)co_emcy_error(node, CO_EMCY_DATA_SET, 0, bad, NULL);
}

bool co_store_limit_reached(const co_node_t *node)
{
    uint32_t lim = co_cfg(node)->store_write_limit;
    return lim != 0u && node->store.writes >= lim;
}

/* A group write: entries of the class with index in [lo, hi] come from
 * RAM (or their defaults, for a group restore), the others keep what the
 * newest record holds (their defaults when there is none). */
typedef struct group {
    uint16_t lo, hi;
    bool defaults; /* the group's entries take their default values */
    int from;      /* slot holding the record to keep the rest from; -1: defaults */
} group_t;

/* Bytes [at, at + n) of the record data for class cls. */
static bool record_chunk(co_node_t *node, co_cls_t cls, const group_t *g, uint32_t at, uint8_t *out,
                         uint32_t n)
{
    memcpy(out, (const uint8_t *)node->ram[cls] + at, n);
    if (g == NULL) {
        return true;
    }
    const co_od_t *od = co_cfg(node)->od;
    for (uint16_t i = 0; i < od->count; i++) {
        const co_od_entry_t *e = &od->entries[i];
        if (e->cls != cls || e->off + e->size <= at || e->off >= at + n) {
            continue;
        }
        bool in_group = e->index >= g->lo && e->index <= g->hi;
        if (in_group && !g->defaults) {
            continue; /* RAM, already there */
        }
        uint8_t v[4];
        if (in_group || g->from < 0) {
            co_od_native(e, e->def, v); /* records hold the RAM image */
        } else if (!co_port_nvm_read(
                       node->port, slot_addr(node, cls, (unsigned)g->from) + CO_STORE_HDR + e->off,
                       v, e->size)) {
            return false;
        }
        for (uint16_t b = 0; b < e->size; b++) {
            uint32_t pos = e->off + b;
            if (pos >= at && pos < at + n) {
                out[pos - at] = v[b];
            }
        }
    }
    return true;
}

/* Write a record with sequence seq into slot target: header, data, CRC.
 * Not inlined: its buffers never share the stack with newest()'s. */
static CO_NOINLINE co_res_t write_slot(co_node_t *node, co_cls_t cls, unsigned target, uint32_t seq,
                                       uint8_t flags, const group_t *g)
{
    uint32_t len = (flags & FLAG_DEFAULTS) != 0u ? 0u : co_cfg(node)->ram_size[cls];
    uint8_t h[CO_STORE_HDR] = {0};
    co_put_u32(&h[0], STORE_MAGIC);
    co_put_u32(&h[4], co_store_layout_hash(node, cls));
    co_put_u32(&h[8], seq);
    co_put_u32(&h[12], node->store.writes + 1u);
    co_put_u16(&h[16], (uint16_t)len);
    h[18] = flags;
    h[19] = (uint8_t)cls;
    uint32_t a = slot_addr(node, cls, target);
    uint32_t crc = co_crc32(0, h, sizeof(h));
    if (!co_port_nvm_write(node->port, a, h, sizeof(h))) {
        return CO_E_HW;
    }
    for (uint32_t at = 0; at < len; at += sizeof(h)) { /* the header's buffer, reused */
        uint32_t n = co_min_u32(sizeof(h), len - at);
        if (!record_chunk(node, cls, g, at, h, n) ||
            !co_port_nvm_write(node->port, a + CO_STORE_HDR + at, h, n)) {
            return CO_E_HW;
        }
        crc = co_crc32(crc, h, n);
    }
    co_put_u32(h, crc);
    if (!co_port_nvm_write(node->port, a + CO_STORE_HDR + len, h, 4)) {
        return CO_E_HW;
    }
    return CO_OK;
}

static co_res_t write_record(co_node_t *node, co_cls_t cls, uint8_t flags, group_t *g)
{
    if (!stored_class(node, cls)) {
        return CO_E_STORE;
    }
    if (co_store_limit_reached(node)) {
        return CO_E_STORE;
    }
    newest_t nw = newest(node, cls);
    if (nw.hw) {
        /* A slot could not be read: which record is newest is unknown, so a
         * write could replace it, lose to an older one, or (group save)
         * take the other groups' values from nowhere. Refuse; both stored
         * records stay as they are. */
        return CO_E_HW;
    }
    if (g != NULL) {
        g->from = (nw.k >= 0 && (nw.flags & FLAG_DEFAULTS) == 0u) ? nw.k : -1;
    }
    /* Into the other slot than the newest record's, one sequence number on.
     * Then the slot the next save writes holds a record (the one this
     * replaced, or this one cut short): erased ahead once the SDO server
     * is quiet (co_store_poll). */
    co_res_t r = write_slot(node, cls, target(&nw), nw.k < 0 ? 1u : nw.seq + 1u, flags, g);
    node->store.due |= (uint8_t)CO_STORE_DUE_SPARE(cls);
    if (r != CO_OK) {
        return r;
    }
    node->store.writes++;
    if (node->store.status[cls] != CO_STORE_OK && flags == 0u && g == NULL) {
        node->store.status[cls] = CO_STORE_OK; /* the stored set is sound again */
    }
    return CO_OK;
}

/* Only a product that stores its writes on its own has saves to put off:
 * a constant in an image of a fixed config, which then drops the rest. */
static bool autosaves(const co_node_t *node)
{
    return co_cfg(node)->autosave;
}

/* A record of cls is about to replace what an autosave still due would
 * store (the RAM struct, or the defaults a "load" asks for after it). */
static void no_save_due(co_node_t *node, co_cls_t cls)
{
    if (autosaves(node)) {
        node->store.due &= (uint8_t)~CO_STORE_DUE_SAVE(cls);
    }
}

co_res_t co_store_save(co_node_t *node, co_cls_t cls)
{
    no_save_due(node, cls);
    return write_record(node, cls, 0, NULL);
}

co_res_t co_store_request_defaults(co_node_t *node, co_cls_t cls)
{
    no_save_due(node, cls);
    return write_record(node, cls, FLAG_DEFAULTS, NULL);
}

void co_store_flush(co_node_t *node)
{
    if (!autosaves(node)) {
        return;
    }
    for (unsigned cls = CO_CLS_PARA; cls <= CO_CLS_LSS; cls++) {
        /* A failure cannot be answered any more (the write was): the value
         * stays in use and the set is reported as one the NVM could not
         * take, as after a failed read. */
        if ((node->store.due & CO_STORE_DUE_SAVE(cls)) != 0u &&
            co_store_save(node, (co_cls_t)cls) != CO_OK) {
            node->store.status[cls] = CO_STORE_HW;
        }
    }
}

uint32_t co_store_poll(co_node_t *node, uint32_t now)
{
    co_store_t *s = &node->store;
    if (s->due == 0u) {
        return CO_NEVER;
    }
    uint32_t quiet = now - s->sdo_at;
    uint8_t saves = CO_STORE_DUE_SAVE(CO_CLS_PARA) | CO_STORE_DUE_SAVE(CO_CLS_LSS);
    if (autosaves(node) && (s->due & saves) != 0u) {
        /* The saves first; a master that never pauses gets one answer late
         * after CO_STORE_DEFER_MAX_US rather than the writes left unstored. */
        uint32_t waited = now - s->due_at;
        if (quiet < CO_STORE_QUIET_US && waited < CO_STORE_DEFER_MAX_US) {
            return co_min_u32(CO_STORE_QUIET_US - quiet, CO_STORE_DEFER_MAX_US - waited);
        }
        co_store_flush(node);
        return 0;
    }
    if (quiet < CO_STORE_QUIET_US) {
        return CO_STORE_QUIET_US - quiet;
    }
    /* One slot a call: a request received meanwhile is answered first. */
    co_cls_t cls = (s->due & CO_STORE_DUE_SPARE(CO_CLS_PARA)) != 0u ? CO_CLS_PARA : CO_CLS_LSS;
    s->due &= (uint8_t)~CO_STORE_DUE_SPARE(cls);
    (void)prepare(node, cls);
    return 0;
}

void co_store_share_pause(co_node_t *const nodes[], unsigned n)
{
    uint32_t at = nodes[0]->store.sdo_at;
    for (unsigned i = 1; i < n; i++) {
        if (co_time_before(at, nodes[i]->store.sdo_at)) {
            at = nodes[i]->store.sdo_at;
        }
    }
    for (unsigned i = 0; i < n; i++) {
        nodes[i]->store.sdo_at = at;
    }
}

co_res_t co_store_save_group(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi, bool defaults)
{
    group_t g = {.lo = lo, .hi = hi, .defaults = defaults, .from = -1};
    return write_record(node, cls, 0, &g);
}

/* The class's RAM struct equals its newest valid stored record. */
static bool same_as_stored(co_node_t *node, co_cls_t cls)
{
    newest_t nw = newest(node, cls);
    if (nw.k < 0 || nw.flags != 0u) {
        return false;
    }
    uint32_t a = slot_addr(node, cls, (unsigned)nw.k) + CO_STORE_HDR;
    const uint8_t *ram = node->ram[cls];
    uint8_t chunk[16];
    for (uint32_t at = 0; at < nw.len; at += sizeof(chunk)) {
        uint32_t n = co_min_u32(sizeof(chunk), nw.len - at);
        if (!co_port_nvm_read(node->port, a + at, chunk, n) || memcmp(chunk, ram + at, n) != 0) {
            return false;
        }
    }
    return true;
}

static void notify(co_node_t *node, uint32_t sig)
{
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->stored != NULL) {
        co_cfg(node)->ops->stored(node, sig);
    }
}

/* The CiA 301 groups of 0x1010 / 0x1011 sub 2, 3, 4 (at sub - 2): their
 * index ranges. */
enum { GROUP_COMM, GROUP_APP, GROUP_MANUF };
static const struct {
    uint16_t lo, hi;
} groups[] = {
    [GROUP_COMM] = {0x1000, 0x1FFF},  /* sub 2: communication parameters */
    [GROUP_APP] = {0x6000, 0x9FFF},   /* sub 3: application (device profile) parameters */
    [GROUP_MANUF] = {0x2000, 0x5FFF}, /* sub 4: manufacturer-specific parameters */
};

/* Save or restore (defaults) the group of sub-index sub (2..4: group_hook)
 * in PARA, and in LSS where the product keeps node-ID and bit rate among
 * its parameters. */
static co_res_t group_op(co_node_t *node, uint8_t sub, bool defaults)
{
    unsigned g = (unsigned)sub - 2u;
    co_res_t r = co_store_save_group(node, CO_CLS_PARA, groups[g].lo, groups[g].hi, defaults);
    if (r == CO_OK && co_cfg(node)->save_includes_lss && stored_class(node, CO_CLS_LSS)) {
        r = co_store_save_group(node, CO_CLS_LSS, groups[g].lo, groups[g].hi, defaults);
    }
    return r;
}

co_res_t co_store_write_save(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    (void)e;
    if (value != CO_SIG_SAVE) {
        return CO_E_STORE;
    }
    /* "Save all parameters"; the LSS set too where the product keeps
     * node-ID and bit rate among the saved parameters. */
    co_res_t r = co_store_save(node, CO_CLS_PARA);
    if (r == CO_OK && co_cfg(node)->save_includes_lss && stored_class(node, CO_CLS_LSS) &&
        !same_as_stored(node, CO_CLS_LSS)) {
        r = co_store_save(node, CO_CLS_LSS); /* unchanged: no write cycle spent */
    }
    if (r == CO_OK) {
        notify(node, value);
    }
    return r;
}

co_res_t co_store_write_load(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    (void)e;
    if (value != CO_SIG_LOAD) {
        return CO_E_STORE;
    }
    co_res_t r = co_store_request_defaults(node, CO_CLS_PARA);
    if (r == CO_OK && stored_class(node, CO_CLS_LSS) && !co_cfg(node)->load_keeps_lss) {
        r = co_store_request_defaults(node, CO_CLS_LSS);
    }
    if (r == CO_OK) {
        notify(node, value);
    }
    return r;
}

/* Group save (defaults = false) or restore of 0x1010 / 0x1011 sub 2..4. */
static co_res_t group_hook(co_node_t *node, const co_od_entry_t *e, uint32_t value,
                           uint32_t signature, bool defaults)
{
    if (value != signature || e->sub < 2u || e->sub > 4u) {
        return CO_E_STORE;
    }
    co_res_t r = group_op(node, e->sub, defaults);
    if (r == CO_OK) {
        notify(node, value);
    }
    return r;
}

co_res_t co_store_write_group_save(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    return group_hook(node, e, value, CO_SIG_SAVE, false);
}

co_res_t co_store_write_group_load(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    return group_hook(node, e, value, CO_SIG_LOAD, true);
}
