/*
 * tpdo.c - transmit PDOs. See co_tpdo.h.
 */
#include "co_tpdo.h"

#include <string.h>

#include "co_node.h"

enum {
    TYPE_ACYCLIC = 0,
    TYPE_SYNC_MAX = 240,
    TYPE_RTR_SYNC = 252,
    TYPE_RTR = 253,
    TYPE_EVENT_MFR = 254,
};

static CO_NOINLINE uint32_t get_or(co_node_t *node, uint16_t index, uint8_t sub, uint32_t dflt)
{
    const co_od_entry_t *e = co_node_entry(node, index, sub);
    uint32_t v = dflt;
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    return v;
}

static bool event_driven(const co_tpdo_t *t)
{
    return t->type >= TYPE_EVENT_MFR;
}

/* The inhibit time in us: u16 x a unit of at most 1000 us (co_node_cfg_t)
 * is at most 65 535 000 us, far inside co_time_before's 2^31 us horizon. */
static uint32_t inhibit_us(const co_node_t *node, uint32_t inhibit)
{
    uint32_t unit = co_cfg(node)->inhibit_unit_us != 0u ? co_cfg(node)->inhibit_unit_us : 100u;
    unit = co_min_u32(unit, 1000u);
    return (uint32_t)(uint16_t)inhibit * unit;
}

static void start_one(co_node_t *node, co_tpdo_t *t)
{
    t->sync_count = 0;
    t->pending = false;
    t->have_last = false;
    /* The first event-driven PDO goes out at the next poll. */
    t->timer_armed = t->valid && event_driven(t) && t->event_ms != 0u;
    t->next_event = node->now;
    t->inhibit_end = node->now;
}

/* Resolve one mapping entry; CO_OK with *e and *bytes, or why not. */
static co_res_t resolve_map(co_node_t *node, uint32_t m, const co_od_entry_t **e, uint8_t *bytes)
{
    co_res_t r;
    *e = co_od_find(co_cfg(node)->od, (uint16_t)(m >> 16), (uint8_t)(m >> 8), &r);
    uint32_t bits = m & 0xFFu;
    if (*e == NULL) {
        return CO_E_NO_OBJ;
    }
    if (((*e)->attr & CO_A_PDO) == 0u || bits == 0u || (bits % 8u) != 0u ||
        bits / 8u > co_od_size(*e)) {
        return CO_E_NO_MAP;
    }
    *bytes = (uint8_t)(bits / 8u);
    return CO_OK;
}

void co_tpdo_reconfig(co_node_t *node, unsigned n)
{
    if (!CO_CHECK(n < CO_TPDO_MAX)) {
        return; /* no such TPDO in this build: nothing changes */
    }
    co_tpdo_t *t = &node->tpdo[n];
    bool msb_first = t->msb_first; /* the product's, not the dictionary's */
    memset(t, 0, sizeof(*t));
    t->msb_first = msb_first;
    uint16_t comm = (uint16_t)(0x1800u + n);
    uint16_t mapi = (uint16_t)(0x1A00u + n);
    /* No COB-ID (no such TPDO in the dictionary): invalid, sends nothing. */
    uint32_t cob = get_or(node, comm, 1, 0x80000000u);
    t->type = (uint8_t)get_or(node, comm, 2, 254);
    t->inhibit_us = inhibit_us(node, get_or(node, comm, 3, 0));
    t->event_ms = (uint16_t)get_or(node, comm, 5, 0);
    t->cob_id = (uint16_t)(cob & 0x7FFu);
    t->rtr_allowed = (cob & 0x40000000u) == 0u;
    uint32_t count = get_or(node, mapi, 0, 0);
    if (count == 0u || count > CO_PDO_MAP_MAX) {
        return;
    }
    uint32_t len = 0;
    /* count <= CO_PDO_MAP_MAX (above); a byte index: 4 bytes less code on the Cortex-M0 */
    for (uint8_t i = 0; i < count; i++) { /* NOLINT(bugprone-too-small-loop-variable) */
        uint32_t m = get_or(node, mapi, (uint8_t)(i + 1u), 0);
        uint8_t bytes;
        if (resolve_map(node, m, &t->map[i], &bytes) != CO_OK) {
            return; /* unusable mapping: the PDO stays invalid */
        }
        t->map_drop[i] = (uint8_t)(32u - 8u * bytes);
        len += bytes;
    }
    if (len > 8u) {
        return;
    }
    t->nmap = (uint8_t)count;
    t->len = (uint8_t)len;
    t->dlc = co_cfg(node)->tpdo_dlc != 0u ? co_cfg(node)->tpdo_dlc : t->len;
    t->valid = (cob & 0x80000000u) == 0u;
    if (node->nmt.state == CO_NMT_OPERATIONAL) {
        start_one(node, t); /* a parameter changed while operational: apply it now */
    }
}

void co_tpdo_set_msb_first(co_node_t *node, unsigned n, bool msb_first)
{
    if (CO_CHECK(n < CO_TPDO_MAX)) {
        node->tpdo[n].msb_first = msb_first;
    }
}

static unsigned tpdo_number(const co_od_entry_t *e)
{
    return (unsigned)(e->index & 0x1FFu);
}

co_res_t co_tpdo_write_comm(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    if (e->sub == 2u && value > TYPE_SYNC_MAX && value < TYPE_RTR_SYNC) {
        return CO_E_VAL; /* reserved transmission types */
    }
    co_res_t r = co_od_store(node, e, value);
    if (r == CO_OK && tpdo_number(e) < CO_TPDO_MAX) {
        co_tpdo_reconfig(node, tpdo_number(e));
    }
    return r;
}

co_res_t co_tpdo_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    /* Bit 30 is "no RTR"; an invalid COB-ID may name any CAN-ID (0x80000000). */
    co_res_t c = co_cobid_check(value, true, true);
    if (c != CO_OK) {
        return c;
    }
    uint32_t cur;
    (void)co_od_get(node, e, &cur);
    bool cur_valid = (cur & 0x80000000u) == 0u;
    if (cur_valid && (value & 0x80000000u) == 0u && (value & 0x7FFu) != (cur & 0x7FFu)) {
        return CO_E_VAL; /* the CAN-ID changes only while the PDO is invalid */
    }
    return co_tpdo_write_comm(node, e, value);
}

co_res_t co_tpdo_write_map(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    unsigned n = (unsigned)(e->index & 0x1FFu);
    uint16_t comm = (uint16_t)(0x1800u + n);
    uint16_t mapi = e->index;
    bool checking = co_od_checking(node);
    /* CiA 301's order of a mapping change; a restored record (checking)
     * is judged by its values alone. */
    if (!checking && (get_or(node, comm, 1, 0x80000000u) & 0x80000000u) == 0u) {
        return CO_E_UNSUPP; /* CiA 301: invalidate the PDO first */
    }
    if (e->sub == 0u) {
        /* CiA 301: sub 0 is 0..64. Each of the first value entries must
         * name a mappable object: one that names none (0, or a sub-index
         * the mapping does not have, read as 0) is "object does not
         * exist" (0x06020000), one that cannot be mapped 0x06040041,
         * more than 8 bytes in all 0x06040042. */
        if (value > 64u) {
            return CO_E_VAL_HIGH;
        }
        uint32_t bytes = 0;
        for (unsigned i = 1; i <= value; i++) {
            const co_od_entry_t *m;
            uint8_t b;
            co_res_t r = resolve_map(node, get_or(node, mapi, (uint8_t)i, 0), &m, &b);
            if (r != CO_OK) {
                return r;
            }
            bytes += b;
            if (bytes > 8u) {
                return CO_E_MAP_LEN; /* also every count beyond CO_PDO_MAP_MAX */
            }
        }
    } else {
        if (!checking && get_or(node, mapi, 0, 0) != 0u) {
            return CO_E_UNSUPP; /* CiA 301: set sub 0 to 0 first */
        }
        const co_od_entry_t *m;
        uint8_t b;
        co_res_t r = resolve_map(node, value, &m, &b);
        if (r != CO_OK) {
            return r;
        }
    }
    if (checking) {
        return CO_OK;
    }
    /* No reconfig: the PDO is invalid while its mapping changes (above),
     * and the COB-ID's write that makes it valid again reconfigures it. */
    return co_od_store(node, e, value);
}

void co_tpdo_start(co_node_t *node)
{
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        start_one(node, &node->tpdo[n]);
    }
}

/* v's four bytes in reverse order (big-endian PDO values). */
static uint32_t reverse_bytes(uint32_t v)
{
    return (v << 24) | ((v & 0xFF00u) << 8) | ((v >> 8) & 0xFF00u) | (v >> 24);
}

/* The mapped part of TPDO n, without the product's fill hook. The data
 * bytes are gathered in one 64-bit value and stored at the end. On a
 * 32-bit core it is built as two 32-bit words: there a 64-bit shift by a
 * variable count is a library call (__ashldi3 on the Cortex-M0, 24
 * instructions a mapped object). A 64-bit host keeps the single shift (the
 * words cost x86-64 16 instructions a TPDO). */
static inline void build_mapped(co_node_t *node, unsigned n, co_frame_t *f)
{
    const co_tpdo_t *t = &node->tpdo[n];
    unsigned nmap = t->nmap;
    bool msb_first = t->msb_first;
    f->id = t->cob_id;
    f->rtr = false;
    f->dlc = t->dlc;
#if UINTPTR_MAX > 0xFFFFFFFFu
    uint64_t data = 0;
#else
    uint32_t lo = 0; /* data bytes 0..3 */
    uint32_t hi = 0; /* data bytes 4..7 */
#endif
    unsigned shift = 0;
    for (unsigned i = 0; i < nmap; i++) {
        uint32_t v = 0;
        (void)co_od_get(node, t->map[i], &v);
        /* Its own bytes only: 1..4, every mapped object is at most 32 bits. */
        unsigned drop = t->map_drop[i];
        v = msb_first ? reverse_bytes(v) >> drop : v & (0xFFFFFFFFu >> drop);
        /* At most 8 bytes in all (the mapping's check): shift < 64. */
#if UINTPTR_MAX > 0xFFFFFFFFu
        data |= (uint64_t)v << shift;
#else
        if (shift < 32u) {
            lo |= v << shift;
            if (shift != 0u) {
                hi |= v >> (32u - shift); /* the bytes that cross into hi */
            }
        } else {
            hi |= v << (shift - 32u);
        }
#endif
        shift += 32u - drop;
    }
#if UINTPTR_MAX <= 0xFFFFFFFFu && defined(__GNUC__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    /* A little-endian 32-bit core stores the two words as they are: the
     * frame's data is word aligned (co_frame_t). Two co_put_u32() calls,
     * byte by byte, were 24 more Cortex-M0 instructions a TPDO. */
    co_word_t *w = (co_word_t *)(void *)f->data;
    w[0] = lo;
    w[1] = hi;
#else
#if UINTPTR_MAX <= 0xFFFFFFFFu
    uint64_t data = ((uint64_t)hi << 32) | lo; /* constant shifts: free */
#endif
    co_put_u32(&f->data[0], (uint32_t)data);
    co_put_u32(&f->data[4], (uint32_t)(data >> 32));
#endif
}

void co_tpdo_build(co_node_t *node, unsigned n, co_frame_t *f)
{
    build_mapped(node, n, f);
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->tpdo_fill != NULL) {
        co_cfg(node)->ops->tpdo_fill(node, n, f);
    }
}

_Static_assert(offsetof(co_frame_t, data) % 4u == 0u, "frame data word aligned");

/* The 8 data bytes from s to d, both word aligned (a frame's data, last[]).
 * On a 32-bit core two word copies: there memcpy is libc_min.c's byte
 * loop, 53 Cortex-M0 instructions a TPDO sent on SYNC. A 64-bit host's
 * compiler expands the memcpy itself. */
static inline void copy_data(uint8_t *d, const uint8_t *s)
{
#if defined(__GNUC__) && UINTPTR_MAX <= 0xFFFFFFFFu
    co_word_t *dw = (co_word_t *)(void *)d;
    const co_word_t *sw = (const co_word_t *)(const void *)s;
    dw[0] = sw[0];
    dw[1] = sw[1];
#else
    memcpy(d, s, 8);
#endif
}

/* The same for a compare of all 8 bytes: equal. */
static inline bool same_data(const uint8_t *a, const uint8_t *b)
{
#if defined(__GNUC__) && UINTPTR_MAX <= 0xFFFFFFFFu
    const co_word_t *aw = (const co_word_t *)(const void *)a;
    const co_word_t *bw = (const co_word_t *)(const void *)b;
    return aw[0] == bw[0] && aw[1] == bw[1];
#else
    return memcmp(a, b, 8) == 0;
#endif
}

static void send_frame(co_node_t *node, co_tpdo_t *t, const co_frame_t *f)
{
    (void)co_node_send(node, f);
    copy_data(t->last, f->data);
    t->have_last = true;
}

static void send(co_node_t *node, unsigned n)
{
    co_frame_t f;
    co_tpdo_build(node, n, &f);
    send_frame(node, &node->tpdo[n], &f);
}

void co_tpdo_sync(co_node_t *node)
{
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_t *t = &node->tpdo[n];
        if (!t->valid) {
            continue;
        }
        if (t->type == TYPE_ACYCLIC) {
            co_frame_t f;
            co_tpdo_build(node, n, &f);
            if (!t->have_last || !same_data(f.data, t->last)) {
                send_frame(node, t, &f);
            }
        } else if (t->type <= TYPE_SYNC_MAX) {
            if (++t->sync_count >= t->type) {
                t->sync_count = 0;
                send(node, n);
            }
        } else if (t->type == TYPE_RTR_SYNC) {
            co_frame_t f;
            co_tpdo_build(node, n, &f);
            copy_data(t->last, f.data); /* sampled now, sent on request */
            t->have_last = true;
        }
    }
}

bool co_tpdo_receive_rtr(co_node_t *node, const co_frame_t *f)
{
    if (!f->rtr) {
        return false;
    }
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_t *t = &node->tpdo[n];
        if (!t->valid || f->id != t->cob_id) {
            continue;
        }
        if (!t->rtr_allowed || node->nmt.state != CO_NMT_OPERATIONAL) {
            return true;
        }
        co_frame_t out;
        co_tpdo_build(node, n, &out);
        if (t->type == TYPE_RTR_SYNC) {
            if (!t->have_last) {
                return true; /* nothing sampled yet: no SYNC since operational */
            }
            copy_data(out.data, t->last);
        }
        (void)co_node_send(node, &out);
        return true;
    }
    return false;
}

bool co_tpdo_changed(co_node_t *node, unsigned n)
{
    if (!CO_CHECK(n < CO_TPDO_MAX)) {
        return false;
    }
    co_tpdo_t *t = &node->tpdo[n];
    if (!t->valid || !event_driven(t) || node->nmt.state != CO_NMT_OPERATIONAL) {
        return false;
    }
    co_frame_t f;
    build_mapped(node, n, &f);
    return !t->have_last || memcmp(f.data, t->last, t->len) != 0;
}

void co_tpdo_event(co_node_t *node, unsigned n)
{
    if (!CO_CHECK(n < CO_TPDO_MAX)) {
        return;
    }
    co_tpdo_t *t = &node->tpdo[n];
    if (t->valid && event_driven(t) && node->nmt.state == CO_NMT_OPERATIONAL) {
        t->pending = true; /* sent by the next poll, or when the inhibit time ends */
        co_node_wake(node);
    }
}

uint32_t co_tpdo_poll(co_node_t *node, uint32_t now)
{
    uint32_t next = CO_NEVER;
    if (node->nmt.state != CO_NMT_OPERATIONAL) {
        return next;
    }
    /* Only a valid event-driven TPDO has its timer armed (start_one) or an
     * event pending (co_tpdo_event): the others pass through untouched. */
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_t *t = &node->tpdo[n];
        uint32_t period = (uint32_t)t->event_ms * 1000u; /* <= 65 535 000 us: no overflow */
        bool timer_due = t->timer_armed && !co_time_before(now, t->next_event);
        if (timer_due || t->pending) {
            /* The inhibit time still runs while its end is 1 .. inhibit_us ahead
             * (one compare). Not co_time_before(): an end that seems further
             * ahead went stale more than 2^31 us ago without a send since
             * (an event-driven PDO whose data did not change for 36 min),
             * and the event waited up to 36 min for it (fuzz_node.c). What
             * waits stays: a pending event, or a timer still due (its
             * deadline moves only when it sends). */
            if (t->inhibit_end - now - 1u < t->inhibit_us) {
                next = co_min_u32(next, t->inhibit_end - now);
                continue;
            }
            send(node, n);
            t->pending = false;
            t->inhibit_end = now + t->inhibit_us;
            if (t->timer_armed) {
                /* A timer send keeps the cadence; an event send restarts it. */
                t->next_event = timer_due ? t->next_event + period : now + period;
                if (!co_time_before(now, t->next_event)) {
                    t->next_event = now + period; /* late by a period: no burst */
                }
            }
        }
        if (t->timer_armed) {
            next = co_min_u32(next, t->next_event - now);
        }
    }
    return next;
}

const co_service_t co_rtr_service = {.receive = co_tpdo_receive_rtr};
